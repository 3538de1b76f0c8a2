// Private to the player: an object's row-major 3 x 4 transform (SCENE.md, decoder::MeshTransform)
// in double, with what the renderers of mesh and surfel draw lists need from it.
#pragma once

#include <array>

#include "calf/format/geometry.h"

namespace calf::player::internal {

struct ObjectTransform {
  double r[3][4];    // rows
  double cof[3][3];  // cofactors of the 3 x 3 part: its inverse transpose times its determinant
  double det = 0;    // determinant of the 3 x 3 part

  explicit ObjectTransform(const std::array<float, 12>& m) {
    for (int row = 0; row < 3; ++row) {
      for (int col = 0; col < 4; ++col) r[row][col] = m[4 * row + col];
    }
    for (int a = 0; a < 3; ++a) {
      for (int b = 0; b < 3; ++b) {
        const int a1 = (a + 1) % 3, a2 = (a + 2) % 3, b1 = (b + 1) % 3, b2 = (b + 2) % 3;
        cof[a][b] = r[a1][b1] * r[a2][b2] - r[a1][b2] * r[a2][b1];
      }
    }
    det = r[0][0] * cof[0][0] + r[0][1] * cof[0][1] + r[0][2] * cof[0][2];
  }

  // The 3 x 3 part times v (a direction).
  Vec3 linear(const Vec3& v) const {
    return {r[0][0] * v.x + r[0][1] * v.y + r[0][2] * v.z,
            r[1][0] * v.x + r[1][1] * v.y + r[1][2] * v.z,
            r[2][0] * v.x + r[2][1] * v.y + r[2][2] * v.z};
  }
  // The translation.
  Vec3 translation() const { return {r[0][3], r[1][3], r[2][3]}; }
};

}  // namespace calf::player::internal
