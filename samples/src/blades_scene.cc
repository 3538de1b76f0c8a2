// The "blades" scene (paper 004's grass, Table 2): a field of thin grass blades swaying in the
// wind, a few boulders, seen from a view region at eye height over the middle of the field.
//
// The field is 16 x 16 patches of 1.5 m x 1.5 m, each an instance of one of kPrototypes shared
// patches of kBladesPerPatch blades (7 triangles, 9 vertices each). The sway is in piecewise-linear
// vertex states (format/SCENE.md "Vertex states"): kStates states every kStateStep seconds, the
// same for every instance of a patch, the patches out of phase with each other. So the scene
// file holds 4 patches (84,000 triangles with their states) for a field of 5,376,000 triangles.
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
constexpr uint32_t kPrototypes = 4;
constexpr uint32_t kBladesPerPatch = 3000;
constexpr int kPatches = 16;  // per side
constexpr float kPatch = 1.5f;
constexpr uint32_t kStates = 13;
constexpr float kStateStep = 0.25f;  // seconds: 13 states cover 3 s
constexpr double kSwayPeriod = 1.5;  // seconds

enum : uint32_t { kSoil, kGrass0, kGrasses = 3, kRock = kGrass0 + kGrasses };

// One blade's shape: a tapered strip of three quads and a tip, bending along `lean` and swaying
// along the wind, both growing with the square of the height fraction.
struct Blade {
  glm::vec3 base;
  glm::vec3 across;  // half the base width, horizontal
  glm::vec3 lean;    // tip displacement at rest
  float height;
  float phase;  // of the sway, radians
};

constexpr int kLevels = 4;  // vertex pairs at heights 0, 1/4, 1/2, 3/4; one tip vertex at 1

// The blade's 9 vertices with the wind displacing the tip by `sway` (horizontal).
void blade_vertices(const Blade& b, const glm::vec3& sway, glm::vec3* out) {
  for (int j = 0; j <= kLevels; ++j) {
    const float f = static_cast<float>(j) / kLevels;
    const glm::vec3 centre = b.base + glm::vec3(0, b.height * f, 0) + (b.lean + sway) * (f * f);
    if (j == kLevels) {
      out[2 * j] = centre;
    } else {
      const glm::vec3 half = b.across * (1 - 0.8f * f);
      out[2 * j] = centre - half;
      out[2 * j + 1] = centre + half;
    }
  }
}

std::shared_ptr<TriangleMesh> make_patch(uint32_t p) {
  auto mesh = std::make_shared<TriangleMesh>();
  mesh->name = "grass-patch-" + std::to_string(p);
  const uint64_t st = stream_of(0x6245, p);
  std::vector<Blade> blades(kBladesPerPatch);
  for (uint32_t i = 0; i < kBladesPerPatch; ++i) {
    const uint64_t k = 8ull * i;
    Blade& b = blades[i];
    // Bases may reach 5 cm into the neighbouring patch: no seam of bare soil between patches.
    const float half = kPatch / 2 + 0.05f;
    b.base = {uniform(st, k, -half, half), -0.01f, uniform(st, k + 1, -half, half)};
    const float facing = uniform(st, k + 2, 0, static_cast<float>(kTau));
    const float width = uniform(st, k + 3, 0.008f, 0.014f);
    b.across = glm::vec3(std::cos(facing), 0, std::sin(facing)) * (width / 2);
    b.height = uniform(st, k + 4, 0.25f, 0.6f);
    const float lean_dir = uniform(st, k + 5, 0, static_cast<float>(kTau));
    const float lean = uniform(st, k + 6, 0.05f, 0.25f) * b.height;
    b.lean = glm::vec3(std::cos(lean_dir), 0, std::sin(lean_dir)) * lean;
    b.phase = uniform(st, k + 7, 0, 1.2f);
  }
  const uint32_t v = 2 * kLevels + 1;
  mesh->positions.resize(static_cast<size_t>(kBladesPerPatch) * v);
  for (uint32_t i = 0; i < kBladesPerPatch; ++i) {
    blade_vertices(blades[i], glm::vec3(0), &mesh->positions[static_cast<size_t>(i) * v]);
    const uint32_t o = i * v;
    // Counter-clockwise seen from the side `across` x up points to.
    for (uint32_t j = 0; j + 1 < kLevels; ++j) {
      const uint32_t l0 = o + 2 * j, r0 = l0 + 1, l1 = l0 + 2, r1 = l0 + 3;
      mesh->triangles.push_back({l0, r0, r1});
      mesh->triangles.push_back({l0, r1, l1});
    }
    mesh->triangles.push_back({o + 2 * (kLevels - 1), o + 2 * (kLevels - 1) + 1, o + 2 * kLevels});
  }
  // The wind blows along +X with a little +Z; gusts move across the field with x.
  const glm::vec3 wind = glm::normalize(glm::vec3(1, 0, 0.3f));
  const double patch_phase = 1.3 * p;
  mesh->state_times.resize(kStates);
  mesh->state_positions.resize(static_cast<size_t>(kStates) * mesh->positions.size());
  for (uint32_t k = 0; k < kStates; ++k) {
    const float t = kStateStep * static_cast<float>(k);
    mesh->state_times[k] = t;
    for (uint32_t i = 0; i < kBladesPerPatch; ++i) {
      const Blade& b = blades[i];
      const double a = kTau * t / kSwayPeriod + patch_phase + b.phase + 0.8 * b.base.x;
      const float amount = b.height * static_cast<float>(0.12 + 0.1 * std::sin(a));
      blade_vertices(b, wind * amount,
                     &mesh->state_positions[(static_cast<size_t>(k) * kBladesPerPatch + i) * v]);
    }
  }
  return mesh;
}

}  // namespace

Scene blades_scene() {
  Scene s;
  s.name = "blades";
  s.materials = {procedural::diffuse(0.3f, 0.22f, 0.14f), procedural::diffuse(0.25f, 0.5f, 0.12f),
                 procedural::diffuse(0.35f, 0.55f, 0.15f), procedural::diffuse(0.3f, 0.45f, 0.2f),
                 procedural::diffuse(0.5f, 0.48f, 0.45f)};
  const float extent = kPatches * kPatch / 2;
  Object soil;
  soil.name = "soil";
  soil.material = kSoil;
  add_quad(&soil.mesh, {-extent - 2, 0, -extent - 2}, {-extent - 2, 0, extent + 2},
           {extent + 2, 0, extent + 2}, {extent + 2, 0, -extent - 2});
  s.objects.push_back(std::move(soil));

  std::vector<std::shared_ptr<TriangleMesh>> patches;
  for (uint32_t p = 0; p < kPrototypes; ++p) patches.push_back(make_patch(p));
  for (int i = 0; i < kPatches; ++i) {
    for (int j = 0; j < kPatches; ++j) {
      const uint64_t st = stream_of(0x9A7C, static_cast<uint64_t>(i), static_cast<uint64_t>(j));
      Object o;
      o.name = "grass-" + std::to_string(i) + "-" + std::to_string(j);
      o.material = kGrass0 + pick(st, 0, kGrasses);
      o.shared_mesh = patches[pick(st, 1, kPrototypes)];
      const glm::mat4 m =
          glm::translate(glm::mat4(1), {(static_cast<float>(i) - (kPatches - 1) / 2.0f) * kPatch, 0,
                                        (static_cast<float>(j) - (kPatches - 1) / 2.0f) * kPatch});
      o.transform = [m](double) { return m; };
      s.objects.push_back(std::move(o));
    }
  }
  // Boulders: large occluders in the grass, away from the view region.
  Object rocks;
  rocks.name = "boulders";
  rocks.material = kRock;
  const glm::vec4 boulders[] = {{4.0f, 0.0f, -3.0f, 0.9f},
                                {-5.5f, 0.0f, 2.0f, 1.2f},
                                {1.5f, 0.0f, 6.5f, 0.7f},
                                {-2.5f, 0.0f, -7.0f, 1.0f}};
  for (size_t r = 0; r < std::size(boulders); ++r) {
    const glm::vec4 b = boulders[r];
    glm::mat4 m = glm::translate(glm::mat4(1), glm::vec3(b.x, b.w * 0.45f, b.z));
    m = glm::rotate(m, 0.7f * static_cast<float>(r) + 0.3f,
                    glm::normalize(glm::vec3(0.3f, 1, 0.2f)));
    add_box(&rocks.mesh, glm::scale(m, glm::vec3(b.w, b.w * 0.7f, b.w * 0.85f)));
  }
  s.objects.push_back(std::move(rocks));

  s.sky.sun_direction = {0.3f, 0.7f, 0.5f};
  s.sky.sun_irradiance = {2.8f, 2.7f, 2.4f};
  s.ambient = {0.25f, 0.28f, 0.33f};
  s.ao_distance = 0.3f;
  s.fps = 24;
  s.frame_count = 12;
  // 3 m x 3 m over the middle of the field, 1.6 .. 1.8 m high (above the tallest swaying blade).
  s.default_rig = box_rig({0, 1.7, 0}, {1.5, 0.1, 1.5});
  // A slow circle of 0.75 m, looking down into the grass ahead.
  s.validation_path = [](uint32_t frames, double fps, uint32_t w, uint32_t h) {
    capture::EyePath path;
    path.width = w, path.height = h;
    for (uint32_t f = 0; f < frames; ++f) {
      const double a = kTau * f / std::max(1u, frames);
      const glm::dvec3 p(0.75 * std::cos(a), 1.7, 0.75 * std::sin(a));
      const double yaw = a + 1.2;
      path.poses.push_back(
          look_at_pose(f / fps, p, p + glm::dvec3(std::cos(yaw), -0.45, std::sin(yaw)), 70));
    }
    return path;
  };
  s.description = "a field of 24 m x 24 m of thin grass blades swaying in " +
                  std::to_string(kStates) + " vertex states (256 instances of " +
                  std::to_string(kPrototypes) + " patches) and 4 boulders, seen from 1.7 m: " +
                  procedural::with_thousands(s.triangle_count()) + " triangles";
  return s;
}

}  // namespace calf::samples
