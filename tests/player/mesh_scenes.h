// Small mesh draw lists for the mesh renderer and epsilon tests, built by hand.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "calf/player/mesh_draw_list.h"

namespace calf::player::test {

// An axis-aligned rectangle in the plane z = `z`, x in [x0, x1], y in [y0, y1], as two triangles
// (0: lower-left half, 1: upper-right half), wound counter-clockwise seen from +z.
inline MeshDrawPrototype rectangle(double x0, double x1, double y0, double y1, double z) {
  MeshDrawPrototype p;
  const double xs[4] = {x0, x1, x1, x0}, ys[4] = {y0, y0, y1, y1};
  for (int i = 0; i < 4; ++i) {
    p.positions.push_back(static_cast<float>(xs[i]));
    p.positions.push_back(static_cast<float>(ys[i]));
    p.positions.push_back(static_cast<float>(z));
  }
  p.indices = {0, 1, 2, 0, 2, 3};
  return p;
}

// A unit cube centred on the origin (12 triangles, outward winding).
inline MeshDrawPrototype cube() {
  MeshDrawPrototype p;
  for (int i = 0; i < 8; ++i) {
    p.positions.push_back((i & 1) ? 0.5f : -0.5f);
    p.positions.push_back((i & 2) ? 0.5f : -0.5f);
    p.positions.push_back((i & 4) ? 0.5f : -0.5f);
  }
  p.indices = {0, 2, 3, 0, 3, 1,   // -z
               4, 5, 7, 4, 7, 6,   // +z
               0, 1, 5, 0, 5, 4,   // -y
               2, 6, 7, 2, 7, 3,   // +y
               0, 4, 6, 0, 6, 2,   // -x
               1, 3, 7, 1, 7, 5};  // +x
  return p;
}

// A UV sphere of radius 1 with vertex normals and vertex colours.
inline MeshDrawPrototype sphere(int rings, int segments) {
  MeshDrawPrototype p;
  const double pi = 3.141592653589793;
  for (int r = 0; r <= rings; ++r) {
    const double theta = pi * r / rings;
    for (int s = 0; s <= segments; ++s) {
      const double phi = 2 * pi * s / segments;
      const double n[3] = {std::sin(theta) * std::cos(phi), std::cos(theta),
                           std::sin(theta) * std::sin(phi)};
      for (double v : n) {
        p.positions.push_back(static_cast<float>(v));
        p.normals.push_back(static_cast<float>(v));
      }
      p.colours.push_back(static_cast<float>(0.5 + 0.5 * n[0]));
      p.colours.push_back(static_cast<float>(0.5 + 0.5 * n[1]));
      p.colours.push_back(0.8f);
    }
  }
  for (int r = 0; r < rings; ++r) {
    for (int s = 0; s < segments; ++s) {
      const uint32_t a = static_cast<uint32_t>(r * (segments + 1) + s), b = a + 1,
                     c = a + static_cast<uint32_t>(segments + 1), d = c + 1;
      p.indices.insert(p.indices.end(), {a, c, b, b, c, d});
    }
  }
  return p;
}

// Row-major 3 x 4: rotation by `angle` about y, uniform `scale`, then translation.
inline std::array<float, 12> placement(double angle, double scale, double tx, double ty,
                                       double tz) {
  const double c = std::cos(angle) * scale, s = std::sin(angle) * scale;
  return {static_cast<float>(c),
          0,
          static_cast<float>(s),
          static_cast<float>(tx),
          0,
          static_cast<float>(scale),
          0,
          static_cast<float>(ty),
          static_cast<float>(-s),
          0,
          static_cast<float>(c),
          static_cast<float>(tz)};
}

// A scene exercising every feature: a ground plane, cubes (shared prototype, rotated, one with a
// triangle subset, one with per-triangle materials, some of them
// the object's), a coloured sphere with normals, an emitter.
inline MeshDrawList feature_scene() {
  MeshDrawList list;
  list.materials = {{{0.6f, 0.6f, 0.55f}, {0, 0, 0}},
                    {{0.8f, 0.2f, 0.2f}, {0, 0, 0}},
                    {{0.2f, 0.3f, 0.9f}, {0, 0, 0}},
                    {{0.1f, 0.1f, 0.1f}, {0.9f, 0.8f, 0.3f}},
                    {{0.9f, 0.9f, 0.9f}, {0, 0, 0}}};
  list.prototypes.push_back(rectangle(-6, 6, -6, 6, 0));  // ground, turned to y = 0 below
  list.prototypes.push_back(cube());
  MeshDrawPrototype striped = cube();
  for (uint32_t t = 0; t < 12; ++t) {
    striped.triangle_materials.push_back(t % 3 == 2 ? kMeshObjectMaterial : (t % 2 ? 2 : 4));
  }
  list.prototypes.push_back(striped);
  list.prototypes.push_back(sphere(10, 16));

  MeshDrawObject ground;
  ground.prototype = 0;
  ground.material = 0;
  ground.transform = {1, 0, 0, 0, 0, 0, 1, -0.5f, 0, -1, 0, 0};  // z -> -y: the plane y = -0.5
  list.objects.push_back(ground);
  MeshDrawObject a;
  a.prototype = 1;
  a.material = 1;
  a.transform = placement(0.5, 1.0, -1.2, 0.0, -4.0);
  list.objects.push_back(a);
  MeshDrawObject b = a;  // the same prototype, a subset
  b.transform = placement(-0.3, 0.8, 1.3, 0.0, -3.5);
  b.all_triangles = false;
  b.triangles = {0, 1, 4, 5, 6, 7, 10};
  list.objects.push_back(b);
  MeshDrawObject c;
  c.prototype = 2;
  c.material = 0;
  c.transform = placement(0.9, 0.7, 0.2, 0.4, -6.0);
  list.objects.push_back(c);
  MeshDrawObject s;
  s.prototype = 3;
  s.material = 4;
  s.transform = placement(0.2, 0.6, -0.3, 0.9, -3.0);
  list.objects.push_back(s);
  MeshDrawObject e;
  e.prototype = 1;
  e.material = 3;
  e.transform = placement(0.0, 0.3, 2.0, 1.2, -5.0);
  list.objects.push_back(e);
  return list;
}

}  // namespace calf::player::test
