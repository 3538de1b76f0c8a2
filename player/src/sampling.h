// Private to the player: small vector helpers and the texel fetches the CPU renderer shares
// (nearest depth, bilinear colour taps across face seams).
#pragma once

#include <cmath>
#include <cstdint>

#include "calf/decoder/culling.h"
#include "calf/format/cube.h"
#include "calf/player/view_set.h"

namespace calf::player::internal {

inline Vec3 operator+(const Vec3& a, const Vec3& b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
inline Vec3 operator-(const Vec3& a, const Vec3& b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
inline Vec3 operator*(const Vec3& a, double s) {
  return {a.x * s, a.y * s, a.z * s};
}
inline double dot(const Vec3& a, const Vec3& b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
inline Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline double length(const Vec3& a) {
  return std::sqrt(dot(a, a));
}
inline Vec3 normalize(const Vec3& a) {
  return a * (1.0 / length(a));
}
inline Direction to_direction(const Vec3& a) {
  return {a.x, a.y, a.z};
}
inline Vec3 to_vec(const Direction& d) {
  return {d.x, d.y, d.z};
}

// The four bilinear taps around texel-space position `c` on faces of `n` texels, with their
// weights (summing to 1). Taps that fall outside the face continue the face's plane and are
// re-projected onto whichever face that direction hits, like GL's seamless cube-map filtering
// (at a cube corner, where GL averages three texels, the off-diagonal tap lands on one of them).
struct BilinearTaps {
  Texel texel[4];
  double weight[4];
  // max(|du|, |dv|): how far the tap's centre is from the sampled position, in texels.
  double offset[4];
};
BilinearTaps bilinear_taps(const FaceTexelCoord& c, uint32_t n);

// The texel of (face, x, y) where x or y may lie one texel off the face: re-projected onto the
// neighbouring face through the cube conventions.
Texel texel_beyond_face(CubeFace face, int64_t x, int64_t y, uint32_t n);

}  // namespace calf::player::internal
