// Private to samples/: the CAD-like parts of the "factory" scene (factory_scene.cc) and the
// procedural surfaces they are built from. Every part is a closed, outward-wound mesh in its own
// frame (metres, +Y up unless a part says otherwise), made once and instanced many times, with
// 10k-200k triangles of real detail: gear teeth, helical threads, cooling fins, swept pipe bends.
//
// Surfaces of revolution and their kin wind as add_cylinder does (scene.h): a ring's angle a grows
// from +X towards -Z, a point at radius r and height y lies at (r cos a, y, -r sin a), and a
// profile traced counter-clockwise in the (r, y) half-plane (r to the right, y up) gives outward
// normals. A profile point on the axis (r = 0) is one vertex, not a ring, so caps have no
// degenerate triangles.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "calf/samples/scene.h"

namespace calf::samples::factory {

// ---- surfaces --------------------------------------------------------------------------------

// One point of a revolved profile: radius r at height y; with `on_outline`, r is an inset from
// the outline's radius at each angle (add_outline_revolution) instead of a radius.
struct ProfilePoint {
  float r = 0;
  float y = 0;
  bool on_outline = false;
};

// The closed profile revolved about local +Y through `m` with `segments` (>= 3) ring vertices;
// the ring starts at angle `phase` (radians). Edges join consecutive points and the last to the
// first; an edge along the axis adds nothing.
void add_revolution(TriangleMesh* mesh, const glm::mat4& m,
                    const std::vector<ProfilePoint>& profile, uint32_t segments, float phase = 0);

// A revolution whose rings follow a star-shaped outline instead of a circle: ring vertex s lies at
// angle angles[s] (strictly increasing over less than one turn from angles[0]) and radius
// radii[s] - p.r for outline points, p.r for the others. A gear's toothed rim with its round bore,
// or a finned motor body, is one such profile.
void add_outline_revolution(TriangleMesh* mesh, const glm::mat4& m,
                            const std::vector<ProfilePoint>& profile,
                            const std::vector<float>& angles, const std::vector<float>& radii);

// A threaded shaft about local +Y from y0 to y1: a V thread of `pitch` (right-handed) and `depth`
// on a core of radius `core`, `segments` vertices around and `rows_per_pitch` rings per turn,
// closed by flat caps.
void add_threaded_shaft(TriangleMesh* mesh, const glm::mat4& m, float core, float depth,
                        float pitch, float y0, float y1, uint32_t segments,
                        uint32_t rows_per_pitch);

// A tube of `radius` swept along the polyline `path` (>= 2 points, no two consecutive equal),
// rings of `segments` vertices turned along the path by parallel transport. Open at both ends:
// cap them with something solid (the pipe's flanges).
void add_tube(TriangleMesh* mesh, const std::vector<glm::vec3>& path, float radius,
              uint32_t segments);

// A frame at `origin` whose local +Y is `axis` (unit): for placing a revolution along any axis.
glm::mat4 frame_along(const glm::vec3& origin, const glm::vec3& axis);

// ---- parts -----------------------------------------------------------------------------------

// A spur gear in the XZ plane (axle along +Y, faces at y = 0 and y = width): `teeth` teeth of
// module `module` (pitch radius = module * teeth / 2), chamfered rim, a web with a hub and a bore.
std::shared_ptr<TriangleMesh> make_gear(const char* name, uint32_t teeth, float module,
                                        float width);
// The pitch radius of make_gear's gear: module * teeth / 2.
inline float gear_pitch_radius(uint32_t teeth, float module) {
  return module * static_cast<float>(teeth) / 2;
}

// A threaded stud of `diameter` holding a plate whose top is y = 0: a washer and a hex nut on the
// plate and the thread standing `protrusion` above the nut (it reaches 0.02 m into the plate).
std::shared_ptr<TriangleMesh> make_stud(float diameter, float protrusion);

// A totally enclosed fan-cooled motor lying along +X (shaft end at +X), centre line at height
// `axis_height` above feet standing on y = 0: a finned body, end shields, a ribbed fan cowl, a
// terminal box and a shaft.
std::shared_ptr<TriangleMesh> make_motor(float radius, float length, float axis_height);

// A pipe run from a flange at the origin pointing +Y, through `bends` alternating 90-degree bends,
// to a flange at its other end; radius `radius`. `variant` picks the run's shape.
std::shared_ptr<TriangleMesh> make_pipe(float radius, uint32_t variant);

// A machine base: a ribbed cast bed of `length` along X on y = 0 with a headstock, a control
// cabinet with buttons and a spindle.
std::shared_ptr<TriangleMesh> make_machine_bed(float length);

// A conveyor section of `length` along X: side rails on legs and rollers, belt-less.
std::shared_ptr<TriangleMesh> make_conveyor(float length);

// A pallet rack of `bays` bays along X, its front at z = 0 and a wall behind it (-Z): the steel
// frame, and the pallets with crates and drums that `seed` picks (two meshes, two materials).
struct RackMeshes {
  std::shared_ptr<TriangleMesh> frame, loads;
};
RackMeshes make_rack(uint32_t bays, uint32_t seed);

// A steel column (an I-beam of `height` on a base plate) and a roof truss girder of `length`
// along Z at its own height.
std::shared_ptr<TriangleMesh> make_column(float height);
std::shared_ptr<TriangleMesh> make_girder(float length);

}  // namespace calf::samples::factory
