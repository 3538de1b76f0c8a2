// Cube-map conventions: the one place where calf maps between a cube face texel and a direction.
// Every layer (capture, encoder, decoder, CPU and GLSL renderers) calls these functions; the GLSL
// mirror is tested against them.
//
// Faces follow OpenGL: order +X, -X, +Y, -Y, +Z, -Z (face i is GL_TEXTURE_CUBE_MAP_POSITIVE_X + i)
// and the orientation of the OpenGL specification's cube-map table (4.5 core, Table 8.19):
//
//   face  major axis  s_c   t_c        s = (s_c / |m| + 1) / 2,   t = (t_c / |m| + 1) / 2
//   +X    +x          -z    -y
//   -X    -x          +z    -y         (s, t) in [0, 1]; a face image of N x N texels stores
//   +Y    +y          +x    +z          texel (x, y) at row y, column x, with its centre at
//   -Y    -y          +x    -z          s = (x + 0.5) / N, t = (y + 0.5) / N. Row 0 is the first
//   +Z    +z          +x    -y          row in memory and the first row glTexImage2D uploads.
//   -Z    -z          -x    -y
//
// Directions need not be unit length for the lookups; directions returned are unit length.
// A direction on a seam or a corner (two or three components of equal magnitude) belongs to one
// face only, chosen in the order X, then Y, then Z: the face of the first axis whose magnitude is
// the largest. So (1, 1, 0) is on +X, (0, -1, 1) on -Y, (1, 1, 1) on +X.
#pragma once

#include <cstdint>

#include "calf/format/geometry.h"

namespace calf {

enum class CubeFace : uint8_t { kPosX = 0, kNegX = 1, kPosY = 2, kNegY = 3, kPosZ = 4, kNegZ = 5 };
inline constexpr int kCubeFaceCount = 6;

// "+X", "-X", "+Y", "-Y", "+Z", "-Z".
const char* cube_face_name(CubeFace face);
// Face i in OpenGL order; i must be in [0, 6).
inline CubeFace cube_face_from_index(int i) {
  return static_cast<CubeFace>(i);
}
inline int cube_face_index(CubeFace face) {
  return static_cast<int>(face);
}

// Directions are calf::Vec3 (calf/format/geometry.h), in double precision: the conventions are
// the reference every fast path is tested against; hot loops may convert to float after the
// lookup.

// A position on a face in normalised face coordinates, s and t in [0, 1].
struct FaceCoord {
  CubeFace face = CubeFace::kPosX;
  double s = 0.5, t = 0.5;
};

// A position on a face of N x N texels in texel units: u, v in [0, N]; the texel containing it
// is (min(floor(u), N - 1), min(floor(v), N - 1)).
struct FaceTexelCoord {
  CubeFace face = CubeFace::kPosX;
  double u = 0, v = 0;
};

// The face a direction points into, and where. `d` must be finite and non-zero (a caller bug
// otherwise: asserted in debug builds; release builds return the centre of +X).
FaceCoord face_coord_from_direction(const Vec3& d);

// The unit direction through normalised face coordinates (s, t). Values outside [0, 1] are
// allowed and continue the face's plane (useful for filtering across seams).
Vec3 direction_from_face_coord(const FaceCoord& c);

// The unit direction through the centre of texel (x, y) of a face of `face_size` texels.
Vec3 direction_from_texel(CubeFace face, uint32_t x, uint32_t y, uint32_t face_size);

// The unit direction through texel-space position (u, v) of a face of `face_size` texels
// (texel centres are at half-integers).
Vec3 direction_from_texel_coord(const FaceTexelCoord& c, uint32_t face_size);

// The face and texel-space position a direction points at, on faces of `face_size` texels.
FaceTexelCoord texel_coord_from_direction(const Vec3& d, uint32_t face_size);

// The texel (x, y) containing texel-space position (u, v), clamped to the face.
struct Texel {
  CubeFace face = CubeFace::kPosX;
  uint32_t x = 0, y = 0;
};
Texel texel_from_direction(const Vec3& d, uint32_t face_size);

// The texel (x, y) of `face` where x or y may lie one texel off the face (faces of `face_size`
// texels): re-projected onto the neighbouring face through these conventions.
Texel texel_beyond_face(CubeFace face, int64_t x, int64_t y, uint32_t face_size);

// Upright faces: how renderers other than OpenGL (Unity's and Maya's face cameras, image viewers)
// see a calf face. Face f's upright camera sits at the cube's centre with a 90-degree square
// field of view, looking along f's major axis with the up vector below; its image has row 0 at
// the top and is not mirrored (calf::Camera, calf/format/camera.h). Pixel (i, j) of that N x N
// image is texel (N - 1 - i, j) of face f: the same rows, the columns reversed, on every face
// (the GL table mirrors every face horizontally as seen from inside the cube). Up and right:
//   +X: up +Y, right +Z     -X: up +Y, right -Z     +Y: up -Z, right -X
//   -Y: up +Z, right -X     +Z: up +Y, right -X     -Z: up +Y, right +X
// (right = cross(forward, up): a right-handed scene, as calf's camera model is.)
struct UprightFace {
  Vec3 forward, up;
};
UprightFace upright_face(CubeFace face);
// The texel (x, y) of face `face` shown at pixel (i, j) of its upright N x N image: (N-1-i, j).
inline Texel texel_from_upright_pixel(CubeFace face, uint32_t i, uint32_t j, uint32_t face_size) {
  return {face, face_size - 1 - i, j};
}

}  // namespace calf
