// The scalar CPU reference renderer of paper 002 Alg. 4: ray-march each eye ray through the
// viewpoints' depth cube maps, then blend their colours. The GL renderer is tested against it.
// docs/RENDERING.md describes the algorithm as implemented and every choice made where the paper
// is vague; the summary:
//
// Intersection (Alg. 4 RayIntersection). Samples are taken at N_step + 1 constant steps of the
// normalised log depth x = ln(z / near) / ln(far / near) (the paper's nonlin(), eq. 13) between
// the march's near and far, z the radial distance from the ray origin. A sample p is in empty
// space when at least one active view j sees it as such (footnote 2, BetweenViewpointAndGeometry):
// the depth stored in view j's cube map in direction p - P_j (nearest texel) is farther than
// |p - P_j|; sky texels are always farther. Views with |p - P_j| <= min_view_distance are ignored
// for that sample (Alg. 4 line 21). The first sample that is not empty is a hit, provided at least
// one view was consulted (the literal algorithm would call a sample that every view ignored a hit;
// calf treats it as empty). The hit is refined by `refine_steps` bisections between the last
// empty sample and the hit sample, in the same log-depth space, and placed at the middle of the
// final interval. No hit up to far: the ray sees the sky. Two additions (docs/RENDERING.md,
// "Quality"): the march starts at max_j (z_near_j - |o - P_j|), before which every point is empty
// (`tight_march_start`), and the view nearest the ray origin acts as a surface hint: where it sees
// one point in front of its surface and the next behind it (tested at `surface_hint_substeps`
// points per step), the crossing of its surface is a hit unless more than `surface_hint_vetoes`
// views see it as empty beyond a small margin, which finds parts thinner than a step
// (`surface_hints`, default 1).
//
// Colour (Alg. 4 SampleColor / CalculateColor). At the hit p each active view j contributes its
// colour c_j in direction p - P_j with weight w_j = w_depth * w_cam:
//   w_depth = exp(-depth_decay * |ln(d_j / |p - P_j|)|)   d_j the view's stored depth there
//   w_cam   = exp(-cam_decay * |o - P_j| / |p - o|)         o the ray origin
// so a view that sees p itself (d_j = |p - P_j|) dominates one whose surface there is elsewhere,
// and among those the viewpoint nearest the eye (in units of the hit distance, about the parallax
// angle in radians) wins. |ln(d_j / r)| is the paper's |nonlin(d_tex) - nonlin(r)| times each
// view's ln(z_far / z_near), so views with different depth ranges are weighed on one scale.
// Colour texels are sampled bilinearly (optionally depth-aware: each of the four taps is weighted
// by its own depth agreement beyond `colour_depth_tolerance`, so silhouettes do not bleed
// foreground into background); taps that fall off a face are fetched from the neighbouring face
// through the cube conventions. Taps on a depth edge of their view ("mixed" texels: an
// anti-aliased capture gives them the mean colour of both sides) keep only
// exp(-mixed_texel_penalty) of their weight, so colour comes from texels wholly on one surface.
// Sky: the colour of the views whose depth is sky in the ray direction (sky is at infinity, so
// every viewpoint sees it in the same direction), bilinear over sky taps, mixed taps weighed down
// as above (a view's weight is the share of its sky taps' bilinear weight that is left).
//
// RR variant (Alg. 4 *_RR, Sec. 6.1), when `rr` is set and views carry material: at a hit the
// material (reflect, refract, IOR) is the best-weighted view's nearest texel, the normal comes
// from the depths around that texel, and one reflection and one refraction ray are marched from p
// (starting `rr_start` = z_e from it) and shaded recursively up to `rr_max_depth` bounces:
// c = w_rfl c_rfl + w_rfr c_rfr + (1 - w_rfl - w_rfr) c_diffuse; a secondary ray that hits
// nothing takes the sky colour in its direction. With `rr_replace_view_reflection` (default) the
// captured colour, which already holds the capturing view's own reflection, keeps its diffuse
// part and only the reflection / refraction is swapped for the eye's (see the option).
//
// Deterministic: every pixel is computed independently in double precision; the image is the same
// bit for bit whatever the thread count.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "calf/format/camera.h"
#include "calf/format/geometry.h"
#include "calf/format/status.h"
#include "calf/player/rendered_image.h"
#include "calf/player/view_set.h"

namespace calf::player {

// Every knob of the renderer. Defaults follow the paper where it gives one.
struct LightfieldRenderOptions {
  // N_step: constant steps in normalised log depth between near and far (1..65536). The paper
  // leaves it open; 64 is what DESIGN.md's timings assume.
  uint32_t steps = 64;
  // The march range along each ray: radial distances from the ray origin, 0 < near < far,
  // finite (Alg. 4 z_near / z_far). march_range_for() suggests one from the views.
  double near = 0.01, far = 1000;
  // How a view's depth map answers "is this point in front of your surface?" (footnote 2).
  // Where the four texels around the direction hold one smooth surface (their depths within a
  // factor 1 + smooth_depth_ratio of each other) the depth is interpolated bilinearly (in log
  // space): no staircase of per-texel constant depths on slanted surfaces. 0 never interpolates.
  double smooth_depth_ratio = 0;
  // Across a depth discontinuity (or next to sky) interpolating would invent surfaces between
  // foreground and background, so the point must instead be nearer than every texel whose centre
  // lies within this many texels (per axis) of its direction; the nearest texel always counts.
  // 0.5 is the paper's nearest texel: each view's silhouettes are then off by up to half a texel
  // either way, and since a point is empty when any view says so, the eroding errors of all
  // views add up and objects shrink. 1 takes all four bilinear taps (textureGather on the GPU):
  // no view carves into an object, which instead grows by up to a texel. In [0, 1];
  // docs/RENDERING.md has measurements.
  double depth_footprint = 0.9;
  // Bisection steps refining a hit between the last empty and the first hit sample (0..64).
  // Each halves the depth uncertainty in log space: 8 turns a 20 % step into 0.08 %.
  uint32_t refine_steps = 8;
  // Views nearer than this to a sample do not vote on it (Alg. 4 line 21, which reuses z_near):
  // the direction from a viewpoint to a point at its very centre is meaningless. >= 0.
  // Negative: use `near`.
  double min_view_distance = -1;
  // w_depth decay per unit of |ln(d_j / r)| (a relative depth disagreement): 500 gives a view
  // whose surface is 0.2 % off weight e^-1 relative to one that matches, so a view that sees the
  // other side of a thin part (a wing 1 % of the distance thick) hardly counts. > 0. Decays
  // faster than w_cam, as the paper asks. (Was 50: +2.2 dB between viewpoints on turntable,
  // docs/RENDERING.md "Quality".)
  double depth_decay = 500;
  // w_cam decay per unit of |o - P_j| / |p - o| (the eye-to-viewpoint distance in units of the hit
  // distance). >= 0; 0 weighs all agreeing views equally.
  double cam_decay = 20;
  // 0: w_cam as above. K in 1..8: instead, the weights of the Unstructured Lumigraph (Buehler,
  // Bosse, McMillan, Gortler, Cohen 2001) over a_j = |o - P_j| / |p - o|, which blend the K
  // views nearest the eye among those that see p and give a view the eye stands on all the
  // weight: w_cam = max(0, 1 - a_j / t) / a_j, t the (K + 1)-th smallest a_j of the views that
  // see p (+inf where there are at most K, or K + 1 as near as the nearest). A view sees p when its
  // nearest texel's relative depth disagreement |ln(d_j / r)| is within 3 / depth_decay of the
  // smallest (its w_depth within e^-3 of the best). w_depth multiplies as before. Unlike w_cam it
  // has no scale to tune: the blend is as broad as the nearest views are alike, so it keeps an eye
  // near one view of a dense rig on that view and blends the two nearest of a sparse ring
  // (docs/SILHOUETTES.md "The march's quality knobs").
  uint32_t blend_views = 0;
  // Bilinear colour within and across faces (true), or the nearest texel (false).
  bool bilinear_colour = true;
  // With bilinear colour: weigh each tap by its own depth agreement (true) or plain bilinear.
  bool depth_aware_colour = true;
  // Depth-aware colour: taps whose relative depth disagreement |ln(d_t / r)| exceeds the best
  // tap's by at most this much count as the same surface and keep their bilinear weight; only
  // the excess is penalised (depth_decay per unit). 0 penalises every difference, which on
  // slanted surfaces (neighbouring texels at different depths) skews bilinear weights towards the
  // nearest texel and shifts colour edges. >= 0.
  double colour_depth_tolerance = 0.1;
  // Sharpened colour taps. A capture texel already holds its footprint's mean colour, and a
  // bilinear tap between texel centres blurs it once more: at fraction a along an axis it keeps
  // |1 - a + a e^(-2 pi i f)| of frequency f (cycles per texel), cos(pi f) halfway. So each of
  // the four taps of a bilinear lookup (surface and sky) reads its texel's colour c plus, per
  // axis, k 4 a (1 - a) (2c - p - q), p and q its neighbours along the axis (across face seams);
  // the sum is clamped to what texels hold, [0, 65504]. At a texel centre (a = 0: an eye at a
  // viewpoint, pixel on texel) nothing changes; halfway k = 1/8 gives the weights of Catmull-Rom's
  // cubic (-1/16, 9/16, 9/16, -1/16). An axis counts only where the texel and both neighbours lie
  // on one surface (both sky, or log depths within colour_sharpen_jump_texels texel angles, 2 /
  // face size radians each: a plane seen at incidence i steps by tan(i) of them per texel) and none
  // of the three is a mixed texel (mixed_texel_bend_texels), whose colour holds the other side's: a
  // depth edge is never sharpened across. colour_sharpen is k, in [0, 1], 0 = off (the default:
  // it costs 1.4x the GL render time on llvmpipe at one ray per pixel); 0.2 is the measured best.
  // The jump is finite and >= 0. What they cost and buy: docs/RENDERING.md "Sharpened colour".
  double colour_sharpen = 0;
  double colour_sharpen_jump_texels = 8;
  // Mixed texels. An anti-aliased capture (calf-capture's default, any offline renderer's) gives
  // a texel on a depth edge the mean colour of the surfaces on both sides, while its depth (the
  // centre ray's) names one of them: re-projected, it paints background colour into a surface
  // (grey specks along a model's thin legs, where most texels are edge texels) and foreground
  // colour into the background beside it. A colour tap is mixed when one of its four neighbours
  // in its view (across face seams) is sky where it is not (or the reverse), or its log depth
  // bends there along either axis by more than `mixed_texel_bend_texels` texel angles (2 / face
  // size radians, as for the hint margin): |ln z(x-1) + ln z(x+1) - 2 ln z(x)| > bend x 2 / n.
  // A step or a part one texel thin bends by its own depth ratio; a slanted plane's steady slope
  // bends by about (2 / n)^2 / cos^2(incidence), and a crease between planes at incidences a
  // and b by (2 / n)(tan a + tan b), so in texel angles neither depends on the face size, and
  // the default 5 counts a plane as mixed only beyond 88° at 512² faces (83° at 24²), a crease
  // only where its walls are seen at 68° or more. With bilinear colour a mixed tap keeps
  // exp(-mixed_texel_penalty) of its weight, in surface and sky lookups: colour comes from the
  // texels wholly on one surface, in the same view or, since a depth-aware view's w_depth is the
  // sum of its taps' weights, in another view, where there are any; where every texel is mixed
  // (a part a texel thin in every view) nothing changes. 0 = off. Defaults from a sweep on six
  // captures (docs/RENDERING.md "Fourth round"). The penalty is in [0, 50] (e^-50 already drops
  // a mixed tap wherever an unmixed one is near; a larger one would underflow the GPU's float
  // weights), the bend >= 0 and finite.
  double mixed_texel_penalty = 3;
  double mixed_texel_bend_texels = 5;
  // Coverage (views that carry it, format/CAPTURE.md "Coverage"): where a point lies at or behind
  // the surface a view's footprint test names, the view asks whether that front surface covers
  // the point's direction at sub-texel precision; where it does not, the point is compared with
  // the surface behind (the farthest of the bilinear taps outside the front cluster). 0: off;
  // 1: the bilinear blend of the taps' front shares (1 - far for a front tap, near for a tap
  // behind) against `coverage_threshold`; 2: the nearest texel's 4 x 4 cell mask; 3: that mask
  // grown by one cell; 4: each bilinear tap's cell nearest the direction (the direction's own
  // cell in the texel it falls in; a tap across a face seam gives its front share), their
  // covered bits blended bilinearly against `coverage_threshold`; 5: mode 3, except where the
  // nearest texel itself lies behind the front cluster (the front came from a neighbour tap
  // within the footprint): there its own cell decides, not grown: where it shows the texel's own
  // surface the point is compared with that surface, where it shows another one the front
  // covers it if the texel has a nearer share, else the point is compared with the surface
  // behind. The front cluster: taps within a relative depth `coverage_cluster` of the
  // footprint's surface. Off by default: it lifts the spider's silhouettes but carves thin parts
  // of turntable at 128² faces unless coverage_agreement asks for 2 or 3 views, which in turn
  // gives back part of the spider's gain (docs/RENDERING.md "Coverage").
  uint32_t coverage = 0;
  double coverage_threshold = 0.5;
  double coverage_cluster = 0.05;
  // Emptiness by agreement: a point that a view calls empty only through its coverage (its
  // footprint test puts the point at or behind a surface) is empty once at least this many views
  // say so (1..65536; votes of the footprint test alone count as before). One view's cells
  // straddle a part thinner than a texel as easily as its texels do; the views that see the part
  // as covered keep it. 1: every coverage vote counts.
  uint32_t coverage_agreement = 1;
  // Compositing partly covered surfaces (the CPU reference only: the GL renderer refuses it;
  // plain variant, not RR): 0 off, else at most this many partly covered layers per ray (1..8),
  // the next one opaque. Where the march ends on a surface point p, each view with coverage gives
  // the share alpha_j of p's direction that its front surface covers: its 4 x 4 cell masks read
  // bilinearly between cell centres at p's sub-texel position (a cell of a texel at p's depth,
  // within coverage_cluster, counts 1 where the mask shows its own surface; a cell of a texel
  // behind p or of sky counts its texel's near share of the cells its mask leaves; cells of
  // texels nearer than p, which hide it, do not count; across a face seam a texel counts its
  // front share). alpha is `coverage_alpha` over the views: 0 their minimum, 1 their mean
  // weighted as their colours are, 2 their maximum. Where alpha < 1 the surface's colour is laid
  // over what the ray meets behind it, front to back: the march goes on from p with each view's
  // texels at p's depth (within coverage_cluster) taken as absent. The pixel's depth is the
  // layer's at which the accumulated opacity reaches 1/2 (sky if none). Off by default: it lifts
  // the spider but loses on CesiumMilkTruck, turntable and interior (docs/RENDERING.md
  // "Coverage").
  uint32_t coverage_layers = 0;
  uint32_t coverage_alpha = 0;
  // Composite only the hits that surface hints found (a crossing of a hint view's surface that
  // the other views did not refute), the march's own hits being opaque.
  bool coverage_layers_hints_only = false;
  // Start each march where the first surface can be: no point nearer to view j's centre than
  // z_near_j can be behind its surface, so the march starts at max_j (z_near_j - |o - P_j|)
  // (over the active views, at least the ray's own start) and spends its steps beyond.
  bool tight_march_start = true;
  // Surface hints (0..4): the march also follows this many views nearest the ray origin (the
  // "hint" views; ties by index). For a hint view, a sample is in front of its surface when its
  // nearest texel's depth in direction p - P_h is farther than |p - P_h| (or sky); a view within
  // min_view_distance of p abstains. Where a hint view sees one point in front of its surface
  // and the next behind it (points: `surface_hint_substeps` per step, after an empty sample),
  // the ray crossed the hint's surface in between: the crossing is located by `refine_steps`
  // bisections on that view alone (within that substep) and placed
  // at the middle of the final interval, and it is the hit unless more than
  // `surface_hint_vetoes` active views see it as empty by more than
  // `surface_hint_margin_texels` of their own texels: the relative depth margin x 2 / face size
  // (a texel's angular width at the face centre), in code units that / relative_step of the
  // view. A fixed relative depth (0.5 %) would be 2.56 texels of a 1024² face: near a
  // silhouette the hint view's shadow edge of the object would lie that close to the object's
  // surface in the other views, so no view would veto it and silhouettes would grow by a pixel.
  // Of several hints crossing in one interval the nearest confirmed crossing wins. This finds
  // parts thinner than a step (wings, chains, leaves) that the plain march steps over, and at a
  // viewpoint puts the hit exactly on that view's surface. 0: the paper's march alone.
  // Default 1, the tuned value (docs/RENDERING.md "Quality": +7 dB at turntable's viewpoints).
  // The GL renderer compiles the count into its shader (changing it relinks the program).
  uint32_t surface_hints = 1;
  double surface_hint_margin_texels = 0.2;
  // How many views may see a hint crossing as empty space beyond the margin without refuting
  // it (0..65536). Thin parts are often carved away by one view whose texels straddle them; a
  // crossing that is really empty space (the shadow edge, seen from the hint view, of an object
  // in front) is refuted by several views. Counted views are the footprint test's (empty_at).
  uint32_t surface_hint_vetoes = 1;
  // The hint views are tested at this many evenly spaced points per step (1..64; 1 = at the
  // samples only), one texel fetch each: a thin part whose front and back a hint view sees
  // within one step (a silhouette grazed by the ray, a fin) shows as a crossing between two
  // substeps. Each hint offers its first crossing of a step.
  uint32_t surface_hint_substeps = 4;
  // Hint crossings confirmed by coverage (views that carry it): a hint
  // view's crossing ends the ray only where that view's coverage says its surface covers the
  // ray's direction inside the texel the ray went behind (its 4 x 4 cell mask at the direction
  // of the first point behind the surface). 0: off (every crossing counts, as without coverage);
  // 1: the direction's own cell; 2: that cell or one next to it in the texel; 3: as 1, or where
  // another view whose nearest texel at the crossing lies at its depth (within coverage_cluster)
  // covers its direction there (2 and 3: the CPU reference only, the GL renderer refuses them). A
  // hint view without coverage confirms every crossing, so a view set without coverage renders
  // the same at 0 and 1. Default 1 (docs/SILHOUETTES.md "Hint crossings confirmed by coverage").
  uint32_t surface_hint_coverage = 1;
  // Worker threads over image rows (1..256). The result does not depend on it.
  uint32_t threads = 1;
  // Eye rays per pixel along each axis (1..8). The pixel's colour is the mean of n x n rays
  // through the centres of an n x n grid over the pixel's square (a box filter, as calf-capture
  // filters its ground truth and capture texels), its depth the nearest of their hits; 1 = one
  // ray through the pixel centre. Costs n^2 the rays. One ray point-samples every silhouette and
  // texture edge where an anti-aliased image blends them (docs/RENDERING.md "Supersampling").
  uint32_t supersample = 1;
  // RR variant (Sec. 6.1): reflection / refraction rays from the material faces. Views without
  // material contribute (0, 0, 1); a view set without any makes it a no-op.
  bool rr = false;
  // z_e: secondary rays start marching this far from their surface point (> 0), so that they do
  // not hit the surface they leave.
  double rr_start = 0.05;
  // Bounces of reflection / refraction followed (1..8).
  uint32_t rr_max_depth = 1;
  // A captured colour is the full shading the view saw: on a mirror or glass surface it already
  // holds that view's reflection / refraction. true: the best view's colour with its own
  // reflection / refraction (traced from its viewpoint through the same surface point and normal)
  // replaced by the eye's, c = c_view + w_rfl (c_rfl,eye - c_rfl,view) + w_rfr (...), so at a
  // viewpoint the view is reproduced and elsewhere only the view-dependent part moves. false:
  // Alg. 4 as written, c = w_rfl c_rfl + w_rfr c_rfr + (1 - w_rfl - w_rfr) c_blend. The pixel
  // is clamped at 0 (the differences may make it negative). Default true, the tuned value
  // (docs/RENDERING.md "Quality").
  bool rr_replace_view_reflection = true;
};

// The quality setting: `options` with the march and blend knobs that lift most scenes at the
// resolution-matched setting, for offline renders and measurements rather than a frame rate
// (docs/SILHOUETTES.md "The march's quality knobs"): 128 steps, 4 surface hint views that no
// view may veto, the Unstructured Lumigraph's blend of the 3 nearest views, sharpened colour 0.2
// and 4 x 4 eye rays a pixel. Every other field is kept. Coverage is not part of it: which mode
// suits depends on the content (docs/SILHOUETTES.md).
[[nodiscard]] constexpr LightfieldRenderOptions with_quality_setting(
    LightfieldRenderOptions options) {
  options.steps = 128;
  options.surface_hints = 4;
  options.surface_hint_vetoes = 0;
  options.blend_views = 3;
  options.colour_sharpen = 0.2;
  options.supersample = 4;
  return options;
}

// What one ray sees.
struct RaySample {
  double rgb[3] = {0, 0, 0};
  double depth = 0;  // radial distance from the origin to the hit; +inf for sky
  bool hit = false;
};

// A march range covering the views as seen from `eye`: far = max_j (|eye - P_j| + z_far_j)
// (nothing any view stores lies beyond), near = min_j z_near_j / 4 but no nearer
// than far / 2^20 (a tiny z_near must not stretch the log steps).
// Errors: CALF-E403 for an empty view set.
// The same rule over any views: each given by its position and radial depth range.
struct MarchView {
  Vec3 position;
  double z_near = 1, z_far = 2;
};
Expected<LightfieldRenderOptions> march_range_for(std::span<const MarchView> views, const Vec3& eye,
                                                  LightfieldRenderOptions options);
Expected<LightfieldRenderOptions> march_range_for(const ViewSet& views, const Vec3& eye,
                                                  LightfieldRenderOptions options);

// The checks every renderer applies to its options (CALF-E403 naming the option): the range of
// every field.
Status validate_render_options(const LightfieldRenderOptions& options);

// The views a frame uses (per-frame state, apart from the options): indices into the view set, in
// any order; empty = every view. CALF-E403 for an index not below `view_count`.
Status validate_active_views(std::span<const uint32_t> active_views, size_t view_count);

class LightfieldCpuRenderer {
 public:
  // Validates the options against the views (CALF-E403 naming the bad option). The renderer keeps
  // a reference to `views`: they must outlive it and may be updated between frames. It uses every
  // view until restricted_to() or render()'s `active_views` names some.
  static Expected<LightfieldCpuRenderer> make(const ViewSet& views,
                                              const LightfieldRenderOptions& options);

  // The same renderer using only `active_views` (validate_active_views; empty = every view) in
  // render(), trace() and shade_at().
  Expected<LightfieldCpuRenderer> restricted_to(std::span<const uint32_t> active_views) const;

  // Renders `camera` (the one camera model, calf/format/camera.h) into `out` (resized) with the
  // frame's `active_views` (empty = this renderer's views). CALF-E403 for an invalid camera
  // (validate_camera: non-finite position, zero or parallel forward / up, fov outside (0, pi),
  // size outside 1..16384) or active view.
  Status render(const Camera& camera, std::span<const uint32_t> active_views,
                RenderedImage* out) const;
  Status render(const Camera& camera, RenderedImage* out) const { return render(camera, {}, out); }

  // One ray from `origin` along unit `direction`: Alg. 4 Main (or Main_RR with options.rr).
  RaySample trace(const Vec3& origin, const Vec3& direction) const;

  // What trace() returns for the same ray if its march had ended at radial distance `depth` >= 0
  // (+inf or NaN: it found no surface and shows the sky): the same shading, plain or RR, without
  // the march. A diagnostic: given a ground truth's depth it measures the error the shading alone
  // leaves when the geometry is exact (bench-player_quality --gt-depth).
  RaySample shade_at(const Vec3& origin, const Vec3& direction, double depth) const;

  const LightfieldRenderOptions& options() const { return options_; }

 private:
  LightfieldCpuRenderer(const ViewSet& views, const LightfieldRenderOptions& options);
  struct Hit {
    Vec3 p;               // the surface point
    double z = 0;         // its distance from the ray origin
    bool hinted = false;  // found by a surface hint
  };
  RaySample shade_hit(const Vec3& origin, const Vec3& direction, const Hit* hit) const;
  // LightfieldRenderOptions::blend_views: the threshold t at hit p seen from o (+inf: none).
  double blend_threshold(const Vec3& o, const Vec3& p, double hit_distance) const;
  double tap_purity(const View& v, const Texel& t) const;
  void tap_colour(const View& v, const Texel& t, const double strength[2], double rgb[3]) const;
  bool hint_confirmed(const Vec3& o, const Vec3& d, double zb, double zc, const View* h) const;
  // `exclude` (nullptr: none): a surface point of an earlier layer; each view treats its texels
  // at that point's depth (within coverage_cluster) as absent
  // (LightfieldRenderOptions::coverage_layers).
  bool empty_at(const Vec3& p, const Vec3* exclude = nullptr) const;
  bool empty_beyond(const Vec3& p, double margin_texels, uint32_t vetoes_ignored,
                    const Vec3* exclude = nullptr) const;
  bool intersect(const Vec3& origin, const Vec3& dir, double start, Hit* hit,
                 const Vec3* exclude = nullptr) const;
  // `alpha` (optional): the share of p's direction the views' front surfaces cover
  // (LightfieldRenderOptions::coverage_layers), 1 where no view has coverage.
  void shade_surface(const Vec3& origin, const Vec3& p, double* rgb, int* best_view,
                     double* best_rgb = nullptr, double* alpha = nullptr) const;
  RaySample trace_layers(const Vec3& origin, const Vec3& direction) const;
  void secondary(const Vec3& p, const Vec3& dir_in, const Vec3& normal, bool refraction, double ior,
                 uint32_t depth, double* rgb) const;
  void shade_sky(const Vec3& origin, const Vec3& dir, double* rgb) const;
  void shade_rr(const Vec3& origin, const Vec3& dir, const Hit& hit, uint32_t depth,
                double* rgb) const;

  const ViewSet* views_;
  LightfieldRenderOptions options_;
  std::vector<const View*> active_;
  double min_view_distance_ = 0;
  double smooth_log_ratio_ = 0;
  double mixed_penalty_factor_ = 1;  // exp(-mixed_texel_penalty)
};

}  // namespace calf::player
