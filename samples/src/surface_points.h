// Private to samples/: points spread uniformly by area over a scene's surfaces at one time, the
// integration points of camera placement's coverage integrals (rig_placement.h).
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "calf/samples/scene.h"

namespace calf::samples {

struct SurfacePoints {
  std::vector<glm::vec3> positions;  // world space
  double area = 0;                   // total surface area at that time (scene units squared)
};

// `count` points on the triangles and spheres of `scene` at `time` seconds, each area element
// equally likely: stratified over the area (point i's first random number lies in [i, i+1) /
// count of the cumulative area), then uniform within the triangle or on the sphere. Transforms
// are taken as rigid or uniformly scaled (scene.h), so an instance's area is its mesh's times the
// scale squared. A pure function of (scene, time, count, seed). No points when the area is 0.
SurfacePoints sample_surface_points(const Scene& scene, double time, uint32_t count, uint64_t seed);

}  // namespace calf::samples
