// The "city" scene (paper 004's city, Table 2): a grid of blocks of buildings of varied height,
// with protruding windows, sills, floor ledges, parapets and rooftop sheds as real geometry, street
// lamps and a few cars driving; the view region is a street crossing at eye height, from which
// most of the city is hidden behind the first row of facades.
//
// Layout: 8 x 8 blocks of 36 m on a 48 m pitch (12 m streets); street lines at x, z = 48 k for
// k = -4 .. 4, the crossing of the view region at the origin. Each block stands on a 0.15 m
// sidewalk platform and holds 8 buildings on the lots of a 3 x 3 grid around an empty courtyard.
// A building is one of kPrototypes shared wall meshes and its matching window mesh (so walls and
// windows keep their own materials), placed with a quarter-turn rotation; the scene file stores
// each prototype once and each building as two 48-byte placements.
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
constexpr int kBlocks = 8;          // per side
constexpr float kPitch = 48;        // block + street
constexpr float kBlock = 36;        // block side
constexpr float kLot = 12;          // 3 x 3 lots per block
constexpr float kHalfWidth = 5;     // buildings are 10 m x 10 m
constexpr float kPlatform = 0.15f;  // sidewalk height
constexpr float kFloorHeight = 3.2f;
constexpr uint32_t kPrototypes = 20;

enum : uint32_t {
  kAsphalt,
  kSidewalk,
  kFacade0,  // kFacades facade colours follow
  kFacades = 5,
  kWindow = kFacade0 + kFacades,
  kMetal,
  kLampGlow,
  kCar0,  // kCars car colours follow
  kCars = 3,
};

// One building type: a body with windows, sills and ledges. Walls and windows are two meshes.
struct BuildingMeshes {
  std::shared_ptr<TriangleMesh> walls, windows;
};

glm::mat4 box_at(const glm::mat4& frame, const glm::vec3& lo, const glm::vec3& hi) {
  return glm::scale(glm::translate(frame, (lo + hi) * 0.5f), (hi - lo) * 0.5f);
}

BuildingMeshes make_building(uint32_t p) {
  const uint64_t st = stream_of(0xC171, p);
  const int floors = 2 + static_cast<int>(pick(st, 0, 11));  // 2 .. 12
  const int columns = 3 + static_cast<int>(pick(st, 1, 2));  // windows per facade and floor
  const float window_w = uniform(st, 2, 1.1f, 1.7f);
  const float window_h = uniform(st, 3, 1.3f, 1.8f);
  const bool ledge_every_floor = pick(st, 4, 2) == 0;
  const bool shed = pick(st, 5, 3) != 0;
  const float top = kPlatform + static_cast<float>(floors) * kFloorHeight;
  BuildingMeshes b;
  b.walls = std::make_shared<TriangleMesh>();
  b.windows = std::make_shared<TriangleMesh>();
  b.walls->name = "building-" + std::to_string(p) + "-walls";
  b.windows->name = "building-" + std::to_string(p) + "-windows";
  TriangleMesh& walls = *b.walls;
  TriangleMesh& windows = *b.windows;
  // The body reaches into the platform so that no face lies on the platform's top.
  add_box(&walls, {-kHalfWidth, -0.3f, -kHalfWidth}, {kHalfWidth, top, kHalfWidth});
  for (int f = 1; f < floors; ++f) {
    if (!ledge_every_floor && f % 2) continue;
    const float y = kPlatform + static_cast<float>(f) * kFloorHeight - 0.1f;
    add_box(&walls, {-kHalfWidth - 0.2f, y, -kHalfWidth - 0.2f},
            {kHalfWidth + 0.2f, y + 0.2f, kHalfWidth + 0.2f});
  }
  // Parapet: four walls without shared faces (the side ones stop short of the front and back).
  const float t = 0.3f, h = 1.0f, e = kHalfWidth;
  add_box(&walls, {-e, top - 0.1f, -e}, {e, top + h, -e + t});
  add_box(&walls, {-e, top - 0.1f, e - t}, {e, top + h, e});
  add_box(&walls, {-e, top - 0.1f, -e + t + 0.01f}, {-e + t, top + h, e - t - 0.01f});
  add_box(&walls, {e - t, top - 0.1f, -e + t + 0.01f}, {e, top + h, e - t - 0.01f});
  if (shed) add_box(&walls, {-2.0f, top - 0.1f, -1.5f}, {1.5f, top + 2.6f, 2.0f});
  // Windows on the four facades: a pane standing 6 cm proud of the wall on a sill 15 cm deep,
  // both reaching 5 cm into the wall; the ground floor too (shop windows of the same grid).
  for (int side = 0; side < 4; ++side) {
    const glm::mat4 frame =
        glm::rotate(glm::mat4(1), static_cast<float>(kTau / 4 * side), glm::vec3(0, 1, 0));
    for (int f = 0; f < floors; ++f) {
      const float y0 = kPlatform + static_cast<float>(f) * kFloorHeight + 0.9f;
      for (int c = 0; c < columns; ++c) {
        const float cx =
            -e + (2 * e) * (static_cast<float>(c) + 0.5f) / static_cast<float>(columns);
        const float hw = window_w * 0.5f;
        add_box(&windows, box_at(frame, {cx - hw, y0 - 0.02f, e - 0.05f},
                                 {cx + hw, y0 + window_h, e + 0.06f}));
        add_box(&windows, box_at(frame, {cx - hw - 0.1f, y0 - 0.14f, e - 0.05f},
                                 {cx + hw + 0.1f, y0, e + 0.15f}));
      }
    }
  }
  return b;
}

// A street lamp: a pole and a head, standing on the platform.
std::shared_ptr<TriangleMesh> make_lamp() {
  auto lamp = std::make_shared<TriangleMesh>();
  lamp->name = "street-lamp";
  add_cylinder(lamp.get(),
               glm::scale(glm::translate(glm::mat4(1), {0, 2.6f, 0}), {0.09f, 2.6f, 0.09f}), 12);
  add_box(lamp.get(), {-0.2f, 5.1f, -0.3f}, {0.2f, 5.35f, 0.3f});
  return lamp;
}

// A car: body, cabin and four wheels, 4.2 m long along +Z.
std::shared_ptr<TriangleMesh> make_car() {
  auto car = std::make_shared<TriangleMesh>();
  car->name = "car";
  add_box(car.get(), {-0.85f, 0.3f, -2.1f}, {0.85f, 0.95f, 2.1f});
  add_box(car.get(), {-0.75f, 0.94f, -1.2f}, {0.75f, 1.45f, 0.9f});
  for (float x : {-0.86f, 0.86f}) {
    for (float z : {-1.35f, 1.35f}) {
      const glm::mat4 m = glm::rotate(glm::translate(glm::mat4(1), {x, 0.33f, z}),
                                      static_cast<float>(kTau / 4), glm::vec3(0, 0, 1));
      add_cylinder(car.get(), glm::scale(m, {0.33f, 0.12f, 0.33f}), 12);
    }
  }
  return car;
}

Object placed(std::string name, uint32_t material, std::shared_ptr<const TriangleMesh> mesh,
              TransformAt transform) {
  Object o;
  o.name = std::move(name);
  o.material = material;
  o.shared_mesh = std::move(mesh);
  o.transform = std::move(transform);
  return o;
}

// Street line k (-4 .. 4) at 48 k; block j (0 .. 7) between lines j - 4 and j - 3.
float block_centre(int j) {
  return (static_cast<float>(j) - 3.5f) * kPitch;
}

}  // namespace

Scene city_scene() {
  Scene s;
  s.name = "city";
  s.materials = {procedural::diffuse(0.18f, 0.18f, 0.19f), procedural::diffuse(0.55f, 0.53f, 0.5f),
                 procedural::diffuse(0.72f, 0.62f, 0.5f),  procedural::diffuse(0.6f, 0.35f, 0.28f),
                 procedural::diffuse(0.75f, 0.74f, 0.7f),  procedural::diffuse(0.45f, 0.47f, 0.5f),
                 procedural::diffuse(0.8f, 0.7f, 0.45f),   procedural::diffuse(0.12f, 0.16f, 0.22f),
                 procedural::diffuse(0.3f, 0.3f, 0.32f)};
  Material glow;
  glow.albedo = glm::vec3(0);
  glow.emission = {6.0f, 5.2f, 3.8f};
  s.materials.push_back(glow);
  s.materials.push_back(procedural::diffuse(0.7f, 0.1f, 0.08f));
  s.materials.push_back(procedural::diffuse(0.1f, 0.25f, 0.6f));
  s.materials.push_back(procedural::diffuse(0.85f, 0.85f, 0.8f));

  // Ground: streets under everything; the platforms sit on it.
  const float extent = kBlocks / 2 * kPitch + 30;
  Object ground;
  ground.name = "streets";
  ground.material = kAsphalt;
  add_quad(&ground.mesh, {-extent, 0, -extent}, {-extent, 0, extent}, {extent, 0, extent},
           {extent, 0, -extent});
  Object platforms;
  platforms.name = "sidewalks";
  platforms.material = kSidewalk;
  for (int i = 0; i < kBlocks; ++i) {
    for (int j = 0; j < kBlocks; ++j) {
      const float x = block_centre(i), z = block_centre(j), b = kBlock / 2;
      add_box(&platforms.mesh, {x - b, -0.1f, z - b}, {x + b, kPlatform, z + b});
    }
  }
  s.objects.push_back(std::move(ground));
  s.objects.push_back(std::move(platforms));

  std::vector<BuildingMeshes> types;
  for (uint32_t p = 0; p < kPrototypes; ++p) types.push_back(make_building(p));
  for (int i = 0; i < kBlocks; ++i) {
    for (int j = 0; j < kBlocks; ++j) {
      for (int lot = 0; lot < 9; ++lot) {
        if (lot == 4) continue;  // the courtyard
        const uint64_t st =
            stream_of(0xB10C, static_cast<uint64_t>(i * kBlocks + j), static_cast<uint64_t>(lot));
        const uint32_t type = pick(st, 0, kPrototypes);
        const uint32_t facade = kFacade0 + pick(st, 1, kFacades);
        const float angle = static_cast<float>(kTau / 4 * pick(st, 2, 4));
        const glm::vec3 at(block_centre(i) + (static_cast<float>(lot % 3) - 1) * kLot, 0,
                           block_centre(j) + (static_cast<float>(lot / 3) - 1) * kLot);
        const glm::mat4 m =
            glm::rotate(glm::translate(glm::mat4(1), at), angle, glm::vec3(0, 1, 0));
        TransformAt still = [m](double) { return m; };
        const std::string name =
            "building-" + std::to_string(i) + "-" + std::to_string(j) + "-" + std::to_string(lot);
        s.objects.push_back(placed(name, facade, types[type].walls, still));
        s.objects.push_back(placed(name + "-windows", kWindow, types[type].windows, still));
      }
    }
  }

  // Lamps on the four corners of every inner crossing, on the platforms.
  auto lamp = make_lamp();
  for (int a = -3; a <= 3; ++a) {
    for (int b = -3; b <= 3; ++b) {
      for (int corner = 0; corner < 4; ++corner) {
        const float sx = corner & 1 ? 1.0f : -1.0f, sz = corner & 2 ? 1.0f : -1.0f;
        const glm::vec3 at(static_cast<float>(a) * kPitch + sx * 6.6f, kPlatform - 0.05f,
                           static_cast<float>(b) * kPitch + sz * 6.6f);
        const glm::mat4 m = glm::translate(glm::mat4(1), at);
        s.objects.push_back(placed(
            "lamp-" + std::to_string(a) + "-" + std::to_string(b) + "-" + std::to_string(corner),
            kMetal, lamp, [m](double) { return m; }));
      }
    }
  }

  // Cars driving along the two streets of the crossing and a parallel one, away from the view
  // region (their roofs stay below 1.5 m, under the eye).
  auto car = make_car();
  struct Drive {
    float x, z, speed;  // start and speed along the street (m/s)
    bool along_x;
  };
  const Drive drives[] = {{-3.0f, -60.0f, 9.0f, false},       {3.0f, 40.0f, -11.0f, false},
                          {-3.0f, 110.0f, -8.0f, false},      {-70.0f, 3.0f, 10.0f, true},
                          {55.0f, -3.0f, -9.0f, true},        {-3.0f, -150.0f, 12.0f, false},
                          {48.0f - 3.0f, -30.0f, 7.0f, false}};
  for (size_t c = 0; c < std::size(drives); ++c) {
    const Drive d = drives[c];
    s.objects.push_back(placed(
        "car-" + std::to_string(c), kCar0 + static_cast<uint32_t>(c % kCars), car, [d](double t) {
          const float travel = static_cast<float>(d.speed * t);
          glm::vec3 at =
              d.along_x ? glm::vec3(d.x + travel, 0, d.z) : glm::vec3(d.x, 0, d.z + travel);
          float heading = d.along_x ? static_cast<float>(kTau / 4) : 0.0f;
          if (d.speed < 0) heading += static_cast<float>(kTau / 2);
          return glm::rotate(glm::translate(glm::mat4(1), at), heading, glm::vec3(0, 1, 0));
        }));
  }

  s.sky.sun_direction = {0.45f, 0.75f, 0.3f};
  s.sky.sun_irradiance = {3.0f, 2.9f, 2.6f};
  s.ambient = {0.25f, 0.27f, 0.32f};
  s.ao_distance = 2.0f;
  s.fps = 24;
  s.frame_count = 12;
  // The crossing at eye height: 6 m x 6 m inside the 12 m x 12 m crossing, 1.6 .. 1.8 m high.
  s.default_rig = box_rig({0, 1.7, 0}, {3, 0.1, 3});
  // A walk on a circle of 1.5 m around the crossing's centre, the gaze turning along the streets.
  s.validation_path = [](uint32_t frames, double fps, uint32_t w, uint32_t h) {
    capture::EyePath path;
    path.width = w, path.height = h;
    for (uint32_t f = 0; f < frames; ++f) {
      const double a = kTau * f / std::max(1u, frames);
      const glm::dvec3 p(1.5 * std::cos(a), 1.7, 1.5 * std::sin(a));
      const double yaw = a + 0.4;
      path.poses.push_back(
          look_at_pose(f / fps, p, p + glm::dvec3(std::cos(yaw), 0.05, std::sin(yaw)), 70));
    }
    return path;
  };
  s.description = "a city of 8 x 8 blocks, 512 buildings of " + std::to_string(kPrototypes) +
                  " instanced types with protruding windows, sills, ledges and parapets, street "
                  "lamps and moving cars, seen from a street crossing at eye height: " +
                  procedural::with_thousands(s.triangle_count()) + " triangles";
  return s;
}

}  // namespace calf::samples
