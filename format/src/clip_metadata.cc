// The typed clip metadata values (clip_metadata.h).
#include "calf/format/clip_metadata.h"

#include <cmath>
#include <cstdio>
#include <sstream>

namespace calf::container {

std::string format_view_volume(const Box3& box) {
  char volume[160];
  std::snprintf(volume, sizeof volume, "%.17g %.17g %.17g %.17g %.17g %.17g", box.min.x, box.min.y,
                box.min.z, box.max.x, box.max.y, box.max.z);
  return volume;
}

std::optional<Box3> parse_view_volume(const std::string* text) {
  if (text == nullptr) return std::nullopt;
  std::istringstream in(*text);
  double v[6];
  for (double& x : v) {
    if (!(in >> x) || !std::isfinite(x)) return std::nullopt;
  }
  if (v[0] > v[3] || v[1] > v[4] || v[2] > v[5]) return std::nullopt;
  return Box3{{v[0], v[1], v[2]}, {v[3], v[4], v[5]}};
}

}  // namespace calf::container
