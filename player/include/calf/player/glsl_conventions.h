// The GLSL side of calf's conventions: cube-face direction <-> (face, s, t) with the seam
// tie-break of calf/format/cube.h, and the log-16 depth mapping of calf/format/log_depth.h, with
// the same formulas in the same order. tests/integration/glsl_conventions_test.cc runs this source
// under OSMesa on thousands of directions (seams and corners included) and on every depth code,
// and compares with the C++ functions.
//
// The source has no #version line: shaders paste it after their own "#version 450 core". It
// declares (face indices in OpenGL order, 0 = +X ... 5 = -Z; st in [0, 1]; codes as uint):
//
//   int   calf_face_from_direction(vec3 d)          ties go to X, then Y, then Z, like C++
//   vec2  calf_st_from_direction(vec3 d, int face)  (s, t) on `face` (d must point into it)
//   vec3  calf_direction_from_st(int face, vec2 st) unit direction; st outside [0, 1] continues
//                                                   the face's plane
//   vec2  calf_texel_coord_from_st(vec2 st, uint n) texel space: centres at half-integers
//   float calf_depth_from_code(uint code, float z_near, float z_far)   +inf for the sky code
//   uint  calf_code_from_depth(float z, float z_near, float z_far)     encode_unchecked()
//   float calf_normalized_from_depth(float z, float z_near, float z_far)  Alg. 4 nonlin()
//   float calf_depth_from_normalized(float x, float z_near, float z_far)  Alg. 4 lin()
//   const uint CALF_LOG16_SKY = 65535u, CALF_LOG16_MAX_FINITE = 65534u
//
// Precision: GLSL computes in float where C++ uses double. Face choice is identical for the same
// float direction (comparisons of the same values); s and t agree to a few float ulps; decoded
// depths to a relative 4e-6 (float exp/log); codes from calf_code_from_depth may differ by one
// from the C++ encoder for depths within float rounding of a half-code boundary. The test states
// and checks these bounds.
#pragma once

namespace calf::player {

extern const char* const kGlslConventions;

}  // namespace calf::player
