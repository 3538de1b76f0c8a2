// Fuzz target for the eye-path reader (calf/capture/eye_path.h, parse_eye_path): any text must
// give a path or one of its errors (E130, E132, E134, E142), never a crash, a sanitizer report
// or an exception; an accepted path has positions within the coordinate bound, unit forward and
// up vectors orthogonal to each other, and serializes to text that parses back to the same path.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "calf/capture/eye_path.h"
#include "calf/format/coordinates.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::string_view text(reinterpret_cast<const char*>(data), size);
  calf::Expected<calf::capture::EyePath> path = calf::capture::parse_eye_path(text, "fuzz");
  if (!path.ok()) {
    switch (path.status().id()) {
      case calf::ErrorId::kManifestSyntax:
      case calf::ErrorId::kManifestVersion:
      case calf::ErrorId::kCaptureLimit:
      case calf::ErrorId::kEyePathField:
        return 0;
      default:
        std::abort();
    }
  }
  for (const calf::capture::EyePose& p : path->poses) {
    if (!calf::coordinates_ok(p.position)) std::abort();
    if (std::fabs(calf::length(p.forward) - 1) > 1e-9) std::abort();
    if (std::fabs(calf::length(p.up) - 1) > 1e-9) std::abort();
    if (std::fabs(calf::dot(p.forward, p.up)) > 1e-9) std::abort();
    if (!(p.fov_y_degrees > 0 && p.fov_y_degrees < 180)) std::abort();
  }
  calf::Expected<calf::capture::EyePath> again =
      calf::capture::parse_eye_path(calf::capture::serialize_eye_path(*path), "again");
  if (!again.ok() || !(*again == *path)) std::abort();
  return 0;
}
