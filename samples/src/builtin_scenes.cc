// The built-in animated scenes, one per case of paper 002 (Sec. 7): a turntable object with
// crevices and thin parts (Spaceship), an interior with animation in one area, thin geometry and
// changing light (Sponza / Robot), and a box with a moving mirror sphere and glass sphere
// (ReflectionRefractionBox). All geometry is procedural: nothing to download.
//
// Every surface that can be seen is the only surface on its plane (coplanar visible faces would
// z-fight, and which one wins could depend on the BVH, i.e. on the thread count).
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

#include "calf/samples/scene.h"
#include "visibility_scenes.h"

namespace calf::samples {

namespace {

constexpr double kTau = 6.283185307179586;

Material diffuse(float r, float g, float b) {
  Material m;
  m.albedo = {r, g, b};
  return m;
}

Material emissive(float r, float g, float b) {
  Material m;
  m.albedo = glm::vec3(0);
  m.emission = {r, g, b};
  return m;
}

PointLight constant_light(glm::vec3 position, glm::vec3 intensity) {
  return {[=](double) { return position; }, [=](double) { return intensity; }};
}

Object object(std::string name, uint32_t material, TriangleMesh mesh, TransformAt transform = {}) {
  Object o;
  o.name = std::move(name);
  o.material = material;
  o.mesh = std::move(mesh);
  o.transform = std::move(transform);
  return o;
}

Object sphere_object(std::string name, uint32_t material, float radius, TransformAt transform) {
  Object o;
  o.name = std::move(name);
  o.material = material;
  o.spheres.push_back({glm::vec3(0), radius});
  o.transform = std::move(transform);
  return o;
}

// A checkerboard of n x m quads on the plane y = 0 over [x0, x1] x [z0, z1], split into two
// meshes (one per colour) so that each keeps one material.
void add_checker(TriangleMesh* light, TriangleMesh* dark, float x0, float x1, float z0, float z1,
                 int n, int m) {
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < m; ++j) {
      float a0 = x0 + (x1 - x0) * i / n, a1 = x0 + (x1 - x0) * (i + 1) / n;
      float b0 = z0 + (z1 - z0) * j / m, b1 = z0 + (z1 - z0) * (j + 1) / m;
      add_quad((i + j) % 2 ? dark : light, {a0, 0, b0}, {a0, 0, b1}, {a1, 0, b1}, {a1, 0, b0});
    }
  }
}

glm::mat4 translate(float x, float y, float z) {
  return glm::translate(glm::mat4(1), {x, y, z});
}

// ---- turntable (Spaceship) ---------------------------------------------------------------------

Scene turntable() {
  Scene s;
  s.name = "turntable";
  s.description =
      "a spaceship on a turntable: deep engine crevices, a trench, thin wings, fins and antennas, "
      "HDR engine glow; sky background (Spaceship)";
  s.materials = {diffuse(0.6f, 0.62f, 0.65f), diffuse(0.25f, 0.27f, 0.3f),
                 diffuse(0.7f, 0.15f, 0.1f), emissive(4.0f, 1.8f, 0.6f),
                 diffuse(0.2f, 0.35f, 0.5f)};
  // One quarter turn over the default 30 frames, with a slow bob.
  TransformAt spin = [](double t) {
    glm::mat4 m = translate(0, static_cast<float>(0.05 * std::sin(kTau * t / 2)), 0);
    return glm::rotate(m, static_cast<float>(0.4 + kTau / 4 * t), glm::vec3(0, 1, 0));
  };
  TriangleMesh hull, dark, accent, glow;
  add_box(&hull, {-0.3f, -0.15f, -0.9f}, {0.3f, 0.15f, 0.9f});
  add_box(&hull, {-0.18f, -0.1f, 0.85f}, {0.18f, 0.1f, 1.25f});
  // Trench: two ridges with a gap 0.08 wide and 0.12 deep.
  add_box(&hull, {-0.29f, 0.1f, -0.7f}, {-0.04f, 0.27f, 0.6f});
  add_box(&hull, {0.04f, 0.1f, -0.7f}, {0.29f, 0.27f, 0.6f});
  // Thin wings and wing-tip fins.
  add_box(&dark, {-1.2f, -0.05f, -0.6f}, {1.2f, -0.02f, 0.1f});
  add_box(&accent, {-1.23f, -0.15f, -0.62f}, {-1.19f, 0.25f, -0.1f});
  add_box(&accent, {1.19f, -0.15f, -0.62f}, {1.23f, 0.25f, -0.1f});
  add_box(&accent, {-0.015f, 0.1f, -0.92f}, {0.015f, 0.55f, -0.55f});  // tail fin
  // Hollow engine nacelles open at both ends (deep crevices), hung under the wings with a
  // narrow gap, with a glowing core deep inside.
  for (float x : {-0.8f, 0.8f}) {
    add_box(&dark, {x - 0.15f, -0.09f, -0.9f}, {x + 0.15f, -0.06f, -0.1f});
    add_box(&dark, {x - 0.15f, -0.36f, -0.9f}, {x + 0.15f, -0.33f, -0.1f});
    add_box(&dark, {x - 0.151f, -0.34f, -0.895f}, {x - 0.12f, -0.08f, -0.105f});
    add_box(&dark, {x + 0.12f, -0.34f, -0.895f}, {x + 0.151f, -0.08f, -0.105f});
    add_box(&hull, {x - 0.02f, -0.07f, -0.5f}, {x + 0.02f, -0.01f, -0.3f});  // pylon
    add_box(&glow, {x - 0.1f, -0.3f, -0.7f}, {x + 0.1f, -0.12f, -0.66f});
  }
  // Antennas: cylinders 2 cm thick.
  add_cylinder(&dark, glm::scale(translate(0, 0.47f, -0.3f), {0.01f, 0.2f, 0.01f}), 8);
  add_cylinder(&dark,
               glm::scale(glm::rotate(translate(0.1f, 0.05f, 1.45f), 1.45f, glm::vec3(1, 0, 0)),
                          {0.008f, 0.22f, 0.008f}),
               8);
  add_cylinder(&dark,
               glm::scale(glm::rotate(translate(-0.1f, 0.05f, 1.45f), 1.45f, glm::vec3(1, 0, 0)),
                          {0.008f, 0.22f, 0.008f}),
               8);
  s.objects.push_back(object("hull", 0, std::move(hull), spin));
  s.objects.push_back(object("wings-nacelles", 1, std::move(dark), spin));
  s.objects.push_back(object("fins", 2, std::move(accent), spin));
  s.objects.push_back(object("engine-glow", 3, std::move(glow), spin));
  Object cockpit = sphere_object("cockpit", 4, 0.16f, spin);
  cockpit.spheres[0].center = {0, 0.2f, 0.7f};
  s.objects.push_back(std::move(cockpit));

  s.sky.zenith = {0.02f, 0.03f, 0.06f};
  s.sky.horizon = {0.08f, 0.09f, 0.12f};
  s.sky.ground = {0.03f, 0.03f, 0.04f};
  s.sky.sun_direction = {0.5f, 0.8f, 0.35f};
  s.sky.sun_irradiance = {2.6f, 2.5f, 2.3f};
  s.lights.push_back(constant_light({-2.5f, -1.0f, -2.0f}, {1.5f, 1.8f, 2.4f}));  // blue rim
  s.ambient = {0.2f, 0.22f, 0.28f};
  s.ao_distance = 0.4f;
  s.default_rig = sphere_rig(14, 3.0, glm::dvec3(0));
  // Between the ring of cameras (radius 3) and the ship, a quarter turn against the spin.
  s.validation_path = [](uint32_t frames, double fps, uint32_t w, uint32_t h) {
    capture::EyePath path;
    path.width = w, path.height = h;
    for (uint32_t f = 0; f < frames; ++f) {
      double a = 0.3 - kTau / 4 * f / std::max(1u, frames);
      glm::dvec3 p(2.2 * std::cos(a), 0.5, 2.2 * std::sin(a));
      path.poses.push_back(look_at_pose(f / fps, p, glm::dvec3(0), 50));
    }
    return path;
  };
  return s;
}

// ---- interior (Sponza / Robot) -----------------------------------------------------------------

Scene interior() {
  Scene s;
  s.name = "interior";
  s.description =
      "a colonnaded hall: bouncing balls and a rotating arm in one corner, a pulsing lamp, "
      "thin hanging chains and a potted plant with thin leaves (Sponza / Robot)";
  enum : uint32_t {
    kWall,
    kFloorA,
    kFloorB,
    kStone,
    kIron,
    kLeaf,
    kPot,
    kWood,
    kRed,
    kYellow,
    kBlue,
    kGlow,
    kRobot
  };
  s.materials = {
      diffuse(0.75f, 0.7f, 0.6f),  diffuse(0.8f, 0.78f, 0.72f),  diffuse(0.3f, 0.28f, 0.25f),
      diffuse(0.65f, 0.6f, 0.5f),  diffuse(0.15f, 0.15f, 0.17f), diffuse(0.15f, 0.5f, 0.12f),
      diffuse(0.55f, 0.3f, 0.2f),  diffuse(0.5f, 0.35f, 0.2f),   diffuse(0.8f, 0.1f, 0.1f),
      diffuse(0.85f, 0.75f, 0.1f), diffuse(0.1f, 0.25f, 0.8f),   emissive(6.0f, 3.0f, 1.0f),
      diffuse(0.7f, 0.7f, 0.75f)};
  TriangleMesh walls, floor_a, floor_b, stone, iron, leaves, pot, wood, glow;
  // The room's own floor sits 1 cm below the visible checkerboard.
  add_room(&walls, {-5, -0.01f, -4}, {5, 4, 4});
  add_checker(&floor_a, &floor_b, -5, 5, -4, 4, 10, 8);
  for (float cx : {-3.0f, 0.0f, 3.0f}) {
    for (float cz : {-2.2f, 2.2f}) {
      add_box(&stone, {cx - 0.2f, -0.02f, cz - 0.2f}, {cx + 0.2f, 4.02f, cz + 0.2f});
      add_box(&stone, {cx - 0.3f, -0.02f, cz - 0.3f}, {cx + 0.3f, 0.25f, cz + 0.3f});
      add_box(&stone, {cx - 0.28f, 3.7f, cz - 0.28f}, {cx + 0.28f, 4.02f, cz + 0.28f});
    }
  }
  // Hanging chains (1.6 cm thick) with glowing braziers.
  for (float cx : {-1.5f, 1.5f}) {
    for (float cz : {-1.2f, 1.2f}) {
      add_box(&iron, {cx - 0.008f, 2.6f, cz - 0.008f}, {cx + 0.008f, 4.01f, cz + 0.008f});
      add_box(&iron, {cx - 0.12f, 2.45f, cz - 0.12f}, {cx + 0.12f, 2.6f, cz + 0.12f});
      add_box(&glow, {cx - 0.08f, 2.6f, cz - 0.08f}, {cx + 0.08f, 2.64f, cz + 0.08f});
    }
  }
  // Potted plant: leaves 8 mm thick.
  add_cylinder(&pot, glm::scale(translate(3.8f, 0.3f, -3.2f), {0.3f, 0.3f, 0.3f}), 16);
  for (int k = 0; k < 14; ++k) {
    float yaw = static_cast<float>(kTau * k / 14);
    float tilt = 0.35f + 0.25f * static_cast<float>(k % 3);
    glm::mat4 m = glm::rotate(translate(3.8f, 0.62f + 0.04f * (k % 4), -3.2f), yaw, {0, 1, 0});
    m = glm::rotate(m, tilt, {0, 0, 1});
    add_box(&leaves, m * glm::scale(translate(0.38f, 0, 0), {0.36f, 0.004f, 0.035f}));
  }
  // Table with thin legs.
  add_box(&wood, {-4.2f, 0.75f, 2.2f}, {-2.8f, 0.8f, 3.4f});
  for (float x : {-4.15f, -2.85f}) {
    for (float z : {2.25f, 3.35f})
      add_box(&wood, {x - 0.025f, -0.02f, z - 0.025f}, {x + 0.025f, 0.76f, z + 0.025f});
  }
  s.objects.push_back(object("walls", kWall, std::move(walls)));
  s.objects.push_back(object("floor-light", kFloorA, std::move(floor_a)));
  s.objects.push_back(object("floor-dark", kFloorB, std::move(floor_b)));
  s.objects.push_back(object("columns", kStone, std::move(stone)));
  s.objects.push_back(object("chains", kIron, std::move(iron)));
  s.objects.push_back(object("braziers", kGlow, std::move(glow)));
  s.objects.push_back(object("leaves", kLeaf, std::move(leaves)));
  s.objects.push_back(object("pot", kPot, std::move(pot)));
  s.objects.push_back(object("table", kWood, std::move(wood)));
  // The animated corner: three bouncing balls and a rotating arm.
  struct Ball {
    float x, z, r, phase;
    uint32_t material;
  };
  for (Ball b : {Ball{2.2f, 1.4f, 0.22f, 0.0f, kRed}, Ball{2.8f, 1.9f, 0.18f, 0.9f, kYellow},
                 Ball{3.3f, 1.2f, 0.25f, 2.0f, kBlue}}) {
    s.objects.push_back(sphere_object("ball", b.material, b.r, [b](double t) {
      double y = b.r + 1.2 * std::fabs(std::sin(kTau / 2 * t + b.phase));
      return translate(b.x, static_cast<float>(y), b.z);
    }));
  }
  TriangleMesh pedestal, arm;
  add_cylinder(&pedestal, glm::scale(translate(2.8f, 0.4f, -1.5f), {0.15f, 0.43f, 0.15f}), 16);
  add_box(&arm, {-0.05f, -0.05f, -0.05f}, {0.9f, 0.05f, 0.05f});
  add_box(&arm, {0.8f, -0.15f, -0.04f}, {0.86f, 0.05f, 0.04f});
  s.objects.push_back(object("pedestal", kRobot, std::move(pedestal)));
  s.objects.push_back(object("arm", kRobot, std::move(arm), [](double t) {
    return glm::rotate(translate(2.8f, 0.87f, -1.5f), static_cast<float>(kTau / 3 * t),
                       glm::vec3(0, 1, 0));
  }));

  s.lights.push_back(constant_light({0, 3.6f, 0}, {20, 19, 17}));
  // The lamp over the animated corner pulses in power and warms in colour.
  s.lights.push_back({[](double) { return glm::vec3(2.6f, 2.8f, 1.2f); },
                      [](double t) {
                        float k = static_cast<float>(0.55 + 0.45 * std::sin(kTau * t / 1.5));
                        return glm::vec3(9.0f, 5.0f + 2 * k, 2.5f) * k;
                      }});
  s.ambient = {0.08f, 0.08f, 0.09f};
  s.ao_distance = 0.8f;
  s.default_rig = box_rig({0, 1.6, 0}, {0.5, 0.3, 0.5});
  // A loop inside the box, away from centre and corners, sweeping the gaze across the hall with
  // the animated corner in the middle of the sweep.
  s.validation_path = [](uint32_t frames, double fps, uint32_t w, uint32_t h) {
    capture::EyePath path;
    path.width = w, path.height = h;
    for (uint32_t f = 0; f < frames; ++f) {
      double a = kTau * f / std::max(1u, frames);
      glm::dvec3 p(0.3 * std::cos(a), 1.6 + 0.12 * std::sin(2 * a), 0.3 * std::sin(a));
      double yaw = 0.5 + 1.2 * std::sin(a);
      path.poses.push_back(
          look_at_pose(f / fps, p, p + glm::dvec3(std::cos(yaw), -0.25, std::sin(yaw)), 70));
    }
    return path;
  };
  return s;
}

// ---- mirror-box (ReflectionRefractionBox) ------------------------------------------------------

Scene mirror_box() {
  Scene s;
  s.name = "mirror-box";
  s.description =
      "a coloured box with an orbiting mirror sphere, a sliding glass sphere and a spinning cube; "
      "writes material channels (ReflectionRefractionBox)";
  enum : uint32_t {
    kWhite,
    kRed,
    kGreen,
    kFloorA,
    kFloorB,
    kMirror,
    kGlass,
    kPanel,
    kBlue,
    kYellow
  };
  Material mirror = diffuse(0.9f, 0.9f, 0.9f);
  mirror.reflect = 0.9f;
  Material glass = diffuse(1, 1, 1);
  glass.refract = 0.92f;
  glass.reflect = 0.08f;
  glass.ior = 1.5f;
  s.materials = {diffuse(0.75f, 0.75f, 0.75f),
                 diffuse(0.7f, 0.12f, 0.1f),
                 diffuse(0.12f, 0.6f, 0.15f),
                 diffuse(0.8f, 0.8f, 0.8f),
                 diffuse(0.25f, 0.25f, 0.25f),
                 mirror,
                 glass,
                 emissive(12, 11, 10),
                 diffuse(0.15f, 0.3f, 0.75f),
                 diffuse(0.8f, 0.7f, 0.2f)};
  TriangleMesh white, red, green, floor_a, floor_b, panel, pillar;
  add_checker(&floor_a, &floor_b, -2, 2, -2, 2, 8, 8);
  add_quad(&white, {-2, 3, -2}, {2, 3, -2}, {2, 3, 2}, {-2, 3, 2});    // ceiling, facing down
  add_quad(&white, {-2, 0, -2}, {2, 0, -2}, {2, 3, -2}, {-2, 3, -2});  // back, facing +z
  add_quad(&white, {2, 0, 2}, {-2, 0, 2}, {-2, 3, 2}, {2, 3, 2});      // front, facing -z
  add_quad(&red, {-2, 0, 2}, {-2, 0, -2}, {-2, 3, -2}, {-2, 3, 2});    // left, facing +x
  add_quad(&green, {2, 0, -2}, {2, 0, 2}, {2, 3, 2}, {2, 3, -2});      // right, facing -x
  add_box(&panel, {-0.5f, 2.97f, -0.5f}, {0.5f, 2.99f, 0.5f});
  add_cylinder(&pillar, glm::scale(translate(-1.3f, 0.5f, 1.2f), {0.15f, 0.5f, 0.15f}), 24);
  s.objects.push_back(object("ceiling-back-front", kWhite, std::move(white)));
  s.objects.push_back(object("left-wall", kRed, std::move(red)));
  s.objects.push_back(object("right-wall", kGreen, std::move(green)));
  s.objects.push_back(object("floor-light", kFloorA, std::move(floor_a)));
  s.objects.push_back(object("floor-dark", kFloorB, std::move(floor_b)));
  s.objects.push_back(object("light-panel", kPanel, std::move(panel)));
  s.objects.push_back(object("pillar", kYellow, std::move(pillar)));
  s.objects.push_back(sphere_object("mirror-sphere", kMirror, 0.45f, [](double t) {
    double a = kTau / 2 * t;
    return translate(static_cast<float>(0.6 * std::cos(a)),
                     static_cast<float>(0.75 + 0.1 * std::sin(2 * a)),
                     static_cast<float>(0.6 * std::sin(a)));
  }));
  s.objects.push_back(sphere_object("glass-sphere", kGlass, 0.38f, [](double t) {
    return translate(static_cast<float>(-1.1 + 0.4 * std::sin(kTau * t / 1.5)), 0.4f, -1.4f);
  }));
  TriangleMesh cube;
  add_box(&cube, {-0.2f, 0.0f, -0.2f}, {0.2f, 0.4f, 0.2f});
  s.objects.push_back(object("cube", kBlue, std::move(cube), [](double t) {
    return glm::rotate(translate(1.1f, 0, 1.0f), static_cast<float>(kTau / 4 * t),
                       glm::vec3(0, 1, 0));
  }));
  s.lights.push_back(constant_light({0, 2.85f, 0}, {8, 7.6f, 7}));
  s.ambient = {0.12f, 0.12f, 0.12f};
  s.ao_distance = 0.6f;
  s.default_rig = box_rig({0, 1.75, 0}, {0.6, 0.35, 0.6});
  // Circling the rig's centre at a third of the way to the corners, looking at the spheres.
  s.validation_path = [](uint32_t frames, double fps, uint32_t w, uint32_t h) {
    capture::EyePath path;
    path.width = w, path.height = h;
    for (uint32_t f = 0; f < frames; ++f) {
      double a = 0.8 + kTau * f / std::max(1u, frames);
      glm::dvec3 p(0.35 * std::cos(a), 1.75 + 0.1 * std::sin(2 * a), 0.35 * std::sin(a));
      path.poses.push_back(look_at_pose(f / fps, p, glm::dvec3(-0.3, 0.6, -0.6), 60));
    }
    return path;
  };
  return s;
}

}  // namespace

const std::vector<SceneInfo>& builtin_scenes() {
  static const std::vector<SceneInfo> list = {
      {"turntable", "a spaceship on a turntable with crevices and thin parts (paper: Spaceship)"},
      {"interior",
       "a hall with animation in one corner, thin geometry, changing light (Sponza/Robot)"},
      {"mirror-box", "a box with a moving mirror sphere and glass sphere, material output"},
      {"city",
       "streets of instanced buildings with windows, seen from a crossing: 1,417,070 triangles"},
      {"blades", "a field of thin grass blades swaying in vertex states: 5,376,050 triangles"},
      {"spheres", "bouncing analytic spheres among walls and pillars: 1,616 triangles, 14 spheres"},
      {"factory", "a machine hall of instanced CAD parts seen from an aisle: 28,075,486 triangles"},
  };
  return list;
}

Expected<Scene> make_builtin_scene(std::string_view name) {
  if (name == "turntable") return turntable();
  if (name == "interior") return interior();
  if (name == "mirror-box") return mirror_box();
  if (name == "city") return city_scene();
  if (name == "blades") return blades_scene();
  if (name == "spheres") return spheres_scene();
  if (name == "factory") return factory_scene();
  return Status(ErrorId::kSceneUnknown, "no built-in scene '" + std::string(name) + "'");
}

}  // namespace calf::samples
