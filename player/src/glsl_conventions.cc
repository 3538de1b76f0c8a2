#include "calf/player/glsl_conventions.h"

#include <cmath>

namespace calf::player {

GlslRasterCamera glsl_raster_camera(const Camera& camera, double near) {
  const CameraFrame frame = camera_frame(camera);
  const double h = std::tan(camera.fov_y / 2);
  const auto f = [](double x) { return static_cast<float>(x); };
  return {{f(frame.right.x), f(frame.right.y), f(frame.right.z)},
          {f(frame.up.x), f(frame.up.y), f(frame.up.z)},
          {f(frame.forward.x), f(frame.forward.y), f(frame.forward.z)},
          f(h * camera.width / camera.height),
          f(h),
          f(near)};
}

GlslLogRange glsl_log_range(const LogDepthRange& range) {
  // The same double expressions as LogDepthRange's constructor, rounded to float once.
  const double step = range.relative_step();
  return {range.z_near(), range.z_far(),
          static_cast<float>(std::log(static_cast<double>(range.z_near()))),
          static_cast<float>(step), static_cast<float>(1.0 / step)};
}

// Mirrors format/src/cube.cc (kFaceAxes: OpenGL 4.5 core Table 8.19), format/src/log_depth.cc and
// format/src/camera.cc (the pinhole the rasterisers project with).
// Keep the two in step: the integration test fails when they drift.
const char* const kGlslConventions = R"glsl(
const uint CALF_LOG16_SKY = 65535u;
const uint CALF_LOG16_MAX_FINITE = 65534u;

int calf_face_from_direction(vec3 d) {
  vec3 a = abs(d);
  // Ties go to the first axis in X, Y, Z order, so seams and corners belong to one face.
  if (a.x >= a.y && a.x >= a.z) return d.x < 0.0 ? 1 : 0;
  if (a.y >= a.z) return d.y < 0.0 ? 3 : 2;
  return d.z < 0.0 ? 5 : 4;
}

// sc, tc and the major component's magnitude per face.
vec3 calf_face_axes(vec3 d, int face) {
  if (face == 0) return vec3(-d.z, -d.y, d.x);
  if (face == 1) return vec3(d.z, -d.y, -d.x);
  if (face == 2) return vec3(d.x, d.z, d.y);
  if (face == 3) return vec3(d.x, -d.z, -d.y);
  if (face == 4) return vec3(d.x, -d.y, d.z);
  return vec3(-d.x, -d.y, -d.z);
}

vec2 calf_st_from_direction(vec3 d, int face) {
  vec3 a = calf_face_axes(d, face);
  float inv = 1.0 / a.z;
  return 0.5 * (a.xy * inv + 1.0);
}

vec3 calf_direction_from_st(int face, vec2 st) {
  float sc = 2.0 * st.x - 1.0;
  float tc = 2.0 * st.y - 1.0;
  vec3 v;
  if (face == 0) v = vec3(1.0, -tc, -sc);
  else if (face == 1) v = vec3(-1.0, -tc, sc);
  else if (face == 2) v = vec3(sc, 1.0, tc);
  else if (face == 3) v = vec3(sc, -1.0, -tc);
  else if (face == 4) v = vec3(sc, -tc, 1.0);
  else v = vec3(-sc, -tc, -1.0);
  return v / sqrt(dot(v, v));
}

vec2 calf_texel_coord_from_st(vec2 st, uint n) {
  return st * float(n);
}

struct CalfLogRange {
  float z_near;
  float z_far;
  float log_near;  // ln z_near
  float step;      // ln(z_far / z_near) / 65534: ln depth per code
  float inv_step;  // 1 / step
};

float calf_log_depth_from_code(uint code, CalfLogRange r) {
  return r.log_near + float(code) * r.step;
}

float calf_depth_from_code(uint code, CalfLogRange r) {
  if (code == CALF_LOG16_SKY) return uintBitsToFloat(0x7F800000u);
  // The ends are exact, as in C++: z_near and z_far are stored, not recomputed.
  if (code == 0u) return r.z_near;
  if (code == CALF_LOG16_MAX_FINITE) return r.z_far;
  return exp(calf_log_depth_from_code(code, r));
}

float calf_code_from_log_depth(float log_z, CalfLogRange r) {
  return (log_z - r.log_near) * r.inv_step;
}

struct CalfRasterCamera {
  vec3 right;
  vec3 up;
  vec3 forward;
  float scale_x;
  float scale_y;
  float near_distance;
};

vec4 calf_raster_position(vec3 rel, CalfRasterCamera c) {
  return vec4(dot(rel, c.right) / c.scale_x, dot(rel, c.up) / c.scale_y, c.near_distance,
              dot(rel, c.forward));
}
)glsl";

}  // namespace calf::player
