// The initial surfel candidates of paper 001 (Sec. 3.1), ray cast with Embree for every mesh
// prototype of a scene file and written as a surfel-candidate file (format/SURFEL_CANDIDATES.md)
// that the surfel builder in encoder/ reads: the rendering the builder needs, done in samples/.
//
// Per mesh (in the scene file's order; the objects that place a mesh share its candidates):
//   - the box: the bounding box of the mesh's rest-pose positions (vertex states are not
//     followed) and of its spheres;
//   - the views: 8 directions (or 16) from the box's corners towards its centre
//     (capture::SurfelCorners says which corners); each an orthographic camera whose square
//     window of R x R pixels encloses the box's projection (1/1000 margin), its rays starting in
//     front of the box's bounding sphere;
//   - each pixel centre's ray that hits the mesh (its triangles or spheres, in object space)
//     gives one candidate, views in order and pixels row by row from the window's top left: the
//     hit position (on the triangle: barycentric interpolation of its vertices; on a sphere:
//     projected onto it), the geometric normal (the triangle's face normal, as the ray tracer
//     shades; the sphere's radial one) turned to face the view, and one colour per colour set;
//   - colour sets: one per material that objects placing the mesh use, in increasing material
//     order (a mesh no object places has none). A candidate's colour in a set is the unshaded
//     diffuse base colour SCENE.md defines: the material's base colour (the triangle's own
//     material where the mesh has triangle materials) x its texture at the interpolated UV
//     (nearest texel, repeating) x the interpolated vertex colour, stored sRGB-encoded in 8 bits.
//     No lighting, emission, mirror or glass term: a builder takes those from the set's material.
//
// Determinism: every candidate is a pure function of (mesh, view, pixel); rows are traced in
// parallel (TBB) into their own lists joined in order, so the file's bytes do not depend on the
// thread count (as for the ray tracer, Embree's kernels may differ in the last bits across CPUs).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "calf/capture/scene_file.h"
#include "calf/capture/surfel_candidates.h"
#include "calf/format/status.h"
#include "calf/samples/render.h"

namespace calf::samples {

struct SurfelCandidateOptions {
  uint32_t resolution = 512;  // R: G-buffer side in pixels, 1..4096 (the paper uses 1024)
  uint32_t directions = 8;    // 8, or 16 (the 8 and the same turned 45 degrees about +Y)
  capture::SurfelCorners corners = capture::SurfelCorners::kCube;
  uint32_t threads = 0;  // 0: all hardware threads; 1..256 otherwise; output is the same
};
// CALF-E188 for an option outside its range, naming it.
Status validate_surfel_candidate_options(const SurfelCandidateOptions& options);

// The view directions for the box [box_min, box_max] (unit, each pointing from a corner towards
// the centre), in file order: corner k has sign (+ if bit 0 of k, else -) on x, bit 1 on y, bit 2
// on z, i.e. direction k = -(sx, sy, sz) (scaled per axis for kBox); with 16, directions 8..15
// are 0..7 turned 45 degrees about +Y. A zero half extent of the box gives, with kBox, a
// direction in its plane (the paper's rule seeing a flat part edge-on), unless all are zero
// (then kCube's).
std::vector<glm::vec3> surfel_view_directions(const glm::vec3& box_min, const glm::vec3& box_max,
                                              uint32_t directions, capture::SurfelCorners corners);

// The candidates of mesh `index` of `scene` (E188 for bad options or an index out of range,
// E178 when Embree fails). `scene` should be valid (validate_scene_file).
Expected<capture::SurfelCandidates> surfel_candidates_of_mesh(
    const capture::SceneFile& scene, uint32_t index, const SurfelCandidateOptions& options);

struct SurfelCandidateStats {
  uint64_t meshes = 0, candidates = 0, rays = 0, bytes = 0;
  double seconds = 0;
};

// Ray casts every mesh of `scene` and writes the file to `path` record by record (one mesh's
// candidates in memory at a time; capture::SurfelCandidateWriter: whole or nothing). `progress`
// is called after each view of each mesh with (done, meshes x directions). Errors: E188 (options),
// validate_scene_file's (E152-E161), E178, E004 and the writer's.
Expected<SurfelCandidateStats> write_surfel_candidates(const capture::SceneFile& scene,
                                                       const SurfelCandidateOptions& options,
                                                       const std::string& path,
                                                       const ProgressFn& progress);

}  // namespace calf::samples
