// The factory's parts (factory_parts.h): procedural surfaces and the CAD-like parts built from
// them. Sizes are metres; every part is deterministic (no random numbers but the rack's loads,
// which come from procedural.h's counter-based hash).
#include "factory_parts.h"

#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

#include "procedural.h"

namespace calf::samples::factory {

namespace {

constexpr float kTau = 6.2831853f;

glm::vec3 apply(const glm::mat4& m, const glm::vec3& p) {
  return glm::vec3(m * glm::vec4(p, 1));
}

// Appends a triangle, reversed when `flip` (a mirroring transform reverses the winding).
void triangle(TriangleMesh* mesh, bool flip, uint32_t a, uint32_t b, uint32_t c) {
  mesh->triangles.push_back(flip ? glm::uvec3(a, c, b) : glm::uvec3(a, b, c));
}

// The revolution of add_revolution / add_outline_revolution: rings at `angles`, each profile
// point's radius at ring vertex s from `radius(point, s)`.
template <class RadiusFn>
void revolve(TriangleMesh* mesh, const glm::mat4& m, const std::vector<ProfilePoint>& profile,
             const std::vector<float>& angles, const RadiusFn& radius) {
  const size_t n = angles.size(), count = profile.size();
  const bool flip = glm::determinant(glm::mat3(m)) < 0;
  std::vector<uint32_t> first(count);
  std::vector<char> axis(count);
  for (size_t k = 0; k < count; ++k) {
    const ProfilePoint& p = profile[k];
    first[k] = static_cast<uint32_t>(mesh->positions.size());
    axis[k] = !p.on_outline && p.r == 0;
    if (axis[k]) {
      mesh->positions.push_back(apply(m, {0, p.y, 0}));
      continue;
    }
    for (size_t s = 0; s < n; ++s) {
      const float r = radius(p, s);
      mesh->positions.push_back(apply(m, {r * std::cos(angles[s]), p.y, -r * std::sin(angles[s])}));
    }
  }
  auto at = [&](size_t k, size_t s) {
    return axis[k] ? first[k] : first[k] + static_cast<uint32_t>(s % n);
  };
  for (size_t k = 0; k < count; ++k) {
    const size_t k1 = (k + 1) % count;
    if (axis[k] && axis[k1]) continue;
    for (size_t s = 0; s < n; ++s) {
      const uint32_t v0 = at(k, s), v1 = at(k, s + 1), v2 = at(k1, s + 1), v3 = at(k1, s);
      if (!axis[k]) triangle(mesh, flip, v0, v1, v2);
      if (!axis[k1]) triangle(mesh, flip, v0, v2, v3);
    }
  }
}

std::vector<float> uniform_angles(uint32_t segments, float phase) {
  std::vector<float> a(segments);
  for (uint32_t s = 0; s < segments; ++s) {
    a[s] = phase + kTau * static_cast<float>(s) / static_cast<float>(segments);
  }
  return a;
}

glm::mat4 translate(float x, float y, float z) {
  return glm::translate(glm::mat4(1), {x, y, z});
}

void box(TriangleMesh* mesh, float x0, float y0, float z0, float x1, float y1, float z1) {
  add_box(mesh, {x0, y0, z0}, {x1, y1, z1});
}

// A revolution about local +Y at `origin`, the axis turned to `axis`.
void revolve_along(TriangleMesh* mesh, const glm::vec3& origin, const glm::vec3& axis,
                   const std::vector<ProfilePoint>& profile, uint32_t segments, float phase = 0) {
  add_revolution(mesh, frame_along(origin, axis), profile, segments, phase);
}

}  // namespace

void add_revolution(TriangleMesh* mesh, const glm::mat4& m,
                    const std::vector<ProfilePoint>& profile, uint32_t segments, float phase) {
  revolve(mesh, m, profile, uniform_angles(segments, phase),
          [](const ProfilePoint& p, size_t) { return p.r; });
}

void add_outline_revolution(TriangleMesh* mesh, const glm::mat4& m,
                            const std::vector<ProfilePoint>& profile,
                            const std::vector<float>& angles, const std::vector<float>& radii) {
  revolve(mesh, m, profile, angles,
          [&](const ProfilePoint& p, size_t s) { return p.on_outline ? radii[s] - p.r : p.r; });
}

void add_threaded_shaft(TriangleMesh* mesh, const glm::mat4& m, float core, float depth,
                        float pitch, float y0, float y1, uint32_t segments,
                        uint32_t rows_per_pitch) {
  const bool flip = glm::determinant(glm::mat3(m)) < 0;
  const uint32_t rows = std::max(
      1u,
      static_cast<uint32_t>(std::lround((y1 - y0) / pitch * static_cast<float>(rows_per_pitch))));
  const uint32_t base = static_cast<uint32_t>(mesh->positions.size());
  for (uint32_t j = 0; j <= rows; ++j) {
    const float y = y0 + (y1 - y0) * static_cast<float>(j) / static_cast<float>(rows);
    for (uint32_t s = 0; s < segments; ++s) {
      const float a = kTau * static_cast<float>(s) / static_cast<float>(segments);
      // Along a right-handed helix y / pitch - a / tau is constant: the crest of a V thread.
      float phase = y / pitch - a / kTau;
      phase -= std::floor(phase);
      const float r = core + depth * (1 - std::fabs(2 * phase - 1));
      mesh->positions.push_back(apply(m, {r * std::cos(a), y, -r * std::sin(a)}));
    }
  }
  const uint32_t bottom = static_cast<uint32_t>(mesh->positions.size());
  mesh->positions.push_back(apply(m, {0, y0, 0}));
  mesh->positions.push_back(apply(m, {0, y1, 0}));
  auto at = [&](uint32_t j, uint32_t s) { return base + j * segments + s % segments; };
  for (uint32_t s = 0; s < segments; ++s) {
    for (uint32_t j = 0; j < rows; ++j) {
      triangle(mesh, flip, at(j, s), at(j, s + 1), at(j + 1, s + 1));
      triangle(mesh, flip, at(j, s), at(j + 1, s + 1), at(j + 1, s));
    }
    triangle(mesh, flip, bottom, at(0, s + 1), at(0, s));
    triangle(mesh, flip, at(rows, s), at(rows, s + 1), bottom + 1);
  }
}

void add_tube(TriangleMesh* mesh, const std::vector<glm::vec3>& path, float radius,
              uint32_t segments) {
  const size_t n = path.size();
  const uint32_t base = static_cast<uint32_t>(mesh->positions.size());
  glm::vec3 normal(0);
  for (size_t k = 0; k < n; ++k) {
    const glm::vec3 t = glm::normalize(path[std::min(k + 1, n - 1)] - path[k > 0 ? k - 1 : 0]);
    if (k == 0) {
      // Any unit vector across the first tangent starts the parallel transport.
      normal = glm::normalize(
          glm::cross(t, std::fabs(t.x) < 0.9f ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0)));
    } else {
      normal = glm::normalize(normal - glm::dot(normal, t) * t);
    }
    const glm::vec3 binormal = glm::cross(t, normal);
    for (uint32_t s = 0; s < segments; ++s) {
      const float a = kTau * static_cast<float>(s) / static_cast<float>(segments);
      mesh->positions.push_back(path[k] + radius * (std::cos(a) * normal + std::sin(a) * binormal));
    }
  }
  for (uint32_t k = 0; k + 1 < n; ++k) {
    for (uint32_t s = 0; s < segments; ++s) {
      const uint32_t v0 = base + k * segments + s, v1 = base + k * segments + (s + 1) % segments;
      const uint32_t v2 = v1 + segments, v3 = v0 + segments;
      triangle(mesh, false, v0, v1, v2);
      triangle(mesh, false, v0, v2, v3);
    }
  }
}

glm::mat4 frame_along(const glm::vec3& origin, const glm::vec3& axis) {
  const glm::vec3 y = glm::normalize(axis);
  const glm::vec3 x = glm::normalize(
      glm::cross(y, std::fabs(y.z) < 0.9f ? glm::vec3(0, 0, 1) : glm::vec3(1, 0, 0)));
  const glm::vec3 z = glm::cross(x, y);
  glm::mat4 m(1);
  m[0] = glm::vec4(x, 0);
  m[1] = glm::vec4(y, 0);
  m[2] = glm::vec4(z, 0);
  m[3] = glm::vec4(origin, 1);
  return m;
}

// ---- gear --------------------------------------------------------------------------------------

std::shared_ptr<TriangleMesh> make_gear(const char* name, uint32_t teeth, float module,
                                        float width) {
  auto mesh = std::make_shared<TriangleMesh>();
  mesh->name = name;
  const float pitch = gear_pitch_radius(teeth, module);
  const float tip = pitch + module, root = pitch - 1.25f * module;
  const float tau = kTau / static_cast<float>(teeth);
  // Angular half-widths of a tooth at root, pitch and tip radius; between them a quadratic in the
  // radius, which bends the flanks like an involute's.
  const float h_root = 0.31f * tau, h_pitch = 0.25f * tau, h_tip = 0.14f * tau;
  auto half_width = [&](float r) {
    const float u = (r - root) / (tip - root), up = (pitch - root) / (tip - root);
    // Lagrange through (0, h_root), (up, h_pitch), (1, h_tip).
    return h_root * (u - up) * (u - 1) / (up * 1) + h_pitch * u * (u - 1) / (up * (up - 1)) +
           h_tip * u * (u - up) / (1 - up);
  };
  std::vector<float> angles, radii;
  constexpr int kRoot = 3, kFlank = 7, kTip = 4;
  for (uint32_t j = 0; j < teeth; ++j) {
    const float c = tau * static_cast<float>(j);
    auto add = [&](float a, float r) {
      angles.push_back(a);
      radii.push_back(r);
    };
    for (int i = 0; i < kRoot; ++i) {
      add(c - tau / 2 + (tau / 2 - h_root) * static_cast<float>(i) / kRoot, root);
    }
    for (int i = 0; i < kFlank; ++i) {
      const float r = root + (tip - root) * static_cast<float>(i) / kFlank;
      add(c - half_width(r), r);
    }
    for (int i = 0; i < kTip; ++i) {
      add(c - h_tip + 2 * h_tip * static_cast<float>(i) / (kTip - 1), tip);
    }
    for (int i = kFlank - 1; i >= 0; --i) {
      const float r = root + (tip - root) * static_cast<float>(i) / kFlank;
      add(c + half_width(r), r);
    }
    for (int i = 1; i < kRoot; ++i) {
      add(c + h_root + (tau / 2 - h_root) * static_cast<float>(i) / kRoot, root);
    }
  }
  const float chamfer = 0.3f * module, rim = root - 2.5f * module;
  const float hub = std::max(0.35f * rim, 0.03f), bore = 0.5f * hub, boss = 0.15f * width;
  const float web0 = width / 3, web1 = 2 * width / 3;
  const std::vector<ProfilePoint> profile = {{bore, -boss},
                                             {hub, -boss},
                                             {hub, web0},
                                             {rim, web0},
                                             {rim, 0},
                                             {chamfer, 0, true},
                                             {0, chamfer, true},
                                             {0, width - chamfer, true},
                                             {chamfer, width, true},
                                             {rim, width},
                                             {rim, web1},
                                             {hub, web1},
                                             {hub, width + boss},
                                             {bore, width + boss}};
  add_outline_revolution(mesh.get(), glm::mat4(1), profile, angles, radii);
  // The shaft through the bore: it reaches 7 cm behind the gear (into whatever carries it).
  const float shaft = 0.98f * bore, end = width + boss + 0.015f;
  add_revolution(
      mesh.get(), glm::mat4(1),
      {{0, -0.07f}, {shaft, -0.07f}, {shaft, end}, {0.8f * shaft, end + 0.004f}, {0, end + 0.004f}},
      32);
  return mesh;
}

// ---- stud --------------------------------------------------------------------------------------

std::shared_ptr<TriangleMesh> make_stud(float diameter, float protrusion) {
  auto mesh = std::make_shared<TriangleMesh>();
  mesh->name = "stud-m" + std::to_string(static_cast<int>(std::lround(diameter * 1000)));
  const float r = diameter / 2, pitch = 0.11f * diameter;
  const float washer_t = 0.15f * diameter, washer_r = 1.0f * diameter;
  const float nut_h = 0.8f * diameter, across_flats = 1.5f * diameter;
  const float nut_r = across_flats / std::sqrt(3.0f);  // corner radius of the hexagon
  const float c = 0.12f * diameter;
  // The washer reaches 2 mm into the plate so that its bearing face is not on the plate's plane.
  add_revolution(mesh.get(), glm::mat4(1),
                 {{0, -0.002f},
                  {washer_r, -0.002f},
                  {washer_r, washer_t - 0.002f},
                  {washer_r - c / 2, washer_t},
                  {0, washer_t}},
                 48);
  const float nut0 = washer_t - 0.0005f, nut1 = nut0 + nut_h;
  add_revolution(mesh.get(), glm::mat4(1),
                 {{0, nut0},
                  {nut_r - c, nut0},
                  {nut_r, nut0 + c},
                  {nut_r, nut1 - c},
                  {nut_r - c, nut1},
                  {0, nut1}},
                 6, kTau / 12);
  add_threaded_shaft(mesh.get(), glm::mat4(1), r - 0.6f * pitch, 0.6f * pitch, pitch, -0.02f,
                     nut1 + protrusion, 40, 8);
  return mesh;
}

// ---- motor -------------------------------------------------------------------------------------

std::shared_ptr<TriangleMesh> make_motor(float radius, float length, float axis_height) {
  auto mesh = std::make_shared<TriangleMesh>();
  mesh->name = "motor";
  TriangleMesh* m = mesh.get();
  // Built along +Y from y = 0 (fan end) to y = length, then laid along +X by `lay`.
  const glm::mat4 lay = glm::rotate(translate(-length / 2, axis_height, 0), -kTau / 4,
                                    glm::vec3(0, 0, 1));  // local +Y -> +X
  // The finned body: an outline of kFins fins around a cylinder.
  constexpr uint32_t kFins = 36;
  const float fin = 0.3f * radius, fin_half = 0.011f, tau = kTau / kFins;
  std::vector<float> angles, radii;
  for (uint32_t j = 0; j < kFins; ++j) {
    const float c = tau * static_cast<float>(j);
    const float root_half = std::asin(fin_half * 1.6f / radius);
    auto add = [&](float a, float r) {
      angles.push_back(a);
      radii.push_back(r);
    };
    for (int i = 0; i < 5; ++i) {  // the body between fins
      add(c - tau / 2 + (tau / 2 - root_half) * static_cast<float>(i) / 5, radius);
    }
    // Flanks taper from 1.6 x to 1 x the half thickness; the tip is a half circle.
    for (int i = 0; i < 6; ++i) {
      const float f = static_cast<float>(i) / 6;
      const float r = radius + fin * f;
      add(c - std::asin(fin_half * (1.6f - 0.6f * f) / r), r);
    }
    for (int i = 0; i < 7; ++i) {
      const float t = -kTau / 4 + kTau / 2 * static_cast<float>(i) / 6;
      const float r = radius + fin + fin_half * std::cos(t);
      add(c + std::asin(fin_half * std::sin(t) / r), r);
    }
    for (int i = 5; i >= 0; --i) {
      const float f = static_cast<float>(i) / 6;
      const float r = radius + fin * f;
      add(c + std::asin(fin_half * (1.6f - 0.6f * f) / r), r);
    }
    for (int i = 1; i < 5; ++i) {
      add(c + root_half + (tau / 2 - root_half) * static_cast<float>(i) / 5, radius);
    }
  }
  // Fan cowl over [0, y0], finned body over [y0, y1], drive-end shield, then the shaft.
  const float y0 = 0.15f * length, y1 = 0.7f * length, e = 0.008f;
  add_outline_revolution(m, lay,
                         {{0, y0},
                          {fin + e, y0, true},
                          {0, y0 + e, true},
                          {0, y1 - e, true},
                          {fin + e, y1, true},
                          {0, y1}},
                         angles, radii);
  // End shields: domed, with a bearing boss; the drive end carries the shaft.
  add_revolution(m, lay,
                 {{0, y1 - 0.01f},
                  {radius * 1.02f, y1 - 0.01f},
                  {radius * 1.02f, y1 + 0.02f},
                  {radius * 0.9f, y1 + 0.05f},
                  {radius * 0.45f, y1 + 0.07f},
                  {radius * 0.3f, y1 + 0.062f},
                  {radius * 0.3f, y1 + 0.08f},
                  {0, y1 + 0.08f}},
                 96);
  add_revolution(m, lay,
                 {{0, y1 + 0.07f},
                  {0.03f, y1 + 0.07f},
                  {0.03f, length - 0.002f},
                  {0.027f, length},
                  {0, length}},
                 48);
  // Fan cowl over the fan end: a ribbed drum whose face is a grille of ring slots, traced from
  // the axis out along the face (y = 0), up the drum and back in under the body.
  constexpr int kRings = 9;
  const float cowl_r = radius * 1.1f;
  std::vector<ProfilePoint> cowl = {{0, 0}};
  for (int i = 1; i <= kRings; ++i) {
    const float ra = cowl_r * (static_cast<float>(i) - 0.55f) / kRings;
    const float rb = cowl_r * static_cast<float>(i) / kRings - 0.004f;
    cowl.insert(cowl.end(), {{ra, 0}, {ra, 0.008f}, {rb, 0.008f}, {rb, 0}});  // a slot
  }
  for (int i = 0; i < 6; ++i) {  // ribs around the drum
    const float y = 0.01f + (y0 - 0.01f) * static_cast<float>(i) / 6;
    cowl.insert(cowl.end(), {{cowl_r, y + 0.006f},
                             {cowl_r + 0.02f * radius, y + 0.008f},
                             {cowl_r + 0.02f * radius, y + 0.012f},
                             {cowl_r, y + 0.014f}});
  }
  cowl.insert(cowl.end(), {{cowl_r, y0 + 0.02f}, {0, y0 + 0.02f}});
  add_revolution(m, lay, cowl, 96);
  // Terminal box with a lid and two cable glands, on top of the body.
  const glm::vec3 top = apply(lay, {0, 0.55f * length, 0}) + glm::vec3(0, radius + 0.02f, 0);
  box(m, top.x - 0.09f, top.y - 0.05f, -0.08f, top.x + 0.09f, top.y + 0.1f, 0.08f);
  box(m, top.x - 0.1f, top.y + 0.099f, -0.09f, top.x + 0.1f, top.y + 0.12f, 0.09f);
  for (float z : {-0.04f, 0.04f}) {
    revolve_along(
        m, {top.x + 0.089f, top.y + 0.03f, z}, {1, 0, 0},
        {{0, 0}, {0.018f, 0}, {0.018f, 0.02f}, {0.013f, 0.025f}, {0.013f, 0.05f}, {0, 0.05f}}, 32);
  }
  // Feet: two rails with four bolt bosses.
  for (float z : {-radius * 0.75f, radius * 0.75f}) {
    box(m, -length * 0.38f, -0.01f, z - 0.035f, length * 0.38f, 0.03f, z + 0.035f);
    box(m, -length * 0.2f, 0.029f, z - 0.02f, length * 0.2f, axis_height - radius * 0.6f,
        z + 0.02f);
    for (float x : {-length * 0.32f, length * 0.32f}) {
      add_revolution(m, translate(x, 0.029f, z), {{0, 0}, {0.02f, 0}, {0.02f, 0.012f}, {0, 0.012f}},
                     6, kTau / 12);
    }
  }
  return mesh;
}

// ---- pipe --------------------------------------------------------------------------------------

std::shared_ptr<TriangleMesh> make_pipe(float radius, uint32_t variant) {
  auto mesh = std::make_shared<TriangleMesh>();
  mesh->name = "pipe-" + std::to_string(variant);
  // Legs of the run: a direction and a straight length; 90-degree bends of radius 3 r between.
  struct Leg {
    glm::vec3 dir;
    float length;
  };
  const std::vector<Leg> legs = variant == 0 ? std::vector<Leg>{{{0, 1, 0}, 0.25f},
                                                                {{1, 0, 0}, 0.3f},
                                                                {{0, 0, 1}, 0.6f},
                                                                {{1, 0, 0}, 0.25f}}
                                             : std::vector<Leg>{{{0, 1, 0}, 0.25f},
                                                                {{1, 0, 0}, 0.2f},
                                                                {{0, 0, -1}, 0.5f},
                                                                {{0, 1, 0}, 0.4f},
                                                                {{1, 0, 0}, 0.5f}};
  const float bend = 3 * radius;
  constexpr int kBendSteps = 24;
  std::vector<glm::vec3> path = {glm::vec3(0)};
  glm::vec3 at(0);
  for (size_t i = 0; i < legs.size(); ++i) {
    const bool before = i > 0, after = i + 1 < legs.size();
    // A straight leg loses a bend radius at each end where it meets a bend.
    const float straight = legs[i].length - (before ? bend : 0) - (after ? bend : 0);
    // Straight runs get rings every 5 cm: weld seams and supports line up with them.
    const int steps = std::max(1, static_cast<int>(straight / 0.05f));
    for (int s = 1; s <= steps; ++s) {
      path.push_back(at + legs[i].dir * (straight * static_cast<float>(s) / steps));
    }
    at += legs[i].dir * straight;
    if (!after) break;
    // The bend: a quarter circle from dir_i to dir_{i+1} around the corner's centre.
    const glm::vec3 d0 = legs[i].dir, d1 = legs[i + 1].dir;
    const glm::vec3 centre = at + d1 * bend;
    for (int s = 1; s <= kBendSteps; ++s) {
      const float a = kTau / 4 * static_cast<float>(s) / kBendSteps;
      path.push_back(centre - d1 * (bend * std::cos(a)) + d0 * (bend * std::sin(a)));
    }
    at = centre + d0 * bend;
  }
  add_tube(mesh.get(), path, radius, 48);
  // Flanges at both ends with eight bolt heads each, and two welded supports' collars.
  const glm::vec3 ends[2][2] = {{path.front(), glm::normalize(path.front() - path[1])},
                                {path.back(), glm::normalize(path.back() - path[path.size() - 2])}};
  for (const auto& end : ends) {
    const glm::mat4 f = frame_along(end[0] - end[1] * 0.012f, end[1]);
    const float fr = radius * 1.9f;
    add_revolution(
        mesh.get(), f,
        {{0, 0}, {fr, 0}, {fr, 0.02f}, {radius * 1.2f, 0.024f}, {radius * 1.2f, 0.05f}, {0, 0.05f}},
        64);
    for (int b = 0; b < 8; ++b) {
      const float a = kTau * (static_cast<float>(b) + 0.5f) / 8;
      const glm::vec3 p = apply(f, {fr * 0.78f * std::cos(a), 0.019f, -fr * 0.78f * std::sin(a)});
      add_revolution(mesh.get(), frame_along(p, end[1]),
                     {{0, 0}, {0.012f, 0}, {0.012f, 0.01f}, {0.009f, 0.013f}, {0, 0.013f}}, 6);
    }
  }
  return mesh;
}

// ---- machine bed -------------------------------------------------------------------------------

std::shared_ptr<TriangleMesh> make_machine_bed(float length) {
  auto mesh = std::make_shared<TriangleMesh>();
  mesh->name = "machine-bed";
  TriangleMesh* m = mesh.get();
  const float h = length / 2;
  // The cast body on a plinth that reaches 1 cm into the floor, with ribs on both long sides.
  box(m, -h - 0.05f, -0.01f, -0.5f, h + 0.05f, 0.12f, 0.5f);
  box(m, -h, 0.1f, -0.42f, h, 0.8f, 0.42f);
  for (int i = 0; i <= 14; ++i) {
    const float x = -h + 0.05f + (length - 0.1f) * static_cast<float>(i) / 14;
    for (float z : {-1.0f, 1.0f}) {
      box(m, x - 0.02f, 0.11f, std::min(z * 0.41f, z * 0.47f), x + 0.02f, 0.78f,
          std::max(z * 0.41f, z * 0.47f));
    }
  }
  // The top flange the studs hold, and two ways (slide rails) with a dovetail step.
  box(m, -h - 0.03f, 0.79f, -0.45f, h + 0.03f, 0.85f, 0.45f);
  for (float z : {-0.22f, 0.22f}) {
    box(m, -h + 0.02f, 0.84f, z - 0.06f, h - 0.02f, 0.9f, z + 0.06f);
    box(m, -h + 0.02f, 0.899f, z - 0.045f, h - 0.02f, 0.93f, z + 0.045f);
  }
  // Headstock at -X with a spindle and a three-jaw chuck facing +X; tailstock on the ways.
  box(m, -h + 0.05f, 0.92f, -0.3f, -h + 0.55f, 1.4f, 0.3f);
  revolve_along(m, {-h + 0.549f, 1.17f, 0}, {1, 0, 0},
                {{0, 0},
                 {0.11f, 0},
                 {0.11f, 0.05f},
                 {0.14f, 0.06f},
                 {0.14f, 0.16f},
                 {0.12f, 0.17f},
                 {0.05f, 0.17f},
                 {0.05f, 0.2f},
                 {0, 0.2f}},
                96);
  for (int j = 0; j < 3; ++j) {
    const glm::mat4 jaw = glm::rotate(translate(-h + 0.72f, 1.17f, 0),
                                      kTau / 3 * static_cast<float>(j), glm::vec3(1, 0, 0));
    add_box(m, glm::scale(glm::translate(jaw, {0, 0.1f, 0}), {0.02f, 0.04f, 0.018f}));
  }
  box(m, h - 0.7f, 0.92f, -0.2f, h - 0.35f, 1.25f, 0.2f);
  revolve_along(m, {h - 0.351f, 1.17f, 0}, {-1, 0, 0},
                {{0, 0}, {0.06f, 0}, {0.06f, 0.12f}, {0.03f, 0.16f}, {0.008f, 0.2f}, {0, 0.2f}},
                64);
  // Control cabinet at the +X end with a screen and a grid of buttons on its front (+Z).
  box(m, h - 0.3f, 0.849f, 0.12f, h + 0.05f, 1.75f, 0.5f);
  box(m, h - 0.26f, 1.45f, 0.499f, h + 0.01f, 1.68f, 0.52f);
  for (int row = 0; row < 4; ++row) {
    for (int col = 0; col < 5; ++col) {
      const glm::vec3 p(h - 0.24f + 0.055f * static_cast<float>(col),
                        1.05f + 0.08f * static_cast<float>(row), 0.499f);
      revolve_along(m, p, {0, 0, 1},
                    {{0, 0},
                     {0.022f, 0},
                     {0.022f, 0.012f},
                     {0.016f, 0.016f},
                     {0.016f, 0.028f},
                     {0.012f, 0.032f},
                     {0, 0.032f}},
                    24);
    }
  }
  // A coolant hose from the cabinet to the headstock.
  std::vector<glm::vec3> hose;
  for (int i = 0; i <= 60; ++i) {
    const float t = static_cast<float>(i) / 60;
    hose.push_back({h - 0.28f - (length - 0.78f) * t,
                    1.6f - 0.35f * t + 0.2f * std::sin(kTau / 2 * t), 0.35f - 0.1f * t});
  }
  add_tube(m, hose, 0.015f, 16);
  return mesh;
}

// ---- conveyor ----------------------------------------------------------------------------------

std::shared_ptr<TriangleMesh> make_conveyor(float length) {
  auto mesh = std::make_shared<TriangleMesh>();
  mesh->name = "conveyor";
  TriangleMesh* m = mesh.get();
  const float h = length / 2, w = 0.4f, top = 0.8f;
  // Side rails (C channels) on legs with cross braces.
  for (float s : {-1.0f, 1.0f}) {
    const float z = s * w;
    box(m, -h, top - 0.121f, z - 0.003f, h, top + 0.021f, z + 0.003f);
    box(m, -h, top - 0.12f, z, h, top - 0.11f, z + 0.04f * s);
    box(m, -h, top + 0.01f, z, h, top + 0.02f, z + 0.04f * s);
  }
  for (int i = 0; i <= 3; ++i) {
    const float x = -h + 0.1f + (length - 0.2f) * static_cast<float>(i) / 3;
    for (float z : {-w - 0.035f, w + 0.005f}) {
      box(m, x - 0.025f, -0.01f, z, x + 0.025f, top - 0.119f, z + 0.03f);
    }
    box(m, x - 0.015f, 0.2f, -w - 0.01f, x + 0.015f, 0.23f, w + 0.01f);
  }
  // Rollers every 10 cm: a tube with bearing caps on a shaft into both rails.
  const int rollers = static_cast<int>(length / 0.1f);
  for (int i = 0; i < rollers; ++i) {
    const float x = -h + 0.05f + 0.1f * static_cast<float>(i);
    revolve_along(m, {x, top - 0.03f, -w + 0.002f}, {0, 0, 1},
                  {{0, 0},
                   {0.008f, 0},
                   {0.008f, 0.02f},
                   {0.03f, 0.02f},
                   {0.035f, 0.025f},
                   {0.035f, 2 * w - 0.025f},
                   {0.03f, 2 * w - 0.02f},
                   {0.008f, 2 * w - 0.02f},
                   {0.008f, 2 * w - 0.004f},
                   {0, 2 * w - 0.004f}},
                  40, 0.1f * static_cast<float>(i));
  }
  return mesh;
}

// ---- rack --------------------------------------------------------------------------------------

RackMeshes make_rack(uint32_t bays, uint32_t seed) {
  RackMeshes rack{std::make_shared<TriangleMesh>(), std::make_shared<TriangleMesh>()};
  rack.frame->name = "rack-" + std::to_string(seed);
  rack.loads->name = "rack-" + std::to_string(seed) + "-loads";
  TriangleMesh* m = rack.frame.get();
  TriangleMesh* l = rack.loads.get();
  const float bay = 2.7f, depth = 1.1f, height = 4.5f;
  const float levels[] = {0.15f, 1.6f, 3.05f};
  const float x0 = -bay * static_cast<float>(bays) / 2;
  // Uprights: frames of two posts with bracing, punched with slots every 10 cm on the front.
  for (uint32_t u = 0; u <= bays; ++u) {
    const float x = x0 + bay * static_cast<float>(u);
    for (float z : {-depth, 0.0f}) {
      box(m, x - 0.045f, -0.01f, z - 0.04f, x + 0.045f, height, z + 0.04f);
      if (z < 0) continue;
      for (int s = 0; s < 42; ++s) {
        const float y = 0.2f + 0.1f * static_cast<float>(s);
        box(m, x - 0.012f, y, z + 0.039f, x + 0.012f, y + 0.05f, z + 0.043f);
      }
    }
    for (int b = 0; b < 6; ++b) {
      const float y = 0.3f + 0.7f * static_cast<float>(b);
      box(m, x - 0.015f, y, -depth + 0.04f, x + 0.015f, y + 0.03f, -0.04f);
    }
  }
  // Beams and, on each level, two pallets carrying crates or drums.
  const uint64_t st = procedural::stream_of(0x4AC4, seed);
  uint64_t k = 0;
  for (uint32_t b = 0; b < bays; ++b) {
    const float xa = x0 + bay * static_cast<float>(b);
    for (float level : levels) {
      for (float z : {-depth, 0.0f}) {
        box(m, xa + 0.045f, level + 0.0f, z - 0.035f, xa + bay - 0.045f, level + 0.1f, z + 0.035f);
      }
      for (int p = 0; p < 2; ++p) {
        const float px = xa + 0.15f + 1.25f * static_cast<float>(p), py = level + 0.1f;
        // A pallet: three runners and five deck boards.
        for (int r = 0; r < 3; ++r) {
          const float rx = px + 0.05f + 0.5f * static_cast<float>(r);
          box(l, rx, py, -depth + 0.05f, rx + 0.1f, py + 0.1f, -0.05f);
        }
        for (int d = 0; d < 5; ++d) {
          const float dz = -depth + 0.05f + 0.21f * static_cast<float>(d);
          box(l, px, py + 0.099f, dz, px + 1.2f, py + 0.12f, dz + 0.16f);
        }
        const float ly = py + 0.119f;
        if (procedural::pick(st, k++, 3) == 0) continue;  // an empty pallet
        if (procedural::pick(st, k++, 2) == 0) {
          // Four ribbed drums.
          for (int d = 0; d < 4; ++d) {
            const float dx = px + 0.3f + 0.6f * static_cast<float>(d % 2);
            const float dz = -depth / 2 - 0.26f + 0.52f * static_cast<float>(d / 2);
            add_revolution(l, translate(dx, ly, dz),
                           {{0, 0},
                            {0.27f, 0},
                            {0.29f, 0.02f},
                            {0.28f, 0.03f},
                            {0.28f, 0.28f},
                            {0.295f, 0.3f},
                            {0.28f, 0.32f},
                            {0.28f, 0.6f},
                            {0.295f, 0.62f},
                            {0.28f, 0.64f},
                            {0.28f, 0.86f},
                            {0.29f, 0.87f},
                            {0.27f, 0.89f},
                            {0.05f, 0.89f},
                            {0.05f, 0.9f},
                            {0, 0.9f}},
                           48, 0.3f * static_cast<float>(d));
          }
        } else {
          // A slatted crate.
          const float ch = procedural::uniform(st, k++, 0.5f, 1.1f);
          for (int s = 0; s < 5; ++s) {
            const float sy = ly + ch * static_cast<float>(s) / 5;
            box(l, px + 0.02f, sy, -depth + 0.06f, px + 1.18f, sy + ch / 5 - 0.02f, -0.06f);
            box(l, px, sy + 0.01f, -depth + 0.04f, px + 1.2f, sy + 0.05f, -0.04f);
          }
        }
      }
    }
  }
  return rack;
}

// ---- structure ---------------------------------------------------------------------------------

std::shared_ptr<TriangleMesh> make_column(float height) {
  auto mesh = std::make_shared<TriangleMesh>();
  mesh->name = "column";
  TriangleMesh* m = mesh.get();
  box(m, -0.3f, -0.01f, -0.3f, 0.3f, 0.03f, 0.3f);
  box(m, -0.15f, 0.0f, -0.15f, 0.15f, height, -0.13f);
  box(m, -0.15f, 0.0f, 0.13f, 0.15f, height, 0.15f);
  box(m, -0.01f, 0.0f, -0.131f, 0.01f, height, 0.131f);
  for (float x : {-0.22f, 0.22f}) {
    for (float z : {-0.22f, 0.22f}) {
      add_revolution(m, translate(x, 0.029f, z), {{0, 0}, {0.03f, 0}, {0.03f, 0.025f}, {0, 0.025f}},
                     6);
    }
  }
  return mesh;
}

std::shared_ptr<TriangleMesh> make_girder(float length) {
  auto mesh = std::make_shared<TriangleMesh>();
  mesh->name = "girder";
  TriangleMesh* m = mesh.get();
  const float h = length / 2, depth = 1.2f;
  box(m, -0.12f, depth - 0.1f, -h, 0.12f, depth, h);
  box(m, -0.12f, 0.0f, -h, 0.12f, 0.1f, h);
  const int panels = static_cast<int>(length / 1.5f);
  for (int i = 0; i <= panels; ++i) {
    const float z = -h + length * static_cast<float>(i) / panels;
    box(m, -0.05f, 0.099f, z - 0.04f, 0.05f, depth - 0.099f, z + 0.04f);
    if (i == panels) break;
    // A diagonal from this vertical's foot to the next one's head.
    const float z1 = -h + length * static_cast<float>(i + 1) / panels;
    const glm::vec3 a(0, 0.1f, z), b(0, depth - 0.1f, z1);
    const float len = glm::length(b - a), angle = std::atan2(b.z - a.z, b.y - a.y);
    glm::mat4 d =
        glm::rotate(glm::translate(glm::mat4(1), (a + b) * 0.5f), angle, glm::vec3(1, 0, 0));
    add_box(m, glm::scale(d, {0.03f, len / 2 + 0.02f, 0.03f}));
  }
  return mesh;
}

}  // namespace calf::samples::factory
