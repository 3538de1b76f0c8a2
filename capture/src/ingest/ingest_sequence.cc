// The manifests of an ingest sequence: a printf-style frame-number pattern expanded into paths
// (calf/capture/ingest.h, frame_manifests).
#include <cstdio>
#include <string>
#include <system_error>
#include <vector>

#include "calf/capture/ingest.h"

namespace calf::capture {

Expected<std::vector<std::filesystem::path>> frame_manifests(std::string_view pattern,
                                                             uint32_t first, uint32_t count) {
  const size_t at = pattern.find('%');
  if (at == std::string_view::npos) {
    return std::vector<std::filesystem::path>{std::filesystem::path(pattern)};
  }
  const auto bad = [&](const std::string& why) {
    return Status(ErrorId::kInvalidArgument,
                  "manifest pattern '" + std::string(pattern) + "': " + why +
                      " (one frame number, %d or %0Nd with N in 1..9, e.g. "
                      "frame_%04d/manifest.json)");
  };
  // "%d" or "%0Nd": the width N (0 = none).
  size_t end = at + 1;
  int width = 0;
  if (end < pattern.size() && pattern[end] == '0') {
    if (end + 1 >= pattern.size() || pattern[end + 1] < '1' || pattern[end + 1] > '9') {
      return bad("a width after %0 must be a digit 1..9");
    }
    width = pattern[end + 1] - '0';
    end += 2;
  }
  if (end >= pattern.size() || pattern[end] != 'd') return bad("expected %d or %0Nd");
  const std::string_view head = pattern.substr(0, at), tail = pattern.substr(end + 1);
  if (tail.find('%') != std::string_view::npos) return bad("more than one '%'");
  constexpr uint64_t kMaxFrames = 1000000;  // a capture set's frame limit (CAPTURE.md "Limits")
  if (count > kMaxFrames) return bad(std::to_string(count) + " frames: at most 1000000");
  std::vector<std::filesystem::path> out;
  for (uint64_t k = 0; count ? k < count : k <= kMaxFrames; ++k) {
    const uint64_t number = uint64_t{first} + k;
    char digits[32];
    std::snprintf(digits, sizeof digits, "%0*llu", width, static_cast<unsigned long long>(number));
    std::filesystem::path path(std::string(head) + digits + std::string(tail));
    if (!count) {
      std::error_code ec;
      if (!std::filesystem::exists(std::filesystem::symlink_status(path, ec))) {
        if (out.empty()) {
          return Status(ErrorId::kFileOpen, path.string() +
                                                ": no such file (the first frame of manifest "
                                                "pattern '" +
                                                std::string(pattern) + "')");
        }
        break;
      }
      if (k == kMaxFrames) return bad("more than 1000000 frames");
    }
    out.push_back(std::move(path));
  }
  return out;
}

}  // namespace calf::capture
