// The GLSL side of calf's conventions: cube-face direction <-> (face, s, t) with the seam
// tie-break of calf/format/cube.h, and the log-16 depth mapping of calf/format/log_depth.h, with
// the same formulas in the same order. This is the one GLSL copy: the ray-march shader
// (gl_raymarch_shader.cc) is compiled after it and calls these functions for every cube-face
// lookup and every depth code, the rasterisers (mesh, surfels, tiles) for their camera, and
// tests/integration/glsl_conventions_test.cc runs the same source
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
//   struct CalfLogRange { float z_near, z_far, log_near, step, inv_step; }
//                                                   one view's range with LogDepthRange's
//                                                   constants; fill it from glsl_log_range()
//   float calf_depth_from_code(uint code, CalfLogRange r)      decode(): +inf for the sky code,
//                                                              z_near and z_far exact at the ends
//   float calf_log_depth_from_code(uint code, CalfLogRange r)  ln z of a finite code
//   float calf_code_from_log_depth(float log_z, CalfLogRange r) the continuous code of ln z
//                                                   (neither rounded nor clamped):
//                                                   normalized_from_depth(z) * 65534
//   const uint CALF_LOG16_SKY = 65535u, CALF_LOG16_MAX_FINITE = 65534u
//   struct CalfRasterCamera { vec3 right, up, forward; float scale_x, scale_y, near_distance; }
//                                                   calf/format/camera.h's camera for the
//                                                   rasterisers; fill it from glsl_raster_camera()
//   vec4  calf_raster_position(vec3 rel, CalfRasterCamera c)   the clip position of `rel` (a
//                                                   point minus the eye): reversed Z with an
//                                                   infinite far plane in GL's zero-to-one clip
//                                                   range (glClipControl(GL_LOWER_LEFT,
//                                                   GL_ZERO_TO_ONE), depth test GL_GREATER):
//                                                   window x, y those of camera.h's pixel rays,
//                                                   depth near / z (z along forward), clipped
//                                                   where z < near
//
// Precision: GLSL computes in float where C++ uses double; the range constants are computed in
// double on the host and rounded once. Face choice is identical for the same float direction
// (comparisons of the same values); s and t agree to a few float ulps; decoded depths to a
// relative 4e-6 (float exp); continuous codes to float resolution of ln z. The test states and
// checks these bounds.
#pragma once

#include "calf/format/camera.h"
#include "calf/format/log_depth.h"

namespace calf::player {

extern const char* const kGlslConventions;

// The CalfLogRange a shader receives for `range`: z_near and z_far as stored, ln z_near, the
// relative step and its inverse computed in double and rounded to float once.
struct GlslLogRange {
  float z_near, z_far, log_near, step, inv_step;
};
GlslLogRange glsl_log_range(const LogDepthRange& range);

// The CalfRasterCamera a rasteriser receives for `camera` (valid: validate_camera) and the near
// plane at distance `near`: camera_frame()'s unit axes, tan(fov_y / 2) times the aspect and
// tan(fov_y / 2), computed in double and rounded to float once.
struct GlslRasterCamera {
  float right[3], up[3], forward[3];
  float scale_x, scale_y, near_distance;
};
GlslRasterCamera glsl_raster_camera(const Camera& camera, double near);

}  // namespace calf::player
