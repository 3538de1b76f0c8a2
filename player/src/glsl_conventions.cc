#include "calf/player/glsl_conventions.h"

namespace calf::player {

// Mirrors format/src/cube.cc (kFaceAxes: OpenGL 4.5 core Table 8.19) and format/src/log_depth.cc.
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

float calf_depth_from_code(uint code, float z_near, float z_far) {
  if (code == CALF_LOG16_SKY) return uintBitsToFloat(0x7F800000u);
  if (code == 0u) return z_near;
  if (code == CALF_LOG16_MAX_FINITE) return z_far;
  float log_near = log(z_near);
  float step = (log(z_far) - log_near) / 65534.0;
  return exp(log_near + float(code) * step);
}

uint calf_code_from_depth(float z, float z_near, float z_far) {
  if (isnan(z) || (isinf(z) && z > 0.0)) return CALF_LOG16_SKY;  // -inf codes as 0, like C++
  if (!(z > z_near)) return 0u;
  if (z >= z_far) return CALF_LOG16_MAX_FINITE;
  float log_near = log(z_near);
  float inv_step = 65534.0 / (log(z_far) - log_near);
  float code = floor((log(z) - log_near) * inv_step + 0.5);
  return code >= 65534.0 ? CALF_LOG16_MAX_FINITE : uint(code);
}

float calf_normalized_from_depth(float z, float z_near, float z_far) {
  float log_near = log(z_near);
  return (log(z) - log_near) / (log(z_far) - log_near);
}

float calf_depth_from_normalized(float x, float z_near, float z_far) {
  float log_near = log(z_near);
  return exp(log_near + x * (log(z_far) - log_near));
}
)glsl";

}  // namespace calf::player
