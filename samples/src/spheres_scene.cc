// The "spheres" scene (paper 004 Sec. 3.3, dynamic spheres): analytic spheres bouncing on a
// chequered floor, each on its own height, period and slow drift, among four low walls around
// the view region and a ring of pillars; a ball's motion is a translation per frame.
//
// The walls stand on a circle of 1.9 m around the region (2 m x 2 m at eye height), so that from
// its edge some balls are behind a wall and others not; balls move on circles of 3 .. 7 m, never
// reaching a wall, a pillar or the region.
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

#include "procedural.h"
#include "visibility_scenes.h"

namespace calf::samples {

namespace {

using procedural::pick;
using procedural::stream_of;
using procedural::uniform;

constexpr double kTau = 6.283185307179586;
constexpr uint32_t kBalls = 14;

enum : uint32_t { kFloorLight, kFloorDark, kWall, kPillar, kBall0, kBallColours = 5 };

}  // namespace

Scene spheres_scene() {
  Scene s;
  s.name = "spheres";
  s.materials = {procedural::diffuse(0.8f, 0.8f, 0.78f),   procedural::diffuse(0.25f, 0.25f, 0.27f),
                 procedural::diffuse(0.65f, 0.55f, 0.45f), procedural::diffuse(0.5f, 0.52f, 0.6f),
                 procedural::diffuse(0.8f, 0.15f, 0.1f),   procedural::diffuse(0.9f, 0.75f, 0.15f),
                 procedural::diffuse(0.15f, 0.35f, 0.8f),  procedural::diffuse(0.2f, 0.65f, 0.25f),
                 procedural::diffuse(0.7f, 0.3f, 0.7f)};
  Object light, dark;
  light.name = "floor-light";
  light.material = kFloorLight;
  dark.name = "floor-dark";
  dark.material = kFloorDark;
  // A 20 m x 20 m chequerboard of 1 m squares.
  for (int i = 0; i < 20; ++i) {
    for (int j = 0; j < 20; ++j) {
      const float a0 = static_cast<float>(i - 10), a1 = a0 + 1;
      const float b0 = static_cast<float>(j - 10), b1 = b0 + 1;
      add_quad((i + j) % 2 ? &dark.mesh : &light.mesh, {a0, 0, b0}, {a0, 0, b1}, {a1, 0, b1},
               {a1, 0, b0});
    }
  }
  s.objects.push_back(std::move(light));
  s.objects.push_back(std::move(dark));

  // Four walls, 2.4 m long and 1.4 m high (below the eye: balls show above them), tangent to a
  // circle of 1.9 m at 45, 135, 225 and 315 degrees.
  Object walls;
  walls.name = "walls";
  walls.material = kWall;
  for (int w = 0; w < 4; ++w) {
    const float a = static_cast<float>(kTau / 8 + kTau / 4 * w);
    glm::mat4 m = glm::translate(glm::mat4(1), {1.9f * std::cos(a), 0.7f, 1.9f * std::sin(a)});
    m = glm::rotate(m, -a, glm::vec3(0, 1, 0));  // local x along the radius
    add_box(&walls.mesh, glm::scale(m, glm::vec3(0.15f, 0.7f, 1.2f)));
  }
  s.objects.push_back(std::move(walls));
  // Eight pillars, 3 m high, on a circle of 8.5 m.
  Object pillars;
  pillars.name = "pillars";
  pillars.material = kPillar;
  for (int p = 0; p < 8; ++p) {
    const float a = static_cast<float>(kTau / 8 * p + 0.2);
    add_cylinder(
        &pillars.mesh,
        glm::scale(glm::translate(glm::mat4(1), {8.5f * std::cos(a), 1.5f, 8.5f * std::sin(a)}),
                   {0.35f, 1.5f, 0.35f}),
        24);
  }
  s.objects.push_back(std::move(pillars));

  for (uint32_t b = 0; b < kBalls; ++b) {
    const uint64_t st = stream_of(0xBA11, b);
    const float radius = uniform(st, 0, 0.2f, 0.6f);
    const double orbit = uniform(st, 1, 3.0f, 7.0f);
    const double angle = kTau * b / kBalls + uniform(st, 2, -0.2f, 0.2f);
    const double drift = uniform(st, 3, -0.15f, 0.15f);  // radians per second along the orbit
    const double height = uniform(st, 4, 0.4f, 2.2f);
    const double period = uniform(st, 5, 0.6f, 1.4f);  // seconds between bounces
    const double phase = uniform(st, 6, 0, 1);
    Object o;
    o.name = "ball-" + std::to_string(b);
    o.material = kBall0 + pick(st, 7, kBallColours);
    o.spheres.push_back({glm::vec3(0), radius});
    // A bounce is |sin|: the ball touches the floor (y = radius) once per period.
    o.transform = [=](double t) {
      const double a = angle + drift * t;
      const double y = radius + height * std::fabs(std::sin(kTau / 2 * (t / period + phase)));
      return glm::translate(
          glm::mat4(1), glm::vec3(static_cast<float>(orbit * std::cos(a)), static_cast<float>(y),
                                  static_cast<float>(orbit * std::sin(a))));
    };
    s.objects.push_back(std::move(o));
  }

  s.sky.sun_direction = {-0.35f, 0.8f, 0.45f};
  s.sky.sun_irradiance = {2.6f, 2.5f, 2.3f};
  s.ambient = {0.22f, 0.24f, 0.28f};
  s.ao_distance = 1.0f;
  s.fps = 24;
  s.frame_count = 24;
  s.default_rig = box_rig({0, 1.7, 0}, {1, 0.1, 1});
  // A circle of 0.5 m, looking outward and a little down, turning once.
  s.validation_path = [](uint32_t frames, double fps, uint32_t w, uint32_t h) {
    capture::EyePath path;
    path.width = w, path.height = h;
    for (uint32_t f = 0; f < frames; ++f) {
      const double a = kTau * f / std::max(1u, frames);
      const glm::dvec3 p(0.5 * std::cos(a), 1.7, 0.5 * std::sin(a));
      path.poses.push_back(
          look_at_pose(f / fps, p, p + glm::dvec3(std::cos(a), -0.3, std::sin(a)), 70));
    }
    return path;
  };
  s.description = std::to_string(kBalls) +
                  " analytic spheres bouncing on a chequered floor among four low walls around "
                  "the view region and eight pillars: " +
                  procedural::with_thousands(s.triangle_count()) + " triangles and " +
                  std::to_string(s.sphere_count()) + " spheres";
  return s;
}

}  // namespace calf::samples
