// The top-level guard every command's main runs its body through (format/tools/command_line.h):
// an allocation that fails becomes the command's one line, CALF-E013, and exit status 1.
// (AddressSanitizer's operator new reports and aborts instead of throwing, so a sanitized command
// cannot show this end to end; tests/CMakeLists.txt runs calf-ingest under `ulimit -v` in a plain
// build.)
#include <gtest/gtest.h>

#include <new>
#include <stdexcept>
#include <string>
#include <vector>

#include "../../format/tools/command_line.h"

namespace calf::tools {
namespace {

TEST(RunCommand, BadAllocIsOneLineWithE013AndExit1) {
  testing::internal::CaptureStderr();
  const int rc = run_command("calf-test", []() -> int { throw std::bad_alloc(); });
  const std::string printed = testing::internal::GetCapturedStderr();
  EXPECT_EQ(rc, kExitError);
  EXPECT_EQ(printed.rfind("calf-test: CALF-E013 out of memory", 0), 0u) << printed;
  EXPECT_EQ(printed.find('\n'), printed.size() - 1) << printed;
}

TEST(RunCommand, LengthErrorToo) {
  testing::internal::CaptureStderr();
  const int rc = run_command("calf-test", [] {
    std::vector<double> v;
    v.resize(v.max_size() + 1);  // throws std::length_error
    return 0;
  });
  const std::string printed = testing::internal::GetCapturedStderr();
  EXPECT_EQ(rc, kExitError);
  EXPECT_EQ(printed.rfind("calf-test: CALF-E013 ", 0), 0u) << printed;
}

TEST(RunCommand, PassesTheBodysStatusThrough) {
  EXPECT_EQ(run_command("calf-test", [] { return 0; }), 0);
  EXPECT_EQ(run_command("calf-test", [] { return 2; }), 2);
}

}  // namespace
}  // namespace calf::tools
