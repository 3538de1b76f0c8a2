// Private to samples/: the built-in scenes of the visible-set mode (paper 004), one file each,
// registered in builtin_scenes.cc.
#pragma once

#include "calf/samples/scene.h"

namespace calf::samples {

// city_scene.cc: streets of instanced buildings with windows and ledges, seen from a crossing.
Scene city_scene();
// blades_scene.cc: a field of thin grass blades swaying in piecewise-linear vertex states.
Scene blades_scene();
// spheres_scene.cc: analytic spheres bouncing on a floor among walls and pillars.
Scene spheres_scene();
// factory_scene.cc (the surfel mode): a machine hall of instanced CAD-like parts.
Scene factory_scene();

}  // namespace calf::samples
