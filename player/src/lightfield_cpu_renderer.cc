#include "calf/player/lightfield_cpu_renderer.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <thread>

#include "calf/format/grid.h"
#include "sampling.h"

namespace calf::player {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// LightfieldRenderOptions::blend_views: a view sees the hit when its w_depth is within
// e^-kBlendSeeWindow of the best; a_j below kBlendMinDistance (an eye on the viewpoint) counts
// as that, so 1 / a_j stays finite. The shader uses the same constants.
constexpr double kBlendSeeWindow = 3;
constexpr double kBlendMinDistance = 1e-9;
constexpr uint32_t kMaxBlendViews = 8;

Status option_error(const std::string& what) {
  return Status(ErrorId::kPlayerOptions, what);
}

}  // namespace

Expected<LightfieldRenderOptions> march_range_for(std::span<const MarchView> views, const Vec3& eye,
                                                  LightfieldRenderOptions options) {
  if (views.empty()) return option_error("march range of an empty view set");
  double far = 0, near = kInf;
  for (const MarchView& v : views) {
    far = std::max(far, length(eye - v.position) + v.z_far);
    near = std::min(near, v.z_near / 4);
  }
  options.far = far;
  options.near = std::max(near, far / (1 << 20));
  return options;
}

Expected<LightfieldRenderOptions> march_range_for(const ViewSet& views, const Vec3& eye,
                                                  LightfieldRenderOptions options) {
  std::vector<MarchView> m;
  for (const View& v : views.views)
    m.push_back({v.position(), v.range().z_near(), v.range().z_far()});
  return march_range_for(m, eye, std::move(options));
}

LightfieldCpuRenderer::LightfieldCpuRenderer(const ViewSet& views,
                                             const LightfieldRenderOptions& options)
    : views_(&views), options_(options) {}

Status validate_render_options(const LightfieldRenderOptions& o) {
  if (o.steps < 1 || o.steps > 65536) {
    return option_error("steps " + std::to_string(o.steps) + " is outside [1, 65536]");
  }
  if (!(o.near > 0) || !(o.far > o.near) || !std::isfinite(o.far)) {
    return option_error("march range near " + std::to_string(o.near) + ", far " +
                        std::to_string(o.far) + " is not 0 < near < far < inf");
  }
  if (!(o.depth_footprint >= 0 && o.depth_footprint <= 1)) {
    return option_error("depth_footprint must be in [0, 1]");
  }
  if (!(o.smooth_depth_ratio >= 0) || !std::isfinite(o.smooth_depth_ratio)) {
    return option_error("smooth_depth_ratio must be finite and >= 0");
  }
  if (o.refine_steps > 64) return option_error("refine_steps is above 64");
  if (!(o.depth_decay > 0) || !std::isfinite(o.depth_decay)) {
    return option_error("depth_decay must be finite and > 0");
  }
  if (!(o.cam_decay >= 0) || !std::isfinite(o.cam_decay)) {
    return option_error("cam_decay must be finite and >= 0");
  }
  if (o.surface_hints > 4) return option_error("surface_hints is above 4");
  if (o.surface_hint_vetoes > 65536) return option_error("surface_hint_vetoes is above 65536");
  if (o.surface_hint_substeps < 1 || o.surface_hint_substeps > 64) {
    return option_error("surface_hint_substeps is outside [1, 64]");
  }
  if (!(o.surface_hint_margin_texels >= 0) || !std::isfinite(o.surface_hint_margin_texels)) {
    return option_error("surface_hint_margin_texels must be finite and >= 0");
  }
  if (!(o.colour_depth_tolerance >= 0) || !std::isfinite(o.colour_depth_tolerance)) {
    return option_error("colour_depth_tolerance must be finite and >= 0");
  }
  if (!(o.colour_sharpen >= 0 && o.colour_sharpen <= 1)) {
    return option_error("colour_sharpen must be in [0, 1]");
  }
  if (!(o.colour_sharpen_jump_texels >= 0) || !std::isfinite(o.colour_sharpen_jump_texels)) {
    return option_error("colour_sharpen_jump_texels must be finite and >= 0");
  }
  if (!(o.mixed_texel_penalty >= 0 && o.mixed_texel_penalty <= 50)) {
    return option_error("mixed_texel_penalty must be in [0, 50]");
  }
  if (!(o.mixed_texel_bend_texels >= 0) || !std::isfinite(o.mixed_texel_bend_texels)) {
    return option_error("mixed_texel_bend_texels must be finite and >= 0");
  }
  if (o.blend_views > kMaxBlendViews) return option_error("blend_views is above 8");
  if (o.coverage > 5) return option_error("coverage is not 0, 1, 2, 3, 4 or 5");
  if (!(o.coverage_threshold >= 0 && o.coverage_threshold <= 1)) {
    return option_error("coverage_threshold must be in [0, 1]");
  }
  if (!(o.coverage_cluster >= 0) || !std::isfinite(o.coverage_cluster)) {
    return option_error("coverage_cluster must be finite and >= 0");
  }
  if (o.coverage_agreement < 1 || o.coverage_agreement > 65536) {
    return option_error("coverage_agreement is outside [1, 65536]");
  }
  if (o.surface_hint_coverage > 3) return option_error("surface_hint_coverage is not 0, 1, 2 or 3");
  if (o.coverage_layers > 8) return option_error("coverage_layers is above 8");
  if (o.coverage_alpha > 2) return option_error("coverage_alpha is not 0, 1 or 2");
  if (!std::isfinite(o.min_view_distance)) return option_error("min_view_distance is not finite");
  if (o.threads < 1 || o.threads > 256) return option_error("threads is outside [1, 256]");
  if (o.supersample < 1 || o.supersample > 8) return option_error("supersample is outside [1, 8]");
  if (!(o.rr_start > 0) || !std::isfinite(o.rr_start)) {
    return option_error("rr_start (z_e) must be finite and > 0");
  }
  if (o.rr_max_depth < 1 || o.rr_max_depth > 8) {
    return option_error("rr_max_depth is outside [1, 8]");
  }
  return Status::Ok();
}

Status validate_active_views(std::span<const uint32_t> active_views, size_t view_count) {
  for (uint32_t i : active_views) {
    if (i >= view_count) {
      return option_error("active view " + std::to_string(i) + " is not below the view count " +
                          std::to_string(view_count));
    }
  }
  return Status::Ok();
}

Expected<LightfieldCpuRenderer> LightfieldCpuRenderer::make(const ViewSet& views,
                                                            const LightfieldRenderOptions& o) {
  if (views.views.empty()) return option_error("the view set is empty");
  CALF_RETURN_IF_ERROR(validate_render_options(o));
  LightfieldCpuRenderer r(views, o);
  for (const View& v : views.views) r.active_.push_back(&v);
  r.smooth_log_ratio_ = std::log1p(std::max(o.smooth_depth_ratio, 0.0));
  r.min_view_distance_ = o.min_view_distance < 0 ? o.near : o.min_view_distance;
  r.mixed_penalty_factor_ = std::exp(-o.mixed_texel_penalty);
  return r;
}

namespace {

// How far in front of its surface view v sees the point at offset x from its centre (r = |x|),
// in the view's log-16 code units: > 0 in front (empty for this view), <= 0 at or behind the
// surface; +inf where the view sees sky. The depth compared with is depth_footprint's rule
// (see LightfieldRenderOptions), or the interpolated depth where the taps form one smooth surface.
// Excluded depth codes (LightfieldRenderOptions::coverage_layers): taps with codes in [lo, hi] are
// absent (read as sky). An empty band (lo > hi) excludes nothing.
struct Band {
  double lo = 1, hi = 0;
  uint16_t apply(uint16_t code) const { return code >= lo && code <= hi ? kLog16Sky : code; }
};

double code_margin(const View& v, const Vec3& x, double r, double footprint,
                   double smooth_log_ratio, const Band& band = {}) {
  const internal::BilinearTaps taps =
      internal::bilinear_taps(texel_coord_from_direction(x, v.face_size()), v.face_size());
  uint16_t c[4], lo = kLog16Sky, hi = 0;
  for (int k = 0; k < 4; ++k) {
    c[k] = band.apply(v.depth_code_at(taps.texel[k].face, taps.texel[k].x, taps.texel[k].y));
    lo = std::min(lo, c[k]);
    hi = std::max(hi, c[k]);
  }
  // Compared in code space: code > nonlin(r) * 65534 is exactly decode(code) > r, one log
  // instead of one exp, and needs no special case for r outside [z_near, z_far].
  const double rcode = v.range().normalized_from_depth(r) * kLog16MaxFinite;
  if (hi != kLog16Sky && (hi - lo) * v.range().relative_step() <= smooth_log_ratio) {
    // One smooth surface around the direction: interpolate it (log-depth codes interpolate
    // geometrically), which removes the staircase of per-texel constant depths.
    double code = 0;
    for (int k = 0; k < 4; ++k) code += taps.weight[k] * c[k];
    return code - rcode;
  }
  // A depth discontinuity (or sky): the nearest surface among the texels whose centres lie
  // within depth_footprint of the direction; the nearest texel always counts.
  uint16_t code = kLog16Sky;
  int nearest = 0;
  for (int k = 0; k < 4; ++k) {
    if (taps.weight[k] > taps.weight[nearest]) nearest = k;
    if (taps.offset[k] < footprint - 1e-9) code = std::min(code, c[k]);
  }
  code = std::min(code, c[nearest]);
  return code == kLog16Sky ? kInf : code - rcode;
}

// Coverage (LightfieldRenderOptions::coverage): `margin` is code_margin's answer for the same
// point; where it says the point lies at or behind the footprint's surface, the view's coverage
// decides whether that surface covers the direction at sub-texel precision, and where it does not,
// the answer is measured against the surface behind it instead.
double coverage_margin(const View& v, const Vec3& x, double r, double margin, uint32_t mode,
                       double threshold, double cluster) {
  if (margin > 0 || mode == 0 || !v.has_coverage()) return margin;
  const FaceTexelCoord fc = texel_coord_from_direction(x, v.face_size());
  const internal::BilinearTaps taps = internal::bilinear_taps(fc, v.face_size());
  const double rcode = v.range().normalized_from_depth(r) * kLog16MaxFinite;
  const double front_code = rcode + margin;  // the footprint's surface
  const double cluster_codes = cluster / v.range().relative_step();
  bool front[4], edge = false;
  Coverage cov[4];
  int nearest = 0;
  double back = -1;  // the farthest tap outside the front cluster (kLog16Sky: sky)
  for (int k = 0; k < 4; ++k) {
    const uint16_t c = v.depth_code_at(taps.texel[k].face, taps.texel[k].x, taps.texel[k].y);
    cov[k] = v.coverage_at(taps.texel[k].face, taps.texel[k].x, taps.texel[k].y);
    front[k] = c != kLog16Sky && c - front_code <= cluster_codes;
    if (!front[k]) back = std::max(back, static_cast<double>(c));
    if (cov[k].mask != 0xFFFF || cov[k].near > 0 || cov[k].far > 0 || !front[k]) edge = true;
    if (taps.weight[k] > taps.weight[nearest]) nearest = k;
  }
  if (!edge) return margin;
  bool covered;
  if (mode == 1) {
    double o = 0;
    for (int k = 0; k < 4; ++k) {
      o += taps.weight[k] * (front[k] ? 1.0 - cov[k].far : cov[k].near);
    }
    covered = o >= threshold;
  } else if (mode == 4) {
    // Every tap's cell nearest the direction (the direction's own cell in the texel it falls
    // in), front shares for a tap across a face seam, blended bilinearly against the threshold.
    const double x0 = std::floor(fc.u - 0.5), y0 = std::floor(fc.v - 0.5);
    double o = 0;
    for (int k = 0; k < 4; ++k) {
      const double tx = x0 + (k & 1), ty = y0 + (k >> 1);
      const Texel& t = taps.texel[k];
      double share;
      if (t.face == fc.face && t.x == tx && t.y == ty) {
        const int i = std::clamp(static_cast<int>(std::floor((fc.u - tx) * 4)), 0, 3);
        const int j = std::clamp(static_cast<int>(std::floor((fc.v - ty) * 4)), 0, 3);
        const bool own = (cov[k].mask >> (4 * j + i)) & 1u;
        share = own == front[k] ? 1.0 : 0.0;
      } else {
        share = front[k] ? 1.0 - cov[k].far : cov[k].near;
      }
      o += taps.weight[k] * share;
    }
    covered = o >= threshold;
  } else {
    const auto cell = [](double u) {
      return std::clamp(static_cast<int>(std::floor((u - std::floor(u)) * 4)), 0, 3);
    };
    // The nearest tap is the texel containing the direction; on a face's last row or column
    // bilinear_taps may name it by its clamped coordinates, which the cell ignores.
    const int cx = cell(fc.u), cy = cell(fc.v);
    const uint32_t mask = front[nearest] ? cov[nearest].mask : ~uint32_t{cov[nearest].mask};
    covered = false;
    // Modes 3 and 5 grow the front surface by one cell (a quarter texel) within the texel: one
    // view's empty vote suffices, so each view's errors erode thin parts unless the test leans to
    // occupied, as the footprint rule does by up to 0.9 texels. Mode 5 does not grow a front that
    // a neighbour tap gave into a texel behind it: there the texel's own cells say exactly how
    // far the nearer surface reaches.
    const bool behind = mode == 5 && !front[nearest];
    const int grow = mode == 2 || behind ? 0 : 1;
    for (int j = std::max(cy - grow, 0); j <= std::min(cy + grow, 3); ++j) {
      for (int i = std::max(cx - grow, 0); i <= std::min(cx + grow, 3); ++i) {
        covered = covered || ((mask >> (4 * j + i)) & 1u);
      }
    }
    if (behind) {
      // The texel the direction falls in lies behind the front. Where its cell shows its own
      // surface, that surface is what the view sees along the direction: the farthest tap
      // (another surface, or the sky) would carve it. Where its other cells are only farther
      // surfaces, the front does not reach into it.
      if (!covered) {
        const Texel& t = taps.texel[nearest];
        const uint16_t own = v.depth_code_at(t.face, t.x, t.y);
        return own == kLog16Sky ? kInf : own - rcode;
      }
      if (cov[nearest].near == 0) covered = false;
    }
  }
  if (covered) return margin;
  if (back < 0) return margin;  // no surface behind among the taps: keep the front's answer
  return back == kLog16Sky ? kInf : back - rcode;
}

// The band of v's depth codes around the point q (LightfieldRenderOptions::coverage_layers): within
// a relative depth `cluster` of |q - P_v|.
Band exclusion_band(const View& v, const Vec3& q, double cluster) {
  const double code = v.range().normalized_from_depth(length(q - v.position())) * kLog16MaxFinite;
  const double half = cluster / v.range().relative_step();
  return {code - half, code + half};
}

// The share of direction x (at distance r) that view v's surface at distance r covers, read from
// its coverage masks bilinearly between cell centres (LightfieldRenderOptions::coverage_layers);
// cells of texels nearer than r (the view does not see the point there) do not count, and -1 where
// no cell counts.
double coverage_alpha_of_view(const View& v, const Vec3& x, double r, double cluster) {
  const uint32_t n = v.face_size();
  const FaceTexelCoord fc = texel_coord_from_direction(x, n);
  const double rcode = v.range().normalized_from_depth(r) * kLog16MaxFinite;
  const double half = cluster / v.range().relative_step();
  const double qx = 4 * fc.u - 0.5, qy = 4 * fc.v - 0.5;
  const double fx0 = std::floor(qx), fy0 = std::floor(qy);
  const double wx = qx - fx0, wy = qy - fy0;
  double alpha = 0, wsum = 0;
  for (int k = 0; k < 4; ++k) {
    const int64_t cx = static_cast<int64_t>(fx0) + (k & 1),
                  cy = static_cast<int64_t>(fy0) + (k >> 1);
    const double w = ((k & 1) ? wx : 1 - wx) * ((k >> 1) ? wy : 1 - wy);
    if (w == 0) continue;
    const int64_t tx = cx >= 0 ? cx / 4 : -((-cx + 3) / 4),
                  ty = cy >= 0 ? cy / 4 : -((-cy + 3) / 4);
    const bool inside = tx >= 0 && ty >= 0 && tx < n && ty < n;
    const Texel t = texel_beyond_face(fc.face, tx, ty, n);
    const uint16_t code = v.depth_code_at(t.face, t.x, t.y);
    const Coverage cov = v.coverage_at(t.face, t.x, t.y);
    const bool front = code != kLog16Sky && std::fabs(code - rcode) <= half;
    const bool behind = code == kLog16Sky || code > rcode + half;
    if (!front && !behind) continue;  // a nearer surface hides the point from the view here
    double value;
    if (inside) {
      const int i = static_cast<int>(cx - 4 * tx), j = static_cast<int>(cy - 4 * ty);
      const bool own = (cov.mask >> (4 * j + i)) & 1u;
      const double other = cov.near + cov.far;
      value = front ? (own ? 1.0 : 0.0) : behind && !own && other > 0 ? cov.near / other : 0.0;
    } else {
      value = front ? 1.0 - cov.near - cov.far : behind ? cov.near : 0.0;
    }
    alpha += w * value;
    wsum += w;
  }
  return wsum > 0 ? std::clamp(alpha / wsum, 0.0, 1.0) : -1.0;
}

// Whether view v's coverage says its surface covers the direction of x (at distance r) inside
// the texel the direction falls in (LightfieldRenderOptions::surface_hint_coverage): 1 where the
// 4 x 4 cell mask of that texel shows the texel's own surface at the direction's cell (or at one
// of the cells around it, `grow` = 1), 0 where it does not, -1 where v has nothing to say (no
// coverage; with `at_depth`, a texel not within a relative depth `cluster` of r or sky).
int hint_cell_covered(const View& v, const Vec3& x, double r, int grow, bool at_depth,
                      double cluster) {
  if (!v.has_coverage()) return -1;
  const Texel t = texel_from_direction(x, v.face_size());
  const uint16_t code = v.depth_code_at(t.face, t.x, t.y);
  if (at_depth) {
    if (code == kLog16Sky) return -1;
    const double rcode = v.range().normalized_from_depth(r) * kLog16MaxFinite;
    if (std::fabs(code - rcode) > cluster / v.range().relative_step()) return -1;
  }
  const uint32_t mask = v.coverage_at(t.face, t.x, t.y).mask;
  if (mask == 0xFFFF) return 1;
  const FaceTexelCoord fc = texel_coord_from_direction(x, v.face_size());
  const auto cell = [](double u) {
    return std::clamp(static_cast<int>(std::floor((u - std::floor(u)) * 4)), 0, 3);
  };
  const int cx = cell(fc.u), cy = cell(fc.v);
  for (int j = std::max(cy - grow, 0); j <= std::min(cy + grow, 3); ++j) {
    for (int i = std::max(cx - grow, 0); i <= std::min(cx + grow, 3); ++i) {
      if ((mask >> (4 * j + i)) & 1u) return 1;
    }
  }
  return 0;
}

// |ln(d / r)| for v's depth code `code` (d its decoded depth) at distance r: the relative depth
// disagreement w_depth decays with; +inf for sky. The shader's log_disagreement.
double log_disagreement(const View& v, uint16_t code, double r) {
  return code == kLog16Sky ? kInf : std::fabs(std::log(v.range().decode(code) / r));
}

// `texels` texel angles of v (2 / face size radians each, a texel's width at the face centre) as
// a relative depth, in v's log-16 code units: the scale of the hint margin and the mixed-texel
// bend.
double texel_angles_in_codes(const View& v, double texels) {
  return texels * 2 / v.face_size() / v.range().relative_step();
}

// Whether texel t of v lies on a depth edge of its view (see
// LightfieldRenderOptions::mixed_texel_penalty): one of its four neighbours, across face seams, is
// sky where t is not (or the reverse), or the log depth bends at t by more than `bend_codes` log-16
// codes along either axis (the second difference; LightfieldRenderOptions::mixed_texel_bend_texels
// says what bends how much).
bool mixed_texel(const View& v, const Texel& t, double bend_codes) {
  const uint16_t code = v.depth_code_at(t.face, t.x, t.y);
  constexpr int kDx[4] = {-1, 1, 0, 0}, kDy[4] = {0, 0, -1, 1};
  int bend[2] = {0, 0};  // along x, along y: the neighbours' sum less twice t's code
  for (int k = 0; k < 4; ++k) {
    const Texel u =
        texel_beyond_face(t.face, int64_t{t.x} + kDx[k], int64_t{t.y} + kDy[k], v.face_size());
    const uint16_t other = v.depth_code_at(u.face, u.x, u.y);
    if ((other == kLog16Sky) != (code == kLog16Sky)) return true;
    bend[k / 2] += int{other} - int{code};
  }
  return code != kLog16Sky && (std::abs(bend[0]) > bend_codes || std::abs(bend[1]) > bend_codes);
}

}  // namespace

// The factor a colour tap of v keeps: exp(-mixed_texel_penalty) on a depth edge, else 1.
double LightfieldCpuRenderer::tap_purity(const View& v, const Texel& t) const {
  if (mixed_penalty_factor_ == 1) return 1;
  return mixed_texel(v, t, texel_angles_in_codes(v, options_.mixed_texel_bend_texels))
             ? mixed_penalty_factor_
             : 1;
}

// A bilinear colour tap: the texel's colour, sharpened along each axis with strength[axis]
// (LightfieldRenderOptions::colour_sharpen) where the texel and both its neighbours along the
// axis lie on one surface and none is a mixed texel, whose colour holds the other side's.
void LightfieldCpuRenderer::tap_colour(const View& v, const Texel& t, const double strength[2],
                                       double rgb[3]) const {
  const float* c = v.colour_at(t.face, t.x, t.y);
  for (int ch = 0; ch < 3; ++ch) rgb[ch] = c[ch];
  if (!(strength[0] > 0) && !(strength[1] > 0)) return;
  const double bend_codes = texel_angles_in_codes(v, options_.mixed_texel_bend_texels);
  if (mixed_texel(v, t, bend_codes)) return;
  const double jump_codes = texel_angles_in_codes(v, options_.colour_sharpen_jump_texels);
  const uint16_t code = v.depth_code_at(t.face, t.x, t.y);
  double sum[3] = {0, 0, 0};
  for (int axis = 0; axis < 2; ++axis) {
    if (!(strength[axis] > 0)) continue;
    const float* side[2];
    bool same_surface = true;
    for (int s = 0; s < 2 && same_surface; ++s) {
      const int64_t step = s == 0 ? -1 : 1;
      const Texel u = texel_beyond_face(t.face, int64_t{t.x} + (axis == 0 ? step : 0),
                                        int64_t{t.y} + (axis == 1 ? step : 0), v.face_size());
      const uint16_t other = v.depth_code_at(u.face, u.x, u.y);
      same_surface = (other == kLog16Sky) == (code == kLog16Sky) &&
                     (code == kLog16Sky || std::abs(int{other} - int{code}) <= jump_codes) &&
                     !mixed_texel(v, u, bend_codes);
      side[s] = v.colour_at(u.face, u.x, u.y);
    }
    if (!same_surface) continue;
    for (int ch = 0; ch < 3; ++ch) {
      sum[ch] += strength[axis] * (2.0 * c[ch] - side[0][ch] - side[1][ch]);
    }
  }
  // Within what colour texels can hold (0 to the largest half float), so that a sharpened tap
  // stays finite wherever a renderer stores it.
  for (int ch = 0; ch < 3; ++ch) rgb[ch] = std::clamp(rgb[ch] + sum[ch], 0.0, 65504.0);
}

// BetweenViewpointAndGeometry (footnote 2) over the active views: true as soon as one view that
// is not too near sees p in front of its stored surface (or sees sky there) by more than
// `margin_texels` of its own texels, as relative depth margin_texels x 2 / face size (0 for the
// plain test).
bool LightfieldCpuRenderer::empty_at(const Vec3& p, const Vec3* exclude) const {
  return empty_beyond(p, 0, 0, exclude);
}

bool LightfieldCpuRenderer::empty_beyond(const Vec3& p, double margin_texels,
                                         uint32_t vetoes_ignored, const Vec3* exclude) const {
  bool consulted = false;
  // Votes of views whose footprint test alone sees p as empty, and of those whose coverage does
  // where the footprint test does not: the latter count once coverage_agreement of them agree.
  uint32_t vetoes = 0, coverage_votes = 0;
  for (const View* v : active_) {
    const Vec3 x = p - v->position();
    const double r = length(x);
    if (r <= min_view_distance_) continue;
    consulted = true;
    // Behind an earlier layer the view's texels at that layer's depth are absent, and coverage
    // has no more to say: the layer's own cells were composited already.
    const Band band = exclude ? exclusion_band(*v, *exclude, options_.coverage_cluster) : Band{};
    const double plain = code_margin(*v, x, r, options_.depth_footprint, smooth_log_ratio_, band);
    const double m = exclude
                         ? plain
                         : coverage_margin(*v, x, r, plain, options_.coverage,
                                           options_.coverage_threshold, options_.coverage_cluster);
    const double threshold = texel_angles_in_codes(*v, margin_texels);
    if (!(m > threshold)) continue;
    ++(plain > threshold ? vetoes : coverage_votes);
    const uint32_t counted =
        vetoes + (coverage_votes >= options_.coverage_agreement ? coverage_votes : 0);
    if (counted > vetoes_ignored) return true;
  }
  return !consulted;
}

// RayIntersection: constant steps in the march's normalised log depth from `start` to far.
bool LightfieldCpuRenderer::intersect(const Vec3& o, const Vec3& d, double start, Hit* hit,
                                      const Vec3* exclude) const {
  const double log_ratio = std::log(options_.far / options_.near);
  const auto lin = [&](double x) { return options_.near * std::exp(x * log_ratio); };
  if (options_.tight_march_start) {
    // Nearer than z_near_j to P_j, view j sees every point as empty (or, within
    // min_view_distance, no surface can be there): nothing to find before this.
    for (const View* v : active_) {
      start = std::max(start, static_cast<double>(v->range().z_near()) - length(o - v->position()));
    }
  }
  const double x0 = std::log(std::max(start, options_.near) / options_.near) / log_ratio;
  if (!(x0 < 1)) return false;
  const double step = (1 - x0) / options_.steps;
  // Surface hints: the views nearest the ray origin. Where one of them goes from seeing a sample
  // in front of its surface to seeing the next one behind it, while both samples are empty, the
  // ray crossed that view's surface between them: a surface too thin for the step, or the
  // shadow edge of something in front of it. The crossing, located by bisection on that view
  // alone, is a hit unless more than surface_hint_vetoes views see it in front of their surface
  // by more than the hint margin (the shadow edge of a foreground object is seen through by
  // several views; a thin part carved by one view's texel grid is not).
  constexpr uint32_t kMaxHints = 4;
  const View* hint[kMaxHints] = {};
  const uint32_t hints = std::min<uint32_t>(
      {options_.surface_hints, kMaxHints, static_cast<uint32_t>(active_.size())});
  {
    double dist[kMaxHints];
    for (uint32_t h = 0; h < hints; ++h) dist[h] = kInf;
    for (const View* v : active_) {
      double dv = length(o - v->position());
      const View* cand = v;
      for (uint32_t h = 0; h < hints; ++h) {
        if (dv < dist[h]) {
          std::swap(dv, dist[h]);
          std::swap(cand, hint[h]);
        }
      }
    }
  }
  // -1: the view does not vote here (too near its centre), 0: behind its surface, 1: in front.
  const auto side = [&](const View* v, double x) {
    const Vec3 rel = o + d * lin(x) - v->position();
    const double r = length(rel);
    if (r <= min_view_distance_) return -1;
    // The nearest texel's depth: the view's own best estimate of its surface along the ray
    // (the conservative footprint minimum would put the crossing in front of slanted surfaces,
    // where the other views then rightly see empty space). One fetch, also on the GPU.
    const Texel t = texel_from_direction(rel, v->face_size());
    const Band band = exclude ? exclusion_band(*v, *exclude, options_.coverage_cluster) : Band{};
    const uint16_t code = band.apply(v->depth_code_at(t.face, t.x, t.y));
    if (code == kLog16Sky) return 1;
    return code > v->range().normalized_from_depth(r) * kLog16MaxFinite ? 1 : 0;
  };
  int prev[kMaxHints] = {};
  for (uint32_t i = 0; i <= options_.steps; ++i) {
    const double x = i == options_.steps ? 1.0 : x0 + i * step;
    if (!empty_at(o + d * lin(x), exclude)) {
      double lo = x - step, hi = x;
      if (i == 0) {
        lo = hi;  // already behind a surface at the first sample: nothing to refine
      } else {
        for (uint32_t k = 0; k < options_.refine_steps; ++k) {
          const double mid = 0.5 * (lo + hi);
          (empty_at(o + d * lin(mid), exclude) ? lo : hi) = mid;
        }
      }
      hit->z = lin(0.5 * (lo + hi));
      hit->p = o + d * hit->z;
      hit->hinted = false;
      return true;
    }
    // The hint views are followed at `surface_hint_substeps` points per step (one fetch each),
    // so that a crossing pair (in front, behind) closer than a step is still seen; each hint
    // offers its first crossing of the step.
    double found = kInf;
    const uint32_t sub = options_.surface_hint_substeps;
    const double sub_step = step / sub;
    for (uint32_t h = 0; h < hints; ++h) {
      bool crossed = false;
      for (uint32_t s = i == 0 ? sub : 1; s <= sub; ++s) {
        const double xs = s == sub ? x : x - step + s * sub_step;
        const int now = side(hint[h], xs);
        if (i > 0 && !crossed && prev[h] == 1 && now == 0) {
          crossed = true;
          double lo = xs - sub_step, hi = xs;
          for (uint32_t k = 0; k < options_.refine_steps; ++k) {
            const double mid = 0.5 * (lo + hi);
            (side(hint[h], mid) == 1 ? lo : hi) = mid;
          }
          const double xc = 0.5 * (lo + hi);
          if (xc < found && hint_confirmed(o, d, lin(hi), lin(xc), hint[h]) &&
              !empty_beyond(o + d * lin(xc), options_.surface_hint_margin_texels,
                            options_.surface_hint_vetoes, exclude)) {
            found = xc;
          }
        }
        prev[h] = now;
      }
    }
    if (found < kInf) {
      hit->z = lin(found);
      hit->p = o + d * hit->z;
      hit->hinted = true;
      return true;
    }
  }
  return false;
}

// LightfieldRenderOptions::surface_hint_coverage: whether the coverage of the hint view h confirms
// its crossing of the ray (o, d) at distance zc, found between zc and the first point zb behind
// h's surface.
bool LightfieldCpuRenderer::hint_confirmed(const Vec3& o, const Vec3& d, double zb, double zc,
                                           const View* h) const {
  const uint32_t mode = options_.surface_hint_coverage;
  if (mode == 0) return true;
  // The texel whose surface the ray went behind, at the direction of the point behind it.
  const Vec3 xb = o + d * zb - h->position();
  const int own = hint_cell_covered(*h, xb, length(xb), mode == 2 ? 1 : 0, false, 0);
  if (own != 0) return true;
  if (mode != 3) return false;
  // Mode 3: another view whose nearest texel lies at the crossing's depth and covers its
  // direction there.
  const Vec3 p = o + d * zc;
  for (const View* v : active_) {
    if (v == h) continue;
    const Vec3 x = p - v->position();
    const double r = length(x);
    if (r <= min_view_distance_) continue;
    if (hint_cell_covered(*v, x, r, 0, true, options_.coverage_cluster) == 1) return true;
  }
  return false;
}

// LightfieldRenderOptions::blend_views: the (K + 1)-th smallest a_j of the views that see p, the
// threshold t of the Unstructured Lumigraph's weights; +inf where at most K views see p or K + 1
// of them are as near as the nearest.
double LightfieldCpuRenderer::blend_threshold(const Vec3& o, const Vec3& p,
                                              double hit_distance) const {
  // The views that see p: their nearest texel's disagreement within kBlendSeeWindow / depth_decay
  // of the smallest (w_depth within e^-kBlendSeeWindow of the best).
  const auto disagreement = [&](const View& v) {
    const Vec3 x = p - v.position();
    const double r = length(x);
    if (r <= min_view_distance_) return kInf;
    const Texel t = texel_from_direction(x, v.face_size());
    const uint16_t code = v.depth_code_at(t.face, t.x, t.y);
    return log_disagreement(v, code, r);
  };
  double dmin = kInf;
  for (const View* v : active_) dmin = std::min(dmin, disagreement(*v));
  if (dmin == kInf) return kInf;
  const double limit = dmin + kBlendSeeWindow / options_.depth_decay;
  // The K + 1 smallest a_j of those views, ascending.
  const uint32_t keep = options_.blend_views + 1;
  double smallest[kMaxBlendViews + 1];
  uint32_t n = 0;
  for (const View* v : active_) {
    if (!(disagreement(*v) <= limit)) continue;
    double a = length(o - v->position()) / hit_distance;
    for (uint32_t i = 0; i < n; ++i) {
      if (a < smallest[i]) std::swap(a, smallest[i]);
    }
    if (n < keep) smallest[n++] = a;
  }
  if (n < keep) return kInf;
  // K + 1 views as near as the nearest (ties): no view would keep a weight.
  return smallest[keep - 1] > smallest[0] ? smallest[keep - 1] : kInf;
}

// SampleColor over the active views and their blend (CalculateColor). Weights are kept as
// logarithms and normalised by the largest, so no view's weight underflows to zero.
void LightfieldCpuRenderer::shade_surface(const Vec3& o, const Vec3& p, double* rgb, int* best_view,
                                          double* best_rgb, double* alpha) const {
  const double hit_distance = std::max(length(p - o), 1e-12);
  const double blend_t = options_.blend_views > 0 ? blend_threshold(o, p, hit_distance) : kInf;
  double sum[3] = {0, 0, 0}, wsum = 0, best = -kInf;
  struct Contribution {
    double log_w, c[3], alpha;
  };
  double min_alpha = 1, max_alpha = -1;
  // Views are few (the paper uses up to 16); a small fixed buffer would do, a vector is clearer.
  std::vector<Contribution> contributions;
  contributions.reserve(active_.size());
  *best_view = -1;
  for (size_t vi = 0; vi < active_.size(); ++vi) {
    const View& v = *active_[vi];
    const Vec3 x = p - v.position();
    const double r = length(x);
    if (r <= min_view_distance_) continue;
    const FaceTexelCoord c = texel_coord_from_direction(x, v.face_size());
    const Texel nearest = texel_from_direction(x, v.face_size());
    const uint16_t ncode = v.depth_code_at(nearest.face, nearest.x, nearest.y);
    const double view_alpha = alpha && v.has_coverage()
                                  ? coverage_alpha_of_view(v, x, r, options_.coverage_cluster)
                                  : 1.0;
    if (view_alpha >= 0) {
      min_alpha = std::min(min_alpha, view_alpha);
      max_alpha = std::max(max_alpha, view_alpha);
    }
    if (ncode == kLog16Sky) continue;  // this view sees past p: it has no colour for it
    const double ndiff = log_disagreement(v, ncode, r);
    Contribution k{-options_.depth_decay * ndiff, {0, 0, 0}, view_alpha};
    if (!options_.bilinear_colour) {
      const float* col = v.colour_at(nearest.face, nearest.x, nearest.y);
      for (int ch = 0; ch < 3; ++ch) k.c[ch] = col[ch];
    } else {
      const internal::BilinearTaps taps = internal::bilinear_taps(c, v.face_size());
      double diff[4], dmin = kInf;
      for (int t = 0; t < 4; ++t) {
        const uint16_t code = v.depth_code_at(taps.texel[t].face, taps.texel[t].x, taps.texel[t].y);
        diff[t] = log_disagreement(v, code, r);
        if (taps.weight[t] > 0) dmin = std::min(dmin, diff[t]);
      }
      double a[4], asum = 0;
      for (int t = 0; t < 4; ++t) {
        a[t] = taps.weight[t] > 0 ? taps.weight[t] * tap_purity(v, taps.texel[t]) : 0.0;
        if (options_.depth_aware_colour) {
          a[t] *= diff[t] == kInf
                      ? 0.0
                      : std::exp(-options_.depth_decay *
                                 std::max(0.0, diff[t] - dmin - options_.colour_depth_tolerance));
        }
        asum += a[t];
      }
      double strength[2];
      internal::sharpen_strengths(taps, options_.colour_sharpen, strength);
      for (int t = 0; t < 4; ++t) {
        double col[3];
        tap_colour(v, taps.texel[t], strength, col);
        for (int ch = 0; ch < 3; ++ch) k.c[ch] += a[t] / asum * col[ch];
      }
      // Depth-aware: the view's w_depth is the bilinear blend of its taps' agreements.
      if (options_.depth_aware_colour) k.log_w = -options_.depth_decay * dmin + std::log(asum);
    }
    const double a = length(o - v.position()) / hit_distance;
    if (options_.blend_views == 0) {
      k.log_w -= options_.cam_decay * a;
    } else {
      // The Unstructured Lumigraph's weight; t = +inf gives 1 / a.
      const double w = std::max(0.0, 1 - a / blend_t) / std::max(a, kBlendMinDistance);
      if (!(w > 0)) continue;
      k.log_w += std::log(w);
    }
    if (k.log_w > best) {
      best = k.log_w;
      *best_view = static_cast<int>(vi);
      if (best_rgb) std::copy(k.c, k.c + 3, best_rgb);
    }
    contributions.push_back(k);
  }
  double asum = 0, awsum = 0;
  for (const Contribution& k : contributions) {
    const double w = std::exp(k.log_w - best);
    for (int ch = 0; ch < 3; ++ch) sum[ch] += w * k.c[ch];
    wsum += w;
    if (k.alpha >= 0) asum += w * k.alpha, awsum += w;
  }
  for (int ch = 0; ch < 3; ++ch) rgb[ch] = wsum > 0 ? sum[ch] / wsum : 0.0;
  if (alpha) {
    *alpha = options_.coverage_alpha == 0   ? min_alpha
             : options_.coverage_alpha == 2 ? (max_alpha >= 0 ? max_alpha : 1.0)
             : awsum > 0                    ? asum / awsum
                                            : 1.0;
  }
}

// Sky has no parallax: every view sees it in the ray's own direction. Views whose depth there is
// sky count (if none is, the march ended before far geometry, all views do), each with the share
// of its taps' bilinear weight that mixed texels leave (1 where none is mixed).
void LightfieldCpuRenderer::shade_sky(const Vec3& /*origin*/, const Vec3& d, double* rgb) const {
  for (int pass = 0; pass < 2; ++pass) {
    double sum[3] = {0, 0, 0};
    double n = 0;
    for (const View* v : active_) {
      const Texel nearest = texel_from_direction(d, v->face_size());
      const bool sky = v->depth_code_at(nearest.face, nearest.x, nearest.y) == kLog16Sky;
      if (pass == 0 && !sky) continue;
      double c[3] = {0, 0, 0};
      double w = 1;  // the view's weight
      if (!options_.bilinear_colour) {
        const float* col = v->colour_at(nearest.face, nearest.x, nearest.y);
        for (int ch = 0; ch < 3; ++ch) c[ch] = col[ch];
      } else {
        const internal::BilinearTaps taps =
            internal::bilinear_taps(texel_coord_from_direction(d, v->face_size()), v->face_size());
        double a[4], asum = 0, unpenalised = 0;
        for (int t = 0; t < 4; ++t) {
          const bool tap_sky =
              v->depth_code_at(taps.texel[t].face, taps.texel[t].x, taps.texel[t].y) == kLog16Sky;
          a[t] = taps.weight[t] * (pass == 0 && options_.depth_aware_colour && !tap_sky ? 0 : 1);
          unpenalised += a[t];
          if (a[t] > 0) a[t] *= tap_purity(*v, taps.texel[t]);
          asum += a[t];
        }
        double strength[2];
        internal::sharpen_strengths(taps, options_.colour_sharpen, strength);
        for (int t = 0; t < 4; ++t) {
          double col[3];
          tap_colour(*v, taps.texel[t], strength, col);
          for (int ch = 0; ch < 3; ++ch) c[ch] += a[t] / asum * col[ch];
        }
        w = asum / unpenalised;
      }
      for (int ch = 0; ch < 3; ++ch) sum[ch] += w * c[ch];
      n += w;
    }
    if (n > 0) {
      for (int ch = 0; ch < 3; ++ch) rgb[ch] = sum[ch] / n;
      return;
    }
  }
}

RaySample LightfieldCpuRenderer::trace(const Vec3& origin, const Vec3& direction) const {
  if (options_.coverage_layers > 0 && !options_.rr) return trace_layers(origin, direction);
  Hit hit;
  return shade_hit(origin, direction,
                   intersect(origin, direction, options_.near, &hit) ? &hit : nullptr);
}

// LightfieldRenderOptions::coverage_layers: partly covered surfaces laid front to back over what
// the ray meets behind them.
RaySample LightfieldCpuRenderer::trace_layers(const Vec3& o, const Vec3& d) const {
  RaySample s;
  s.depth = kInf;
  double transmit = 1;
  double start = options_.near;
  Hit hit, previous;
  for (uint32_t layer = 0;; ++layer) {
    const bool found = intersect(o, d, start, &hit, layer > 0 ? &previous.p : nullptr);
    double rgb[3] = {0, 0, 0}, alpha = 1;
    if (found) {
      int best;
      shade_surface(
          o, hit.p, rgb, &best, nullptr,
          layer < options_.coverage_layers && (hit.hinted || !options_.coverage_layers_hints_only)
              ? &alpha
              : nullptr);
      if (alpha > 1 - 1e-6) alpha = 1;
    } else {
      shade_sky(o, d, rgb);
    }
    for (int ch = 0; ch < 3; ++ch) s.rgb[ch] += transmit * alpha * rgb[ch];
    // The pixel's depth: the layer that brings the accumulated opacity to 1/2.
    if (transmit > 0.5 && transmit * (1 - alpha) <= 0.5) {
      s.hit = found;
      s.depth = found ? hit.z : kInf;
    }
    transmit *= 1 - alpha;
    if (!found || alpha == 1) break;
    previous = hit;
    start = std::nextafter(hit.z, kInf);
  }
  return s;
}

RaySample LightfieldCpuRenderer::shade_at(const Vec3& origin, const Vec3& direction,
                                          double depth) const {
  if (!std::isfinite(depth)) return shade_hit(origin, direction, nullptr);
  const Hit hit{origin + direction * depth, depth};
  return shade_hit(origin, direction, &hit);
}

// The colour and depth of a ray whose march ended at `hit` (nullptr: no surface).
RaySample LightfieldCpuRenderer::shade_hit(const Vec3& origin, const Vec3& direction,
                                           const Hit* hit) const {
  RaySample s;
  if (!hit) {
    shade_sky(origin, direction, s.rgb);
    s.depth = kInf;
    return s;
  }
  s.hit = true;
  s.depth = hit->z;
  if (options_.rr) {
    shade_rr(origin, direction, *hit, 0, s.rgb);
    // With replacement a ray's colour is c_view + sum of w (c_eye - c_view): negative where a
    // view saw a brighter reflection than the eye does. Intermediate bounces stay linear (the
    // GL renderer sums the ray tree in any order); the pixel is clamped.
    if (options_.rr_replace_view_reflection) {
      for (double& c : s.rgb) c = std::max(c, 0.0);
    }
  } else {
    int best;
    shade_surface(origin, hit->p, s.rgb, &best);
  }
  return s;
}

Expected<LightfieldCpuRenderer> LightfieldCpuRenderer::restricted_to(
    std::span<const uint32_t> active_views) const {
  if (active_views.empty()) return *this;
  CALF_RETURN_IF_ERROR(validate_active_views(active_views, views_->views.size()));
  LightfieldCpuRenderer r = *this;
  r.active_.clear();
  for (uint32_t i : active_views) r.active_.push_back(&views_->views[i]);
  return r;
}

Status LightfieldCpuRenderer::render(const Camera& camera, std::span<const uint32_t> active_views,
                                     RenderedImage* out) const {
  if (!active_views.empty()) {
    CALF_ASSIGN_OR_RETURN(const LightfieldCpuRenderer restricted, restricted_to(active_views));
    return restricted.render(camera, {}, out);
  }
  CALF_RETURN_IF_ERROR(validate_camera(camera));
  const CameraFrame frame = camera_frame(camera);
  out->width = camera.width;
  out->height = camera.height;
  const size_t pixels = size_t{camera.width} * camera.height;
  out->color.assign(3 * pixels, 0.0f);
  out->depth.assign(pixels, 0.0f);
  // Rows are interleaved over the workers; each pixel depends only on its own ray, so the image
  // does not depend on the thread count.
  const auto work = [&](uint32_t first) {
    for (uint32_t j = first; j < camera.height; j += options_.threads) {
      for (uint32_t i = 0; i < camera.width; ++i) {
        // Sub-pixel rays in row-major order, summed as the GL renderer sums them; with n = 1
        // the one ray through the centre, camera_ray's own (so the supersampling test has a
        // reference that does not share the sub-pixel formula).
        const uint32_t n = options_.supersample;
        double rgb[3] = {0, 0, 0};
        double depth = kInf;
        for (uint32_t sy = 0; sy < n; ++sy) {
          for (uint32_t sx = 0; sx < n; ++sx) {
            const Vec3 d =
                n == 1 ? camera_ray(camera, frame, i, j)
                       : camera_ray_at(camera, frame, i + (sx + 0.5) / n, j + (sy + 0.5) / n);
            const RaySample s = trace(camera.position, d);
            for (int ch = 0; ch < 3; ++ch) rgb[ch] += s.rgb[ch];
            depth = std::min(depth, s.depth);
          }
        }
        const size_t k = size_t{j} * camera.width + i;
        for (int ch = 0; ch < 3; ++ch) {
          out->color[3 * k + ch] = static_cast<float>(rgb[ch] / (static_cast<double>(n) * n));
        }
        out->depth[k] = static_cast<float>(depth);
      }
    }
  };
  const uint32_t workers = std::min(options_.threads, camera.height);
  std::vector<std::thread> pool;
  for (uint32_t t = 1; t < workers; ++t) pool.emplace_back(work, t);
  work(0);
  for (std::thread& t : pool) t.join();
  return Status::Ok();
}

}  // namespace calf::player
