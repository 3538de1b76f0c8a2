#include "gl_raymarch_shader.h"

namespace calf::player::internal {

const char* const kGlFullscreenVertex = R"glsl(
void main() {
  // (-1, -1), (3, -1), (-1, 3): one triangle covering the viewport.
  vec2 p = vec2(float((gl_VertexID & 1) << 2) - 1.0, float((gl_VertexID & 2) << 1) - 1.0);
  gl_Position = vec4(p, 0.0, 1.0);
}
)glsl";

// The structure follows the CPU reference function for function (names in comments), so a change
// there is mirrored here in the same place. Positions are relative to the eye: the CPU works in
// double, the GPU in float, and eye-relative coordinates keep the float error independent of
// where the scene sits.
const char* const kGlRaymarchFragment = R"glsl(
struct CalfView {
  vec3 position;  // relative to the eye
  float log_near;  // the CalfLogRange of the view (glsl_conventions.h), spread over the record
  float step;      // so that the record packs into 64 bytes (std140)
  float inv_step;
  float z_near;
  float z_far;
  uint face_size;
  uint cell_size;
  uint layer;        // 6 * view index
  int material_layer;  // -1: no material
  int coverage_layer;  // -1: no coverage
};
// A uniform block, not a storage buffer: llvmpipe loads it as uniform data (measured 20 % faster
// than the same records in an SSBO). Sized by CALF_MAX_VIEWS, defined by the host.
layout(std140, binding = 0) uniform CalfViews { CalfView views[CALF_MAX_VIEWS]; };

layout(binding = 0) uniform sampler2DArray colour_tex;
#ifdef CALF_DEPTH_BC5
layout(binding = 1) uniform sampler2DArray depth_tex;
#else
layout(binding = 1) uniform usampler2DArray depth_tex;
#endif
layout(binding = 2) uniform usampler2DArray cell_tex;
layout(binding = 3) uniform sampler2DArray material_tex;
layout(binding = 4) uniform usampler2DArray coverage_tex;

uniform uint view_count;         // active views, in views[]
uniform uint colour_slots;       // 2 keyframe slots per face, or 1
uniform uint steps;              // N_step
uniform uint refine_steps;
uniform float march_near;        // LightfieldRenderOptions::near
uniform float march_log_ratio;   // ln(far / near)
uniform float min_view_distance;
uniform float footprint_limit;   // depth_footprint - 1e-9
uniform float smooth_log_ratio;  // ln(1 + smooth_depth_ratio)
uniform float depth_decay;
uniform float cam_decay;
uniform uint blend_views;        // LightfieldRenderOptions::blend_views (0: cam_decay)
uniform float colour_depth_tolerance;
uniform float colour_sharpen;             // LightfieldRenderOptions::colour_sharpen
uniform float colour_sharpen_jump_texels;
uniform float mixed_penalty_factor;  // exp(-mixed_texel_penalty); 1 = off
uniform float mixed_texel_bend_texels;  // in texel angles, 2 / face size radians
uniform uint coverage_mode;      // LightfieldRenderOptions::coverage (read with CALF_COVERAGE only)
uniform float coverage_threshold;
uniform float coverage_cluster;
uniform uint coverage_agreement;
uniform bool tight_march_start;
uniform bool bilinear_colour;
uniform bool depth_aware_colour;
uniform float surface_hint_margin_texels;  // of its own texels a vetoing view must see beyond
uniform uint surface_hint_vetoes;   // vetoes a hint crossing survives
uniform uint surface_hint_substeps; // hint tests per step
uniform uint surface_hint_coverage; // LightfieldRenderOptions::surface_hint_coverage (0, 1)
uniform bool rr;
uniform bool rr_replace_view_reflection;
uniform float rr_start;
uniform uint rr_max_depth;
uniform uvec2 image_size;
uniform uint supersample;        // eye rays per pixel along each axis
uniform uint ray_first;          // this pass's rays: [ray_first, ray_first + ray_count) of the
uniform uint ray_count;          // supersample^2 grid, row-major
uniform vec3 cam_forward;        // unit forward
uniform vec3 cam_right;          // unit right * tan(fov_y / 2) * aspect
uniform vec3 cam_up;             // unit up * tan(fov_y / 2)

layout(location = 0) out vec4 out_colour;  // rgb, radial hit distance (+inf: sky)

const float INF = uintBitsToFloat(0x7F800000u);
// A depth-first walk pops one ray and pushes at most 4 (reflection and refraction, for the eye
// and, with replacement, for the view): at most 3 rr_max_depth + 4 <= 28 rays wait at a time.
const int RR_STACK = 28;

// ---- texel fetches (sampling.cc) ----

// Texel index from a texel-space coordinate, clamped to the face (texel_from_direction).
int clamp_texel(float u, uint n) {
  if (!(u > 0.0)) return 0;
  float f = floor(u);
  return f >= float(n) ? int(n) - 1 : int(f);
}

// texel_beyond_face: (x, y, face) of a texel that may lie one texel off the face, re-projected
// onto the neighbouring face through the conventions.
ivec3 texel_beyond_face(int face, int x, int y, uint n) {
  if (x >= 0 && y >= 0 && x < int(n) && y < int(n)) return ivec3(x, y, face);
  vec3 d = calf_direction_from_st(face, (vec2(x, y) + 0.5) / float(n));
  int f = calf_face_from_direction(d);
  vec2 uv = calf_texel_coord_from_st(calf_st_from_direction(d, f), n);
  return ivec3(clamp_texel(uv.x, n), clamp_texel(uv.y, n), f);
}

struct Taps {
  ivec3 texel[4];
  float weight[4];
  float offset[4];
};

// bilinear_taps: the four texel centres around texel-space position uv of `face`.
Taps bilinear_taps(int face, vec2 uv, uint n) {
  vec2 c = uv - 0.5;
  vec2 f0 = floor(c);
  vec2 a = c - f0;
  ivec2 i0 = ivec2(f0);
  Taps t;
  t.texel[0] = texel_beyond_face(face, i0.x, i0.y, n);
  t.texel[1] = texel_beyond_face(face, i0.x + 1, i0.y, n);
  t.texel[2] = texel_beyond_face(face, i0.x, i0.y + 1, n);
  t.texel[3] = texel_beyond_face(face, i0.x + 1, i0.y + 1, n);
  t.weight[0] = (1.0 - a.x) * (1.0 - a.y);
  t.weight[1] = a.x * (1.0 - a.y);
  t.weight[2] = (1.0 - a.x) * a.y;
  t.weight[3] = a.x * a.y;
  t.offset[0] = max(a.x, a.y);
  t.offset[1] = max(1.0 - a.x, a.y);
  t.offset[2] = max(a.x, 1.0 - a.y);
  t.offset[3] = max(1.0 - a.x, 1.0 - a.y);
  return t;
}

// Where direction x of view v points: face and texel-space position (texel_coord_from_direction).
int face_of(vec3 x) { return calf_face_from_direction(x); }
vec2 texel_coord(vec3 x, int face, uint n) {
  return calf_texel_coord_from_st(calf_st_from_direction(x, face), n);
}

uint depth_code(CalfView v, ivec3 t) {
#ifdef CALF_DEPTH_BC5
  vec2 rg = texelFetch(depth_tex, ivec3(t.xy, int(v.layer) + t.z), 0).rg;
  return uint(round(rg.r * 255.0)) * 256u + uint(round(rg.g * 255.0));
#else
  return texelFetch(depth_tex, ivec3(t.xy, int(v.layer) + t.z), 0).r;
#endif
}

// The view's log-16 range, for the conventions' depth functions.
CalfLogRange log_range(CalfView v) {
  return CalfLogRange(v.z_near, v.z_far, v.log_near, v.step, v.inv_step);
}

// texel_angles_in_codes: `texels` texel angles of v (2 / face size radians each) as a relative
// depth in v's code units.
float texel_angles_in_codes(CalfView v, float texels) {
  return texels * 2.0 / float(v.face_size) * v.inv_step;
}

// |ln(decode(code) / r)| given ln r.
float log_disagreement(CalfView v, uint code, float log_r) {
  return abs(calf_log_depth_from_code(code, log_range(v)) - log_r);
}

// The colour a view shows at a texel: its cell's keyframe slots blended by t (SPEC §11.1.4).
vec3 colour_at(CalfView v, ivec3 t) {
  int face_layer = int(v.layer) + t.z;
  uint cell = texelFetch(cell_tex, ivec3(t.xy / int(v.cell_size), face_layer), 0).r;
  uint w = cell & 255u;
  int a = int((cell >> 8) & 1u);
  int base = face_layer * int(colour_slots);
  vec3 ca = texelFetch(colour_tex, ivec3(t.xy, base + a), 0).rgb;
  if (w == 0u) return ca;
  vec3 cb = texelFetch(colour_tex, ivec3(t.xy, base + 1 - a), 0).rgb;
  return mix(ca, cb, float(w) / 255.0);
}

// ---- code_margin (lightfield_cpu_renderer.cc): how far in front of its surface view v sees the point at
// offset x (r = |x|), in code units: > 0 in front, <= 0 at or behind, +inf where v sees sky ----
float code_margin(CalfView v, vec3 x, float r) {
  int face = face_of(x);
  Taps taps = bilinear_taps(face, texel_coord(x, face, v.face_size), v.face_size);
  uint c[4];
  uint lo = CALF_LOG16_SKY, hi = 0u;
  for (int t = 0; t < 4; ++t) {
    c[t] = depth_code(v, taps.texel[t]);
    lo = min(lo, c[t]);
    hi = max(hi, c[t]);
  }
  float rcode = calf_code_from_log_depth(log(r), log_range(v));
  if (hi != CALF_LOG16_SKY && float(hi - lo) * v.step <= smooth_log_ratio) {
    float code = 0.0;
    for (int t = 0; t < 4; ++t) code += taps.weight[t] * float(c[t]);
    return code - rcode;
  }
  uint code = CALF_LOG16_SKY;
  int nearest = 0;
  for (int t = 0; t < 4; ++t) {
    if (taps.weight[t] > taps.weight[nearest]) nearest = t;
    if (taps.offset[t] < footprint_limit) code = min(code, c[t]);
  }
  code = min(code, c[nearest]);
  return code == CALF_LOG16_SKY ? INF : float(code) - rcode;
}

#ifdef CALF_COVERAGE
// ---- coverage_margin (lightfield_cpu_renderer.cc): where code_margin's `margin` puts the point at or behind
// the footprint's surface, the view's coverage says whether that surface covers the direction
// inside the texel; where it does not, the margin is measured against the surface behind it ----
float coverage_margin(CalfView v, vec3 x, float r, float margin) {
  if (margin > 0.0 || coverage_mode == 0u || v.coverage_layer < 0) return margin;
  int face = face_of(x);
  vec2 uv = texel_coord(x, face, v.face_size);
  Taps taps = bilinear_taps(face, uv, v.face_size);
  float rcode = calf_code_from_log_depth(log(r), log_range(v));
  float front_code = rcode + margin;  // the footprint's surface
  float cluster_codes = coverage_cluster * v.inv_step;
  bool front[4];
  bool edge = false;
  uvec4 cov[4];
  int nearest = 0;
  float back = -1.0;  // the farthest tap outside the front cluster (CALF_LOG16_SKY: sky)
  for (int t = 0; t < 4; ++t) {
    uint c = depth_code(v, taps.texel[t]);
    // mask low byte, mask high byte, near count, far count (of 16 cells)
    cov[t] = texelFetch(coverage_tex, ivec3(taps.texel[t].xy, v.coverage_layer + taps.texel[t].z),
                        0);
    front[t] = c != CALF_LOG16_SKY && float(c) - front_code <= cluster_codes;
    if (!front[t]) back = max(back, float(c));
    if (cov[t].x != 255u || cov[t].y != 255u || cov[t].z > 0u || cov[t].w > 0u || !front[t]) {
      edge = true;
    }
    if (taps.weight[t] > taps.weight[nearest]) nearest = t;
  }
  if (!edge) return margin;
  bool covered = false;
  if (coverage_mode == 1u) {
    float o = 0.0;
    for (int t = 0; t < 4; ++t) {
      o += taps.weight[t] * (front[t] ? 1.0 - float(cov[t].w) / 16.0 : float(cov[t].z) / 16.0);
    }
    covered = o >= coverage_threshold;
  } else if (coverage_mode == 4u) {
    // Every tap's cell nearest the direction; front shares for a tap across a face seam.
    vec2 base = floor(uv - 0.5);
    float o = 0.0;
    for (int t = 0; t < 4; ++t) {
      vec2 txy = base + vec2(float(t & 1), float(t >> 1));
      float share;
      if (taps.texel[t].z == face && vec2(taps.texel[t].xy) == txy) {
        ivec2 c = clamp(ivec2(floor((uv - txy) * 4.0)), ivec2(0), ivec2(3));
        bool own = ((uint(cov[t].x | cov[t].y << 8) >> uint(4 * c.y + c.x)) & 1u) != 0u;
        share = own == front[t] ? 1.0 : 0.0;
      } else {
        share = front[t] ? 1.0 - float(cov[t].w) / 16.0 : float(cov[t].z) / 16.0;
      }
      o += taps.weight[t] * share;
    }
    covered = o >= coverage_threshold;
  } else {
    // The cell of the nearest texel that the direction falls in (clamped coordinates ignored).
    ivec2 cell = clamp(ivec2(floor((uv - floor(uv)) * 4.0)), ivec2(0), ivec2(3));
    uint mask = cov[nearest].x | cov[nearest].y << 8;
    if (!front[nearest]) mask = ~mask;
    // Modes 3 and 5: the front grown by one cell, except (mode 5) into a texel behind it.
    bool behind = coverage_mode == 5u && !front[nearest];
    int grow = coverage_mode == 2u || behind ? 0 : 1;
    for (int j = max(cell.y - grow, 0); j <= min(cell.y + grow, 3); ++j) {
      for (int i = max(cell.x - grow, 0); i <= min(cell.x + grow, 3); ++i) {
        covered = covered || ((mask >> uint(4 * j + i)) & 1u) != 0u;
      }
    }
    if (behind) {
      // The nearest texel lies behind the front: its own surface where its cell shows it; the
      // surface behind where its other cells are only farther ones.
      if (!covered) {
        uint own = depth_code(v, taps.texel[nearest]);
        return own == CALF_LOG16_SKY ? INF : float(own) - rcode;
      }
      if (cov[nearest].z == 0u) covered = false;
    }
  }
  if (covered || back < 0.0) return margin;
  return back == float(CALF_LOG16_SKY) ? INF : back - rcode;
}
#endif

// ---- LightfieldCpuRenderer::empty_at / empty_beyond: BetweenViewpointAndGeometry over the active views,
// true as soon as one view that is not too near sees p in front of its surface by more than
// `margin_texels` of its own texels (relative depth margin_texels x 2 / face size); with
// coverage, votes that only the coverage gives count once coverage_agreement views agree ----
bool empty_beyond(vec3 p, float margin_texels, uint vetoes_ignored) {
  bool consulted = false;
  uint vetoes = 0u;
#ifdef CALF_COVERAGE
  uint coverage_votes = 0u;
#endif
  for (uint k = 0u; k < view_count; ++k) {
    CalfView v = views[k];
    vec3 x = p - v.position;
    float r = length(x);
    if (r <= min_view_distance) continue;
    consulted = true;
#ifdef CALF_COVERAGE
    float plain = code_margin(v, x, r);
    float threshold = texel_angles_in_codes(v, margin_texels);
    if (!(coverage_margin(v, x, r, plain) > threshold)) continue;
    if (plain > threshold) {
      ++vetoes;
    } else {
      ++coverage_votes;
    }
    uint counted = vetoes + (coverage_votes >= coverage_agreement ? coverage_votes : 0u);
    if (counted > vetoes_ignored) return true;
#else
    if (code_margin(v, x, r) > texel_angles_in_codes(v, margin_texels) &&
        ++vetoes > vetoes_ignored) {
      return true;
    }
#endif
  }
  return !consulted;
}

// ---- LightfieldCpuRenderer::intersect: RayIntersection ----
float lin(float x) { return march_near * exp(x * march_log_ratio); }

// The hint test of intersect()'s `side`: -1 view h does not vote at the sample (too near its
// centre), 0 behind its surface, 1 in front (nearest texel; sky counts as in front).
int hint_side(uint h, vec3 o, vec3 d, float x) {
  CalfView v = views[h];
  vec3 rel = o + d * lin(x) - v.position;
  float r = length(rel);
  if (r <= min_view_distance) return -1;
  int face = face_of(rel);
  vec2 uv = texel_coord(rel, face, v.face_size);
  uint code = depth_code(v, ivec3(clamp_texel(uv.x, v.face_size),
                                  clamp_texel(uv.y, v.face_size), face));
  if (code == CALF_LOG16_SKY) return 1;
  return float(code) > calf_code_from_log_depth(log(r), log_range(v)) ? 1 : 0;
}

// ---- LightfieldCpuRenderer::hint_confirmed (surface_hint_coverage 1): whether view h's coverage
// says its surface covers the direction, at the point x of the ray, inside the texel the
// direction falls in (its cell); no coverage confirms ----
bool hint_confirmed(uint h, vec3 o, vec3 d, float x) {
#ifdef CALF_COVERAGE
  CalfView v = views[h];
  if (surface_hint_coverage == 0u || v.coverage_layer < 0) return true;
  vec3 rel = o + d * lin(x) - v.position;
  int face = face_of(rel);
  vec2 uv = texel_coord(rel, face, v.face_size);
  ivec2 t = ivec2(clamp_texel(uv.x, v.face_size), clamp_texel(uv.y, v.face_size));
  uvec4 cov = texelFetch(coverage_tex, ivec3(t, v.coverage_layer + face), 0);
  uint mask = cov.x | cov.y << 8;
  if (mask == 0xFFFFu) return true;
  ivec2 cell = clamp(ivec2(floor((uv - floor(uv)) * 4.0)), ivec2(0), ivec2(3));
  return ((mask >> uint(4 * cell.y + cell.x)) & 1u) != 0u;
#else
  return true;
#endif
}

bool intersect(vec3 o, vec3 d, float start, out float z_hit) {
  z_hit = INF;
  if (tight_march_start) {
    // Nearer than z_near_j to P_j, view j sees every point as empty: nothing to find before.
    for (uint k = 0u; k < view_count; ++k) {
      start = max(start, views[k].z_near - length(o - views[k].position));
    }
  }
  float x0 = log(max(start, march_near) / march_near) / march_log_ratio;
  if (!(x0 < 1.0)) return false;
  float step = (1.0 - x0) / float(steps);
#if CALF_HINTS > 0
  // Surface hints: the views nearest the ray origin, nearest first (ties: lower index). Their
  // count is compiled in (CALF_HINTS = LightfieldRenderOptions::surface_hints), so that the per-hint state
  // lives in registers: llvmpipe spills dynamically indexed arrays to memory.
  uint hints = min(uint(CALF_HINTS), view_count);
  uint hint[CALF_HINTS];
  float hint_dist[CALF_HINTS];
  int prev[CALF_HINTS];
  float crossing[CALF_HINTS];
  for (int h = 0; h < CALF_HINTS; ++h) {
    hint[h] = 0u;
    hint_dist[h] = INF;
    prev[h] = 0;
    crossing[h] = INF;
  }
  for (uint k = 0u; k < view_count; ++k) {
    float dv = length(o - views[k].position);
    uint cand = k;
    for (int h = 0; h < CALF_HINTS; ++h) {
      if (dv < hint_dist[h]) {
        float td = hint_dist[h];
        hint_dist[h] = dv;
        dv = td;
        uint tk = hint[h];
        hint[h] = cand;
        cand = tk;
      }
    }
  }
  uint h_next = 0u;
  float found = INF;
#endif
  // The march (samples i = 0..steps), the bisection of a hit (refine_steps halvings of [lo, hi])
  // and the confirmation of hint crossings (empty_beyond with the hint margin, one crossing per
  // pass) in one loop, so that empty_beyond() is instantiated once: the driver inlines every
  // call, and llvmpipe's compile time grows with the code.
  const int MARCH = 0, REFINE = 1, CONFIRM = 2;
  int state = MARCH;
  uint i = 0u, k = 0u;
  float lo = 0.0, hi = 0.0;
  for (;;) {
    float x;
    float margin = 0.0;
    uint vetoes_ignored = 0u;
#if CALF_HINTS > 0
    if (state == CONFIRM) {
      // The next crossing of this interval that would be nearer than one already confirmed.
      while (h_next < hints && !(crossing[h_next] < found)) ++h_next;
      if (h_next == hints) {
        if (found < INF) {
          z_hit = lin(found);
          return true;
        }
        state = MARCH;
        if (++i > steps) return false;
        continue;
      }
      x = crossing[h_next];
      margin = surface_hint_margin_texels;
      vetoes_ignored = surface_hint_vetoes;
    } else
#endif
    if (state == REFINE) {
      x = 0.5 * (lo + hi);
    } else {
      x = i == steps ? 1.0 : x0 + float(i) * step;
    }
    bool empty = empty_beyond(o + d * lin(x), margin, vetoes_ignored);
#if CALF_HINTS > 0
    if (state == CONFIRM) {
      if (!empty) found = x;
      ++h_next;
      continue;
    }
#endif
    if (state == REFINE) {
      if (empty) lo = x; else hi = x;
      if (++k >= refine_steps) break;
    } else if (!empty) {
      lo = x - step;
      hi = x;
      if (i == 0u) lo = hi;  // already behind a surface at the first sample: nothing to refine
      if (i == 0u || refine_steps == 0u) break;
      state = REFINE;
    } else {
#if CALF_HINTS > 0
      // An empty sample: where a hint view went from in front of its surface to behind it
      // between two of its substeps, locate the first such crossing of the step by bisection on
      // that view alone.
      bool any = false;
      float sub_step = step / float(surface_hint_substeps);
      for (int h = 0; h < CALF_HINTS; ++h) {
        crossing[h] = INF;
        if (uint(h) >= hints) continue;
        bool crossed = false;  // each hint offers its first crossing of the step
        for (uint s = i == 0u ? surface_hint_substeps : 1u; s <= surface_hint_substeps; ++s) {
          float xs = s == surface_hint_substeps ? x : x - step + float(s) * sub_step;
          int now = hint_side(hint[h], o, d, xs);
          if (i > 0u && !crossed && prev[h] == 1 && now == 0) {
            crossed = true;
            float clo = xs - sub_step, chi = xs;
            for (uint b = 0u; b < refine_steps; ++b) {
              float mid = 0.5 * (clo + chi);
              if (hint_side(hint[h], o, d, mid) == 1) clo = mid; else chi = mid;
            }
            if (hint_confirmed(hint[h], o, d, chi)) {
              crossing[h] = 0.5 * (clo + chi);
              any = true;
            }
          }
          prev[h] = now;
        }
      }
      if (any) {
        state = CONFIRM;
        h_next = 0u;
        found = INF;
        continue;
      }
#endif
      if (++i > steps) return false;
    }
  }
  z_hit = lin(0.5 * (lo + hi));
  return true;
}

// ---- mixed_texel / LightfieldCpuRenderer::tap_purity ----
bool mixed_texel(CalfView v, ivec3 t) {
  uint code = depth_code(v, t);
  const ivec2 kStep[4] = ivec2[4](ivec2(-1, 0), ivec2(1, 0), ivec2(0, -1), ivec2(0, 1));
  float bend[2] = float[2](0.0, 0.0);
  for (int k = 0; k < 4; ++k) {
    uint other = depth_code(v, texel_beyond_face(t.z, t.x + kStep[k].x, t.y + kStep[k].y,
                                                 v.face_size));
    if ((other == CALF_LOG16_SKY) != (code == CALF_LOG16_SKY)) return true;
    bend[k / 2] += float(other) - float(code);
  }
  float bend_codes = texel_angles_in_codes(v, mixed_texel_bend_texels);
  return code != CALF_LOG16_SKY && (abs(bend[0]) > bend_codes || abs(bend[1]) > bend_codes);
}

float tap_purity(CalfView v, ivec3 t) {
  if (mixed_penalty_factor == 1.0) return 1.0;
  return mixed_texel(v, t) ? mixed_penalty_factor : 1.0;
}

// ---- sharpen_strengths (sampling.cc), LightfieldCpuRenderer::tap_colour: the colour a bilinear
// tap reads, sharpened between texel centres ----
vec2 sharpen_strengths(Taps taps) {
  vec2 a = vec2(taps.weight[1] + taps.weight[3], taps.weight[2] + taps.weight[3]);
  return colour_sharpen * 4.0 * a * (1.0 - a);
}

vec3 tap_colour(CalfView v, ivec3 t, vec2 strength) {
  vec3 c = colour_at(v, t);
  if ((!(strength.x > 0.0) && !(strength.y > 0.0)) || mixed_texel(v, t)) return c;
  uint code = depth_code(v, t);
  bool sky = code == CALF_LOG16_SKY;
  float jump = texel_angles_in_codes(v, colour_sharpen_jump_texels);
  vec3 sum = vec3(0.0);
  for (int axis = 0; axis < 2; ++axis) {
    float s = axis == 0 ? strength.x : strength.y;
    if (!(s > 0.0)) continue;
    ivec2 d = axis == 0 ? ivec2(1, 0) : ivec2(0, 1);
    ivec3 ta = texel_beyond_face(t.z, t.x - d.x, t.y - d.y, v.face_size);
    ivec3 tb = texel_beyond_face(t.z, t.x + d.x, t.y + d.y, v.face_size);
    uint ca = depth_code(v, ta), cb = depth_code(v, tb);
    if ((ca == CALF_LOG16_SKY) != sky || (cb == CALF_LOG16_SKY) != sky) continue;
    if (!sky && (abs(float(ca) - float(code)) > jump || abs(float(cb) - float(code)) > jump)) {
      continue;
    }
    if (mixed_texel(v, ta) || mixed_texel(v, tb)) continue;
    sum += s * (2.0 * c - colour_at(v, ta) - colour_at(v, tb));
  }
  return clamp(c + sum, vec3(0.0), vec3(65504.0));  // what colour texels can hold
}

// ---- LightfieldCpuRenderer::blend_threshold (blend_views): the (K + 1)-th smallest
// a_j = |o - P_j| / |p - o| of the views that see p (nearest texel within 3 / depth_decay of the
// smallest disagreement), +inf where at most K do or all of them tie with the nearest ----
const float BLEND_SEE_WINDOW = 3.0;    // kBlendSeeWindow
const float BLEND_MIN_DISTANCE = 1e-9; // kBlendMinDistance
float view_disagreement(CalfView v, vec3 p) {
  vec3 x = p - v.position;
  float r = length(x);
  if (r <= min_view_distance) return INF;
  int face = face_of(x);
  vec2 uv = texel_coord(x, face, v.face_size);
  uint code = depth_code(v, ivec3(clamp_texel(uv.x, v.face_size),
                                  clamp_texel(uv.y, v.face_size), face));
  return code == CALF_LOG16_SKY ? INF : log_disagreement(v, code, log(r));
}

float blend_threshold(vec3 o, vec3 p, float hit_distance) {
  float dmin = INF;
  for (uint k = 0u; k < view_count; ++k) dmin = min(dmin, view_disagreement(views[k], p));
  if (dmin == INF) return INF;
  float limit = dmin + BLEND_SEE_WINDOW / depth_decay;
  uint keep = blend_views + 1u;
  float smallest[9];  // blend_views + 1, at most kMaxBlendViews + 1
  uint n = 0u;
  for (uint k = 0u; k < view_count; ++k) {
    if (!(view_disagreement(views[k], p) <= limit)) continue;
    float a = length(o - views[k].position) / hit_distance;
    for (uint i = 0u; i < n; ++i) {
      if (a < smallest[i]) {
        float t = smallest[i];
        smallest[i] = a;
        a = t;
      }
    }
    if (n < keep) smallest[n++] = a;
  }
  if (n < keep) return INF;
  return smallest[keep - 1u] > smallest[0] ? smallest[keep - 1u] : INF;
}

// ---- LightfieldCpuRenderer::shade_surface: SampleColor + CalculateColor ----
// The weighted mean is accumulated online, rescaled whenever a larger log weight arrives: the
// same exp(log_w - best) normalisation as the CPU's two passes, without an array of views.
// best_colour: the colour of the best-weighted view (rr_replace_view_reflection starts from it).
vec3 shade_surface(vec3 o, vec3 p, out int best_view, out vec3 best_colour) {
  float hit_distance = max(length(p - o), 1e-12);
  float blend_t = blend_views > 0u ? blend_threshold(o, p, hit_distance) : INF;
  vec3 sum = vec3(0.0);
  float wsum = 0.0, best = -INF;
  best_view = -1;
  best_colour = vec3(0.0);
  for (uint k = 0u; k < view_count; ++k) {
    CalfView v = views[k];
    vec3 x = p - v.position;
    float r = length(x);
    if (r <= min_view_distance) continue;
    int face = face_of(x);
    vec2 uv = texel_coord(x, face, v.face_size);
    ivec3 nearest = ivec3(clamp_texel(uv.x, v.face_size), clamp_texel(uv.y, v.face_size), face);
    uint ncode = depth_code(v, nearest);
    if (ncode == CALF_LOG16_SKY) continue;
    float log_r = log(r);
    float log_w = -depth_decay * log_disagreement(v, ncode, log_r);
    vec3 c = vec3(0.0);
    if (!bilinear_colour) {
      c = colour_at(v, nearest);
    } else {
      Taps taps = bilinear_taps(face, uv, v.face_size);
      float diff[4];
      float dmin = INF;
      for (int t = 0; t < 4; ++t) {
        uint code = depth_code(v, taps.texel[t]);
        diff[t] = code == CALF_LOG16_SKY ? INF : log_disagreement(v, code, log_r);
        if (taps.weight[t] > 0.0) dmin = min(dmin, diff[t]);
      }
      float a[4];
      float asum = 0.0;
      for (int t = 0; t < 4; ++t) {
        a[t] = taps.weight[t] > 0.0 ? taps.weight[t] * tap_purity(v, taps.texel[t]) : 0.0;
        if (depth_aware_colour) {
          a[t] *= diff[t] == INF
                      ? 0.0
                      : exp(-depth_decay * max(0.0, diff[t] - dmin - colour_depth_tolerance));
        }
        asum += a[t];
      }
      vec2 strength = sharpen_strengths(taps);
      for (int t = 0; t < 4; ++t) c += a[t] / asum * tap_colour(v, taps.texel[t], strength);
      if (depth_aware_colour) log_w = -depth_decay * dmin + log(asum);
    }
    float a_cam = length(o - v.position) / hit_distance;
    if (blend_views == 0u) {
      log_w -= cam_decay * a_cam;
    } else {
      // The Unstructured Lumigraph's weight; blend_t = +inf gives 1 / a.
      float w = max(0.0, 1.0 - a_cam / blend_t) / max(a_cam, BLEND_MIN_DISTANCE);
      if (!(w > 0.0)) continue;
      log_w += log(w);
    }
    if (log_w > best) {
      float rescale = exp(best - log_w);
      sum *= rescale;
      wsum *= rescale;
      best = log_w;
      best_view = int(k);
      best_colour = c;
    }
    float w = exp(log_w - best);
    sum += w * c;
    wsum += w;
  }
  return wsum > 0.0 ? sum / wsum : vec3(0.0);
}

// ---- LightfieldCpuRenderer::shade_sky ----
vec3 shade_sky(vec3 d) {
  for (int pass = 0; pass < 2; ++pass) {
    vec3 sum = vec3(0.0);
    float n = 0.0;
    for (uint k = 0u; k < view_count; ++k) {
      CalfView v = views[k];
      int face = face_of(d);
      vec2 uv = texel_coord(d, face, v.face_size);
      ivec3 nearest = ivec3(clamp_texel(uv.x, v.face_size), clamp_texel(uv.y, v.face_size), face);
      bool sky = depth_code(v, nearest) == CALF_LOG16_SKY;
      if (pass == 0 && !sky) continue;
      vec3 c = vec3(0.0);
      float w = 1.0;  // the view's weight
      if (!bilinear_colour) {
        c = colour_at(v, nearest);
      } else {
        Taps taps = bilinear_taps(face, uv, v.face_size);
        float a[4];
        float asum = 0.0, unpenalised = 0.0;
        for (int t = 0; t < 4; ++t) {
          bool tap_sky = depth_code(v, taps.texel[t]) == CALF_LOG16_SKY;
          a[t] = taps.weight[t] * (pass == 0 && depth_aware_colour && !tap_sky ? 0.0 : 1.0);
          unpenalised += a[t];
          if (a[t] > 0.0) a[t] *= tap_purity(v, taps.texel[t]);
          asum += a[t];
        }
        vec2 strength = sharpen_strengths(taps);
        for (int t = 0; t < 4; ++t) c += a[t] / asum * tap_colour(v, taps.texel[t], strength);
        w = asum / unpenalised;
      }
      sum += w * c;
      n += w;
    }
    if (n > 0.0) return sum / n;
  }
  return vec3(0.0);
}

// ---- lightfield_cpu_renderer_rr.cc ----

// texel_point: the scene point (eye-relative) a texel of v stands for; false for sky.
bool texel_point(CalfView v, ivec3 t, out vec3 q) {
  q = vec3(0.0);
  uint code = depth_code(v, t);
  if (code == CALF_LOG16_SKY) return false;
  vec3 dir = calf_direction_from_st(t.z, (vec2(t.xy) + 0.5) / float(v.face_size));
  q = v.position + dir * calf_depth_from_code(code, log_range(v));
  return true;
}

// tangent: along one texel axis, the central difference where both neighbours continue the
// surface evenly, else the one-sided difference toward the nearer neighbour.
bool tangent(CalfView v, ivec3 t, ivec2 dxy, vec3 centre, out vec3 along) {
  along = vec3(0.0);
  vec3 a, b;
  bool ha = texel_point(v, texel_beyond_face(t.z, t.x + dxy.x, t.y + dxy.y, v.face_size), a);
  bool hb = texel_point(v, texel_beyond_face(t.z, t.x - dxy.x, t.y - dxy.y, v.face_size), b);
  if (!ha && !hb) return false;
  float la = ha ? length(a - centre) : 0.0, lb = hb ? length(b - centre) : 0.0;
  if (ha && hb && la <= 2.0 * lb && lb <= 2.0 * la) {
    along = a - b;
    return true;
  }
  if (ha && (!hb || la <= lb)) {
    along = a - centre;
  } else {
    along = centre - b;
  }
  return true;
}

struct RrRay {
  vec3 o, d;     // origin, unit direction
  float start;   // march start (near for eye rays, z_e for secondary rays)
  uint depth;    // bounces so far
  float weight;  // product of the (signed) weights on the way here
};

// The direction LightfieldCpuRenderer::secondary() gives a ray arriving along unit d_in at a surface with
// unit normal n (either orientation): the reflection, or with `refraction` GLSL refract() with
// eta = 1 / ior where there is no total internal reflection.
vec3 secondary_direction(vec3 d_in, vec3 n, bool refraction, float ior) {
  if (dot(n, d_in) > 0.0) n = -n;  // face the incoming ray
  vec3 dir = normalize(d_in - n * (2.0 * dot(d_in, n)));
  if (refraction) {
    float eta = 1.0 / ior;
    float c = dot(n, d_in);
    float k = 1.0 - eta * eta * (1.0 - c * c);
    if (!(k < 0.0)) dir = normalize(d_in * eta - n * (eta * c + sqrt(k)));
  }
  return dir;
}

// LightfieldCpuRenderer::trace and shade_rr without recursion. A ray's colour is linear in its children's:
//   Alg. 4:       c = w_rfl c_rfl + w_rfr c_rfr + (1 - w_rfl - w_rfr) c_diffuse
//   replacement:  c = c_view + w_rfl (c_rfl - c_rfl,view) + w_rfr (c_rfr - c_rfr,view)
// so each ray adds its own term times the product of the weights above it and pushes its
// secondary rays (with replacement also those along the best view's direction, weighted -w); a
// ray that hits nothing adds the sky. The eye ray is the first ray of the walk, so intersect(),
// shade_surface() and shade_sky() are each instantiated once (see intersect()). Returns the eye
// ray's hit distance.
float trace(vec3 o, vec3 d, out vec3 rgb) {
  RrRay stack[RR_STACK];
  int top = 0;
  stack[top++] = RrRay(o, d, march_near, 0u, 1.0);
  rgb = vec3(0.0);
  float eye_z = INF;
  while (top > 0) {
    RrRay ray = stack[--top];
    float z;
    if (!intersect(ray.o, ray.d, ray.start, z)) {
      rgb += ray.weight * shade_sky(ray.d);
      continue;
    }
    if (ray.depth == 0u) eye_z = z;
    vec3 p = ray.o + ray.d * z;
    int best;
    vec3 own;
    vec3 diffuse = shade_surface(ray.o, p, best, own);
    if (!rr || best < 0 || ray.depth >= rr_max_depth) {
      rgb += ray.weight * diffuse;
      continue;
    }
    // Material and normal from the view that weighs most at p (nearest texel).
    CalfView v = views[best];
    vec3 x = p - v.position;
    int face = face_of(x);
    vec2 uv = texel_coord(x, face, v.face_size);
    ivec3 t = ivec3(clamp_texel(uv.x, v.face_size), clamp_texel(uv.y, v.face_size), face);
    vec3 m = vec3(0.0, 0.0, 1.0);
    if (v.material_layer >= 0) {
      vec3 codes = texelFetch(material_tex, ivec3(t.xy, v.material_layer + t.z), 0).rgb;
      m = vec3(codes.r, codes.g, 1.0 + 2.0 * codes.b);
    }
    vec3 centre, tu, tv;
    if ((!(m.x > 0.0) && !(m.y > 0.0)) || !texel_point(v, t, centre) ||
        !tangent(v, t, ivec2(1, 0), centre, tu) || !tangent(v, t, ivec2(0, 1), centre, tv) ||
        !(length(cross(tu, tv)) > 0.0)) {
      rgb += ray.weight * diffuse;
      continue;
    }
    vec3 n = normalize(cross(tu, tv));
    if (dot(n, ray.d) > 0.0) n = -n;  // face the incoming ray
    vec3 view_dir = normalize(x);
    rgb += ray.weight * (rr_replace_view_reflection ? own : (1.0 - m.x - m.y) * diffuse);
    // Pushed in reverse, so that the walk visits them in the CPU's order: reflection then
    // refraction, each for the eye then for the view.
    for (int kind = 1; kind >= 0; --kind) {
      float w = kind == 0 ? m.x : m.y;
      if (!(w > 0.0)) continue;
      if (rr_replace_view_reflection) {
        stack[top++] = RrRay(p, secondary_direction(view_dir, n, kind == 1, m.z), rr_start,
                             ray.depth + 1u, -ray.weight * w);
      }
      stack[top++] = RrRay(p, secondary_direction(ray.d, n, kind == 1, m.z), rr_start,
                           ray.depth + 1u, ray.weight * w);
    }
  }
  if (rr && rr_replace_view_reflection) rgb = max(rgb, vec3(0.0));  // as LightfieldCpuRenderer::trace
  return eye_z;
}

void main() {
  uint i = uint(gl_FragCoord.x);
  uint j = image_size.y - 1u - uint(gl_FragCoord.y);  // row 0 at the top, like the CPU image
  // LightfieldCpuRenderer::render: supersample^2 rays through an even grid over the pixel, row-major, the
  // colour their mean and the depth the nearest hit; 1 = the ray through the centre. A pass
  // traces some of them and outputs their share of the mean; passes add up (GL_FUNC_ADD on rgb,
  // GL_MIN on the depth).
  float n = float(supersample);
  vec3 sum = vec3(0.0);
  float z = INF;
  for (uint r = ray_first; r < ray_first + ray_count; ++r) {
    uint sx = r % supersample, sy = r / supersample;
    float a = 2.0 * (float(i) + (float(sx) + 0.5) / n) / float(image_size.x) - 1.0;
    float b = 1.0 - 2.0 * (float(j) + (float(sy) + 0.5) / n) / float(image_size.y);
    vec3 d = normalize(cam_forward + a * cam_right + b * cam_up);
    vec3 rgb;
    z = min(z, trace(vec3(0.0), d, rgb));
    sum += rgb;
  }
  // llvmpipe ends every loop of an invocation once all of them together have run 65535
  // iterations, and never resets the count: a loop of a uniform length run last finds whether
  // any loop before was cut short. Such a pixel's distance is -1 (LightfieldGlRenderer::render
  // refuses the image).
  uint canary = 0u;
  for (uint k = 0u; k <= ray_count; ++k) ++canary;
  out_colour = vec4(sum / (n * n), canary == ray_count + 1u ? z : -1.0);
}
)glsl";

}  // namespace calf::player::internal
