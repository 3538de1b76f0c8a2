// The RR variant of Alg. 4 (CalculateColor_RR, Sec. 6.1): reflection and refraction rays spawned
// from the material faces, with normals from neighbouring depths.
#include <algorithm>
#include <cmath>

#include "calf/player/lightfield_cpu_renderer.h"
#include "sampling.h"

namespace calf::player {

namespace {

// The scene point a texel of `v` stands for, or false for sky.
bool texel_point(const View& v, const Texel& t, Vec3* q) {
  const uint16_t code = v.depth_code_at(t.face, t.x, t.y);
  if (code == kLog16Sky) return false;
  *q =
      v.position() + direction_from_texel(t.face, t.x, t.y, v.face_size()) * v.range().decode(code);
  return true;
}

// The tangent along one texel axis at `centre`. Where both neighbours continue the surface
// evenly (their distances from the centre point within a factor 2 of each other) the central
// difference, which is the tangent at the texel itself (a one-sided difference is the tangent
// half a texel away: on a curved mirror the normal would jump from texel to texel, +0.2 dB on
// mirror-box with RR); otherwise the one-sided difference to the nearer neighbour, which never
// reaches across a depth discontinuity. False when both are sky.
bool tangent(const View& v, const Texel& t, int dx, int dy, const Vec3& centre, Vec3* out) {
  const uint32_t n = v.face_size();
  Vec3 a, b;
  const bool ha =
      texel_point(v, texel_beyond_face(t.face, int64_t{t.x} + dx, int64_t{t.y} + dy, n), &a);
  const bool hb =
      texel_point(v, texel_beyond_face(t.face, int64_t{t.x} - dx, int64_t{t.y} - dy, n), &b);
  if (!ha && !hb) return false;
  const double la = ha ? length(a - centre) : 0, lb = hb ? length(b - centre) : 0;
  if (ha && hb && la <= 2 * lb && lb <= 2 * la) {
    *out = a - b;
    return true;
  }
  if (ha && (!hb || la <= lb)) {
    *out = a - centre;
  } else {
    *out = centre - b;
  }
  return true;
}

// GLSL refract(): eta = n1 / n2; false on total internal reflection.
bool refract_dir(const Vec3& d, const Vec3& n, double eta, Vec3* out) {
  const double c = dot(n, d);
  const double k = 1 - eta * eta * (1 - c * c);
  if (k < 0) return false;
  *out = normalize(d * eta - n * (eta * c + std::sqrt(k)));
  return true;
}

// The unit normal at texel `t` of `v` from its neighbours' points, facing against `facing`;
// false where the neighbourhood is sky.
bool texel_normal(const View& v, const Texel& t, const Vec3& facing, Vec3* n) {
  Vec3 centre, tu, tv;
  if (!texel_point(v, t, &centre) || !tangent(v, t, 1, 0, centre, &tu) ||
      !tangent(v, t, 0, 1, centre, &tv)) {
    return false;
  }
  *n = cross(tu, tv);
  if (!(length(*n) > 0)) return false;
  *n = normalize(*n);
  if (dot(*n, facing) > 0) *n = *n * -1.0;
  return true;
}

}  // namespace

// One reflection or refraction ray leaving surface point p (normal n, either orientation) for
// an incoming unit direction d_in, shaded: the colour it brings back.
void LightfieldCpuRenderer::secondary(const Vec3& p, const Vec3& d_in, const Vec3& normal,
                                      bool refraction, double ior, uint32_t depth,
                                      double* rgb) const {
  const Vec3 n = dot(normal, d_in) > 0 ? normal * -1.0 : normal;  // facing the incoming ray
  Vec3 dir = normalize(d_in - n * (2 * dot(d_in, n)));            // reflection; refraction's TIR
  if (refraction) refract_dir(d_in, n, 1.0 / ior, &dir);
  Hit next;
  if (intersect(p, dir, options_.rr_start, &next)) {
    shade_rr(p, dir, next, depth + 1, rgb);
  } else {
    shade_sky(p, dir, rgb);  // a mirror shows the sky (the paper drops the weight)
  }
}

void LightfieldCpuRenderer::shade_rr(const Vec3& o, const Vec3& d, const Hit& hit, uint32_t depth,
                                     double* rgb) const {
  int best = -1;
  double diffuse[3], own[3] = {0, 0, 0};
  shade_surface(o, hit.p, diffuse, &best, own);
  for (int ch = 0; ch < 3; ++ch) rgb[ch] = diffuse[ch];
  if (best < 0 || depth >= options_.rr_max_depth) return;
  // Material and normal come from the view that weighs most at p (nearest texel): material is
  // categorical at object edges, where blending weights would invent half-mirrors.
  const View& v = *active_[best];
  const Vec3 x = hit.p - v.position();
  const Texel t = texel_from_direction(x, v.face_size());
  const Material m = v.material_at(t.face, t.x, t.y);
  if (!(m.reflect > 0) && !(m.refract > 0)) return;
  Vec3 n;
  if (!texel_normal(v, t, d, &n)) return;
  const double w[2] = {m.reflect, m.refract};
  if (options_.rr_replace_view_reflection) {
    // The view's colour with its own reflection / refraction swapped for the eye's.
    const Vec3 dv = normalize(x);
    for (int ch = 0; ch < 3; ++ch) rgb[ch] = own[ch];
    for (int kind = 0; kind < 2; ++kind) {
      if (!(w[kind] > 0)) continue;
      double eye[3] = {0, 0, 0}, view[3] = {0, 0, 0};
      secondary(hit.p, d, n, kind == 1, m.ior, depth, eye);
      secondary(hit.p, dv, n, kind == 1, m.ior, depth, view);
      for (int ch = 0; ch < 3; ++ch) rgb[ch] += w[kind] * (eye[ch] - view[ch]);
    }
    return;  // may be negative: trace() clamps the pixel
  }
  double c[2][3] = {{0, 0, 0}, {0, 0, 0}};
  for (int kind = 0; kind < 2; ++kind) {
    if (w[kind] > 0) secondary(hit.p, d, n, kind == 1, m.ior, depth, c[kind]);
  }
  const double wd = 1 - w[0] - w[1];
  for (int ch = 0; ch < 3; ++ch) rgb[ch] = w[0] * c[0][ch] + w[1] * c[1][ch] + wd * diffuse[ch];
}

}  // namespace calf::player
