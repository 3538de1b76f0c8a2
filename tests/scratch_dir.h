// The scratch folder of a test or fuzz target that writes files (clips, scene files, inputs a
// reader must open by path): one folder per process under the temp directory, made on first use
// and removed when the process exits (so ctest leaves nothing behind).
#pragma once

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <string>
#include <system_error>

namespace calf::test {

// temp_directory_path() / "<name>_<pid>", created on the first call. Every call of one process
// must pass the same `name`.
inline const std::filesystem::path& scratch_dir(const char* name) {
  // Never destroyed (reachable through the pointer): a static path's destructor, registered after
  // the atexit handler below, would run before it and leave the handler an empty path.
  static const std::filesystem::path* const dir = [name] {
    auto* d = new std::filesystem::path(std::filesystem::temp_directory_path() /
                                        (std::string(name) + "_" + std::to_string(getpid())));
    std::filesystem::create_directories(*d);
    std::atexit([] {
      std::error_code ignored;
      std::filesystem::remove_all(scratch_dir(nullptr), ignored);
    });
    return d;
  }();
  return *dir;
}

}  // namespace calf::test
