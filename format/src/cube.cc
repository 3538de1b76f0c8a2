#include "calf/format/cube.h"

#include <cassert>
#include <cmath>

namespace calf {
namespace {

// Per face: which axis is major and its sign, and how (s_c, t_c) are read off the direction.
// sc = sc_sign * d[sc_axis], tc = tc_sign * d[tc_axis] (OpenGL 4.5 core, Table 8.19).
struct FaceAxes {
  int major_axis;
  double major_sign;
  int sc_axis;
  double sc_sign;
  int tc_axis;
  double tc_sign;
};

constexpr FaceAxes kFaceAxes[kCubeFaceCount] = {
    {0, +1, 2, -1, 1, -1},  // +X: sc = -z, tc = -y
    {0, -1, 2, +1, 1, -1},  // -X: sc = +z, tc = -y
    {1, +1, 0, +1, 2, +1},  // +Y: sc = +x, tc = +z
    {1, -1, 0, +1, 2, -1},  // -Y: sc = +x, tc = -z
    {2, +1, 0, +1, 1, -1},  // +Z: sc = +x, tc = -y
    {2, -1, 0, -1, 1, -1},  // -Z: sc = -x, tc = -y
};

// Divides by the length (not a multiply by its reciprocal, as normalize() does): the bits every
// capture and frozen conformance file were made with.
Vec3 normalized(double x, double y, double z) {
  const Vec3 v{x, y, z};
  return v / length(v);
}

}  // namespace

const char* cube_face_name(CubeFace face) {
  static const char* const kNames[kCubeFaceCount] = {"+X", "-X", "+Y", "-Y", "+Z", "-Z"};
  const int i = cube_face_index(face);
  return i >= 0 && i < kCubeFaceCount ? kNames[i] : "?";
}

FaceCoord face_coord_from_direction(const Vec3& d) {
  const double ax = std::fabs(d.x), ay = std::fabs(d.y), az = std::fabs(d.z);
  const bool valid =
      std::isfinite(ax) && std::isfinite(ay) && std::isfinite(az) && (ax > 0 || ay > 0 || az > 0);
  assert(valid && "face_coord_from_direction: direction must be finite and non-zero");
  if (!valid) return FaceCoord{};
  // Ties go to the first axis in X, Y, Z order, so seams and corners belong to one face.
  int axis;
  if (ax >= ay && ax >= az) {
    axis = 0;
  } else if (ay >= az) {
    axis = 1;
  } else {
    axis = 2;
  }
  const double m = component(d, axis);
  const int face = 2 * axis + (m < 0 ? 1 : 0);
  const FaceAxes& f = kFaceAxes[face];
  const double inv = 1.0 / std::fabs(m);
  const double sc = f.sc_sign * component(d, f.sc_axis);
  const double tc = f.tc_sign * component(d, f.tc_axis);
  return {cube_face_from_index(face), 0.5 * (sc * inv + 1.0), 0.5 * (tc * inv + 1.0)};
}

Vec3 direction_from_face_coord(const FaceCoord& c) {
  const FaceAxes& f = kFaceAxes[cube_face_index(c.face)];
  double v[3];
  v[f.major_axis] = f.major_sign;
  v[f.sc_axis] = f.sc_sign * (2.0 * c.s - 1.0);
  v[f.tc_axis] = f.tc_sign * (2.0 * c.t - 1.0);
  return normalized(v[0], v[1], v[2]);
}

Vec3 direction_from_texel_coord(const FaceTexelCoord& c, uint32_t face_size) {
  const double n = face_size;
  return direction_from_face_coord({c.face, c.u / n, c.v / n});
}

Vec3 direction_from_texel(CubeFace face, uint32_t x, uint32_t y, uint32_t face_size) {
  return direction_from_texel_coord({face, x + 0.5, y + 0.5}, face_size);
}

FaceTexelCoord texel_coord_from_direction(const Vec3& d, uint32_t face_size) {
  const FaceCoord c = face_coord_from_direction(d);
  const double n = face_size;
  return {c.face, c.s * n, c.t * n};
}

Texel texel_from_direction(const Vec3& d, uint32_t face_size) {
  const FaceTexelCoord c = texel_coord_from_direction(d, face_size);
  const auto clamp_texel = [face_size](double u) -> uint32_t {
    if (!(u > 0)) return 0;  // also catches NaN
    const double f = std::floor(u);
    return f >= face_size ? face_size - 1 : static_cast<uint32_t>(f);
  };
  return {c.face, clamp_texel(c.u), clamp_texel(c.v)};
}

Texel texel_beyond_face(CubeFace face, int64_t x, int64_t y, uint32_t face_size) {
  if (x >= 0 && y >= 0 && x < face_size && y < face_size) {
    return {face, static_cast<uint32_t>(x), static_cast<uint32_t>(y)};
  }
  // The texel centre continued in the face's plane, looked up again: lands on the neighbour.
  const Vec3 d = direction_from_texel_coord(
      {face, static_cast<double>(x) + 0.5, static_cast<double>(y) + 0.5}, face_size);
  return texel_from_direction(d, face_size);
}

UprightFace upright_face(CubeFace face) {
  // up = -t_c's axis direction (row 0 of a face is t = 0, the top of the upright image).
  const FaceAxes& f = kFaceAxes[cube_face_index(face)];
  double fwd[3] = {0, 0, 0}, up[3] = {0, 0, 0};
  fwd[f.major_axis] = f.major_sign;
  up[f.tc_axis] = -f.tc_sign;
  return {{fwd[0], fwd[1], fwd[2]}, {up[0], up[1], up[2]}};
}

}  // namespace calf
