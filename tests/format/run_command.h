// Running a calf command from a test: the shell runs `command` with stderr joined to stdout.
#pragma once

#include <sys/wait.h>

#include <cstdio>
#include <string>

namespace calf::testing_support {

// Appends the command's output to *out and returns its exit status; -1 when it could not be
// started or did not exit normally.
inline int run_command(const std::string& command, std::string* out) {
  FILE* pipe = ::popen((command + " 2>&1").c_str(), "r");
  if (pipe == nullptr) return -1;
  char buf[4096];
  size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, pipe)) > 0) out->append(buf, n);
  const int rc = ::pclose(pipe);
  return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}

}  // namespace calf::testing_support
