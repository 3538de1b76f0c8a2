// Private to samples/: the one conversion between calf's Vec3 (calf/format/geometry.h, what every
// file and every other layer speaks) and glm, which the ray tracer keeps for transforms and
// Embree-side float math.
#pragma once

#include <glm/glm.hpp>

#include "calf/format/geometry.h"

namespace calf::samples {

inline Vec3 to_vec3(const glm::dvec3& v) {
  return {v.x, v.y, v.z};
}
inline glm::dvec3 to_dvec3(const Vec3& v) {
  return {v.x, v.y, v.z};
}
// Rounds each component to float, as Embree's rays take them.
inline glm::vec3 to_fvec3(const Vec3& v) {
  return {static_cast<float>(v.x), static_cast<float>(v.y), static_cast<float>(v.z)};
}

}  // namespace calf::samples
