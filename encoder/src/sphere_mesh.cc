// An analytic sphere as a fixed icosphere (the rules are in sphere_mesh.h).
#include "calf/encoder/sphere_mesh.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <utility>

namespace calf::encoder {
namespace {

using Dir = std::array<double, 3>;

Dir normalised(const Dir& d) {
  const double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  return {d[0] / len, d[1] / len, d[2] / len};
}

// The unit icosphere, built once: every operation is an IEEE basic operation or sqrt (correctly
// rounded), so the floats are the same on every machine.
struct UnitSphere {
  std::vector<Dir> vertices;
  std::vector<std::array<uint32_t, 3>> triangles;
  UnitSphere() {
    const double p = (1.0 + std::sqrt(5.0)) / 2.0;
    const Dir corners[12] = {{-1, p, 0}, {1, p, 0}, {-1, -p, 0}, {1, -p, 0},
                             {0, -1, p}, {0, 1, p}, {0, -1, -p}, {0, 1, -p},
                             {p, 0, -1}, {p, 0, 1}, {-p, 0, -1}, {-p, 0, 1}};
    for (const Dir& c : corners) vertices.push_back(normalised(c));
    // Counter-clockwise seen from outside.
    triangles = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                 {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                 {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                 {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
    for (uint32_t level = 0; level < kSphereSubdivisions; ++level) {
      std::map<std::pair<uint32_t, uint32_t>, uint32_t> middles;
      auto middle = [&](uint32_t a, uint32_t b) {
        const std::pair<uint32_t, uint32_t> key = std::minmax(a, b);
        auto [it, added] = middles.try_emplace(key, static_cast<uint32_t>(vertices.size()));
        if (added) {
          const Dir x = vertices[key.first], y = vertices[key.second];
          vertices.push_back(normalised({x[0] + y[0], x[1] + y[1], x[2] + y[2]}));
        }
        return it->second;
      };
      std::vector<std::array<uint32_t, 3>> finer;
      finer.reserve(triangles.size() * 4);
      for (const auto& t : triangles) {
        const uint32_t ab = middle(t[0], t[1]), bc = middle(t[1], t[2]), ca = middle(t[2], t[0]);
        finer.push_back({t[0], ab, ca});
        finer.push_back({t[1], bc, ab});
        finer.push_back({t[2], ca, bc});
        finer.push_back({ab, bc, ca});
      }
      triangles = std::move(finer);
    }
  }
};

const UnitSphere& unit_sphere() {
  static const UnitSphere sphere;
  return sphere;
}

}  // namespace

void append_sphere_mesh(const float centre[3], float radius, std::vector<float>* positions,
                        std::vector<float>* normals, std::vector<uint32_t>* indices) {
  const UnitSphere& s = unit_sphere();
  const uint32_t base = static_cast<uint32_t>(positions->size() / 3);
  for (const Dir& d : s.vertices) {
    for (int c = 0; c < 3; ++c) {
      positions->push_back(static_cast<float>(double{centre[c]} + double{radius} * d[c]));
      if (normals) normals->push_back(static_cast<float>(d[c]));
    }
  }
  for (const auto& t : s.triangles) {
    for (uint32_t v : t) indices->push_back(base + v);
  }
}

}  // namespace calf::encoder
