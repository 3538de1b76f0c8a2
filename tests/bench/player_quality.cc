// Reconstruction quality of the CPU reference renderer (paper 002 Alg. 4, plain and RR) on a
// capture set read directly (uncompressed), against ground truth (docs/RENDERING.md
// "Quality"). Three measurements, each per pose and as means:
//
//   between   the poses of a ground-truth eye path (calf-capture --ground-truth): inside the view
//             volume, away from the viewpoints; reconstruction vs calf-capture's rendering.
//   vp-gt     the same comparison at the viewpoints, for an eye path whose poses sit on the
//             viewpoints (--viewpoint-gt; write one with --write-viewpoint-path, render it with
//             calf-capture --eye-path).
//   vp-reproj at each viewpoint, reconstruction vs the view's own cube map re-projected to the
//             pose (reproject_view: what a plain 360° player shows there). Independent of the
//             capture resolution and of the ray tracer's noise: only the renderer's own errors.
//
// A viewpoint pose looks where pose (v mod P) of the eye path looks: at the surface point its
// centre pixel shows (its ground-truth depth), or along its forward when that pixel is sky; same
// time, field of view and up.
//
// vp-gt also prints "360": the re-projection itself against the ground truth, the bound that the
// capture sets on any renderer at the viewpoint. --supersample K compares K x K box-filtered
// images (ground truth rendered K times larger with calf-capture --gt-size, reconstructions
// rendered at that size): anti-aliased comparisons, free of the point-sampling mismatch at edges.
//
//   bench-player_quality --capture DIR --eye-path GT/eye_path.json [--viewpoint-gt FILE]
//                        [--steps N] [--threads N] [--variants plain,rr] [--out DIR] ...
// Every LightfieldRenderOptions knob has an option (--help). PSNR / SSIM are image_compare.h's
// (sRGB-encoded, clamped; SSIM on luma); per pose, then mean and worst pose. "depth ok" is the
// share of pixels whose depth is within 2 % of the reference's (or sky in both). --breakdown
// splits the squared error by what the ground truth shows at each pixel (sky, grown, hole, edge,
// wrong depth, surface, mirror, glass; see ErrorClass). The commands that produced
// docs/RENDERING.md's tables are listed there.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include "calf/capture/capture_set.h"
#include "calf/capture/eye_path.h"
#include "calf/format/camera.h"
#include "calf/format/colour.h"
#include "calf/player/capture_views.h"
#include "calf/player/image_compare.h"
#include "calf/player/lightfield_cpu_renderer.h"

namespace {

namespace fs = std::filesystem;
using namespace calf;
using namespace calf::player;

[[noreturn]] void die(const Status& s) {
  std::fprintf(stderr, "bench-player_quality: %s\n", s.to_string().c_str());
  std::exit(1);
}
template <typename T>
T need(Expected<T> e) {
  if (!e.ok()) die(e.status());
  return std::move(*e);
}

double now_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

double g_unmix_jump = 0;  // --coverage-unmix-jump

// Views per capture frame, loaded on first use.
class FrameCache {
 public:
  // `unmix_min_share` >= 0: unmix_coverage_colour on every view with that minimum share.
  FrameCache(const capture::CaptureSetReader& r, double unmix_min_share)
      : reader_(r), unmix_min_share_(unmix_min_share) {}
  const ViewSet& at(uint32_t frame) {
    auto it = cache_.find(frame);
    if (it == cache_.end()) {
      if (cache_.size() >= 4) cache_.clear();  // bounded memory on long paths
      it = cache_.emplace(frame, need(load_capture_views(reader_, frame))).first;
      if (unmix_min_share_ >= 0) {
        capture::CoverageUnmixOptions unmix;
        unmix.min_share = unmix_min_share_;
        unmix.min_jump = g_unmix_jump;
        for (View& v : it->second.views) need(unmix_coverage_colour(&v, unmix));
      }
    }
    return it->second;
  }

 private:
  const capture::CaptureSetReader& reader_;
  double unmix_min_share_;
  std::map<uint32_t, ViewSet> cache_;
};

struct Pose {
  capture::EyePose pose;
  RenderedImage reference;  // colour + depth to compare with
  int viewpoint = -1;       // the viewpoint it sits on, or -1
};

struct Score {
  double psnr = 0, ssim = 0, depth_ok = 0, ms = 0;
};

double depth_ok_share(const RenderedImage& a, const RenderedImage& b) {
  size_t ok = 0;
  for (size_t k = 0; k < a.depth.size(); ++k) {
    const bool sa = std::isinf(a.depth[k]), sb = std::isinf(b.depth[k]);
    ok += (sa && sb) || (!sa && !sb && std::fabs(a.depth[k] / b.depth[k] - 1) < 0.02f);
  }
  return static_cast<double>(ok) / a.depth.size();
}

double nearest_viewpoint(const capture::CaptureManifest& m, const Vec3& p) {
  double best = INFINITY;
  for (const capture::Viewpoint& v : m.viewpoints) {
    best = std::min(best, std::hypot(p.x - v.position.x, p.y - v.position.y, p.z - v.position.z));
  }
  return best;
}

RenderedImage from_ground_truth(const capture::PerspectiveImage& gt) {
  RenderedImage r;
  r.width = gt.width;
  r.height = gt.height;
  r.color = gt.color;
  r.depth = gt.depth;
  return r;
}

// Poses (and their ground truth) of an eye path with images.
std::vector<Pose> read_path_poses(const fs::path& file, const capture::EyePath& path,
                                  const capture::CaptureManifest& m) {
  std::vector<Pose> out;
  for (uint32_t i = 0; i < path.poses.size(); ++i) {
    Pose p;
    p.pose = path.poses[i];
    const fs::path image = file.parent_path() / capture::eye_image_file_name(path, i);
    p.reference = from_ground_truth(need(capture::read_perspective_image(image)));
    if (p.reference.width != path.width || p.reference.height != path.height) {
      die(Status(ErrorId::kImageCompare, image.string() + ": size differs from the eye path's"));
    }
    for (size_t v = 0; v < m.viewpoints.size(); ++v) {
      const Vec3& q = m.viewpoints[v].position;
      if (q == p.pose.position) p.viewpoint = static_cast<int>(v);
    }
    out.push_back(std::move(p));
  }
  return out;
}

// One pose per viewpoint, looking at what eye-path pose (v mod P) looks at (see the top comment).
capture::EyePath viewpoint_path(const capture::CaptureManifest& m, const capture::EyePath& path,
                                const std::vector<Pose>& gt) {
  capture::EyePath out;
  out.width = path.width;
  out.height = path.height;
  for (size_t v = 0; v < m.viewpoints.size(); ++v) {
    const Pose& src = gt[v % gt.size()];
    capture::EyePose p = src.pose;
    const Vec3 at = m.viewpoints[v].position;
    const float z = src.reference.depth[size_t{path.height / 2} * path.width + path.width / 2];
    if (std::isfinite(z)) {
      const Vec3 target{src.pose.position.x + src.pose.forward.x * z,
                        src.pose.position.y + src.pose.forward.y * z,
                        src.pose.position.z + src.pose.forward.z * z};
      const double dx = target.x - at.x, dy = target.y - at.y, dz = target.z - at.z;
      const double len = std::sqrt(dx * dx + dy * dy + dz * dz);
      if (len > 1e-6) p.forward = {dx / len, dy / len, dz / len};
    }
    p.position = at;
    out.poses.push_back(p);
  }
  return out;
}

// reference | render | heat map side by side, each scaled `k` times (nearest), for looking at.
Status write_montage(const fs::path& file, const RenderedImage& ref, const RenderedImage& img,
                     uint32_t k) {
  const std::vector<float> err = need(error_map(rgb_ref(img), rgb_ref(ref)));
  const uint32_t w = ref.width, h = ref.height;
  std::vector<float> out(size_t{3} * 3 * w * k * h * k);
  for (uint32_t y = 0; y < h * k; ++y) {
    for (uint32_t x = 0; x < 3 * w * k; ++x) {
      const uint32_t panel = x / (w * k), sx = (x % (w * k)) / k, sy = y / k;
      const size_t src = size_t{sy} * w + sx, dst = 3 * (size_t{y} * 3 * w * k + x);
      for (int c = 0; c < 3; ++c) {
        out[dst + c] = panel == 0   ? ref.color[3 * src + c]
                       : panel == 1 ? img.color[3 * src + c]
                                    : linear_from_srgb8(heat_colour(err[src] / 0.1)[c]);
      }
    }
  }
  return write_png(file, {3 * w * k, h * k, out});
}

// Every k x k block averaged (linear colour; depth: the block's sample (k/2, k/2), the centre
// one for an odd k), for comparing anti-aliased images: a ground truth rendered k times larger
// and a reconstruction rendered at the same size, both filtered the same way (--supersample).
RenderedImage box_down(const RenderedImage& in, uint32_t k) {
  if (k == 1) return in;
  RenderedImage out;
  out.width = in.width / k;
  out.height = in.height / k;
  out.color.assign(size_t{3} * out.width * out.height, 0.0f);
  out.depth.assign(size_t{out.width} * out.height, 0.0f);
  for (uint32_t y = 0; y < out.height; ++y) {
    for (uint32_t x = 0; x < out.width; ++x) {
      const size_t o = size_t{y} * out.width + x;
      double c[3] = {0, 0, 0};
      for (uint32_t j = 0; j < k; ++j) {
        for (uint32_t i = 0; i < k; ++i) {
          const size_t s = size_t{y * k + j} * in.width + x * k + i;
          for (int ch = 0; ch < 3; ++ch) c[ch] += in.color[3 * s + ch];
        }
      }
      for (int ch = 0; ch < 3; ++ch) out.color[3 * o + ch] = static_cast<float>(c[ch] / (k * k));
      out.depth[o] = in.depth[size_t{y * k + k / 2} * in.width + x * k + k / 2];
    }
  }
  return out;
}

uint32_t g_supersample = 1;
bool g_breakdown = false;
// --gt-depth: which eye rays are shaded at the reference's depth instead of where the march ends.
// kSurface: only where both the reference and the march end on a surface (the march's
// sky-or-surface decision kept, its depth replaced); kDecision: only where they disagree about
// sky (the decision replaced, the march's depth kept elsewhere).
enum class GtDepth { kNone, kAll, kSky, kSurface, kDecision };
GtDepth g_gt_depth = GtDepth::kNone;
std::vector<uint32_t> g_active_views;  // --active (empty: every view)

// The CPU renderer over `views` with `o`, restricted to --active.
LightfieldCpuRenderer make_renderer(const ViewSet& views, const LightfieldRenderOptions& o) {
  return need(need(LightfieldCpuRenderer::make(views, o)).restricted_to(g_active_views));
}

// Re-shades the rays of `img` (rendered by `renderer` from `cam`, one ray per pixel) that
// g_gt_depth names at `reference`'s depth: all of them, or those the reference sends to the sky
// while the renderer hit something. What is left is the error of the shading alone.
void shade_at_reference_depth(const LightfieldCpuRenderer& renderer, const Camera& cam,
                              const RenderedImage& reference, RenderedImage* img) {
  const CameraFrame frame = camera_frame(cam);
  for (uint32_t j = 0; j < cam.height; ++j) {
    for (uint32_t i = 0; i < cam.width; ++i) {
      const size_t k = size_t{j} * cam.width + i;
      const double z = reference.depth[k];
      const bool ref_sky = std::isinf(z), img_sky = std::isinf(img->depth[k]);
      if (g_gt_depth == GtDepth::kSky && !(ref_sky && !img_sky)) continue;
      if (g_gt_depth == GtDepth::kSurface && (ref_sky || img_sky)) continue;
      if (g_gt_depth == GtDepth::kDecision && ref_sky == img_sky) continue;
      const RaySample s = renderer.shade_at(cam.position, camera_ray(cam, frame, i, j), z);
      for (int ch = 0; ch < 3; ++ch) img->color[3 * k + ch] = static_cast<float>(s.rgb[ch]);
      img->depth[k] = static_cast<float>(s.depth);
    }
  }
}

// Where the squared error of a reconstruction sits, by what the ground truth shows at each pixel
// (--breakdown; docs/RENDERING.md "Quality"):
//   sky         ground truth sky, reconstruction sky
//   grown       ground truth sky, reconstruction a surface (an object grown into the sky)
//   hole        ground truth a surface, reconstruction sky (a thin part or an edge lost)
//   edge        both a surface, depth within 2 %, and the ground truth has a depth edge (sky or a
//               depth step > 5 %) among its 8 neighbours: silhouettes and occlusion boundaries
//   wrong depth both a surface, depth off by > 2 % (a different surface: edge-on parts, fill-in)
//   surface     the rest: the right surface away from edges (shading, texture, noise)
//   mirror      `surface` pixels whose point a view with material sees as reflective only
//   glass       ... as refractive (mirror-box's spheres): the view-dependent part
// A pixel's depth: the reference's centre ray; the reconstruction's the nearest of its rays with
// --render-supersample N (LightfieldCpuRenderer::render), so a boundary pixel whose centre sees
// the farther surface may class as wrong depth; with --supersample K both images' block sample
// (K/2, K/2), the centre for an odd K.
enum ErrorClass { kSky, kGrown, kHole, kEdge, kWrongDepth, kSurface, kMirror, kGlass, kClassCount };
const char* const kClassNames[kClassCount] = {"sky",         "grown",   "hole",   "edge",
                                              "wrong depth", "surface", "mirror", "glass"};

struct Breakdown {
  double pixels[kClassCount] = {};
  double se[kClassCount] = {};  // squared error of the sRGB-encoded, clamped values
};

// kMirror / kGlass when the ground-truth point in direction `dir` at `depth` from `eye` is
// reflective / refractive according to the first view with material that sees it (depth within
// 2 %), else kSurface.
ErrorClass specular_class(const ViewSet& views, const Vec3& eye, const Vec3& dir, double depth) {
  const Vec3 q{eye.x + dir.x * depth, eye.y + dir.y * depth, eye.z + dir.z * depth};
  for (const View& v : views.views) {
    if (!v.has_material()) continue;
    const Vec3 x{q.x - v.position().x, q.y - v.position().y, q.z - v.position().z};
    const double r = std::sqrt(x.x * x.x + x.y * x.y + x.z * x.z);
    const Texel t = texel_from_direction({x.x, x.y, x.z}, v.face_size());
    const uint16_t code = v.depth_code_at(t.face, t.x, t.y);
    if (code == kLog16Sky || std::fabs(v.range().decode(code) / r - 1) > 0.02) continue;
    const Material m = v.material_at(t.face, t.x, t.y);
    return m.refract > 0 ? kGlass : m.reflect > 0 ? kMirror : kSurface;
  }
  return kSurface;
}

void add_breakdown(const RenderedImage& img, const RenderedImage& ref, const ViewSet& views,
                   const Camera& cam, Breakdown* b) {
  const uint32_t w = ref.width, h = ref.height;
  const auto encoded = [](float linear) {
    return srgb_from_linear(std::clamp(linear, 0.0f, 1.0f));
  };
  for (uint32_t j = 0; j < h; ++j) {
    for (uint32_t i = 0; i < w; ++i) {
      const size_t k = size_t{j} * w + i;
      double se = 0;
      for (int c = 0; c < 3; ++c) {
        const double d = encoded(img.color[3 * k + c]) - encoded(ref.color[3 * k + c]);
        se += d * d;
      }
      const float zr = ref.depth[k], zi = img.depth[k];
      ErrorClass cls;
      if (std::isinf(zr)) {
        cls = std::isinf(zi) ? kSky : kGrown;
      } else if (std::isinf(zi)) {
        cls = kHole;
      } else if (std::fabs(zi / zr - 1) > 0.02f) {
        cls = kWrongDepth;
      } else {
        bool edge = false;
        for (int dj = -1; dj <= 1 && !edge; ++dj) {
          for (int di = -1; di <= 1 && !edge; ++di) {
            const int64_t x = int64_t{i} + di, y = int64_t{j} + dj;
            if (x < 0 || y < 0 || x >= w || y >= h) continue;
            const float zn = ref.depth[size_t(y) * w + size_t(x)];
            edge = std::isinf(zn) || std::fabs(zn / zr - 1) > 0.05f;
          }
        }
        cls = edge ? kEdge : specular_class(views, cam.position, camera_ray(cam, i, j), zr);
      }
      b->pixels[cls] += 1;
      b->se[cls] += se;
    }
  }
}

// Per class: share of pixels, share of the squared error, and the PSNR the image would have if
// only that class's error remained.
void print_breakdown(const std::string& name, const Breakdown& b) {
  double pixels = 0, se = 0;
  for (int c = 0; c < kClassCount; ++c) {
    pixels += b.pixels[c];
    se += b.se[c];
  }
  std::printf(
      "\n%s error by ground-truth pixel class (PSNR if only this class's error remained):\n\n"
      "| class | pixels | share of squared error | PSNR alone |\n|---|---|---|---|\n",
      name.c_str());
  for (int c = 0; c < kClassCount; ++c) {
    if (b.pixels[c] == 0) continue;
    const double alone = b.se[c] > 0 ? 10 * std::log10(3 * pixels / b.se[c]) : INFINITY;
    std::printf("| %s | %.2f %% | %.1f %% | %.2f dB |\n", kClassNames[c],
                100 * b.pixels[c] / pixels, 100 * b.se[c] / se, alone);
  }
}

struct Variant {
  std::string name;
  LightfieldRenderOptions options;
};

// Renders every pose with every variant, prints a row per pose and the means; returns the means.
std::vector<Score> measure(const char* section, std::vector<Pose>& poses, FrameCache& frames,
                           const capture::CaptureManifest& m, const std::vector<Variant>& variants,
                           const fs::path& out_dir, bool with_360) {
  std::printf("\n### %s (%zu poses)\n\n| pose | frame | eye-viewpoint |", section, poses.size());
  if (with_360) std::printf(" 360 PSNR | SSIM |");
  for (const Variant& v : variants)
    std::printf(" %s PSNR | SSIM | depth ok | ms |", v.name.c_str());
  std::printf("\n|---|---|---|");
  if (with_360) std::printf("---|---|");
  for (size_t i = 0; i < variants.size(); ++i) std::printf("---|---|---|---|");
  std::printf("\n");
  std::vector<Score> mean(variants.size()), worst(variants.size(), Score{INFINITY, INFINITY, 0, 0});
  std::vector<Breakdown> breakdown(variants.size());
  Score mean_360;
  for (size_t pi = 0; pi < poses.size(); ++pi) {
    Pose& p = poses[pi];
    const uint32_t frame = capture_frame_at(m, p.pose.time);
    const ViewSet& views = frames.at(frame);
    const Camera cam = capture::camera_from_pose(p.pose, p.reference.width, p.reference.height);
    const RenderedImage reference = box_down(p.reference, g_supersample);
    std::printf("| %zu | %u | %.3f |", pi, frame, nearest_viewpoint(m, p.pose.position));
    if (with_360) {
      // What a plain 360° player shows at this viewpoint: the bound set by the capture itself.
      if (p.viewpoint < 0)
        die(Status(ErrorId::kInvalidArgument, "a --viewpoint-gt pose is not on a viewpoint"));
      const RenderedImage r =
          box_down(reproject_view(views.views[p.viewpoint], cam), g_supersample);
      const double q = need(psnr(rgb_ref(r), rgb_ref(reference)));
      const double t = need(ssim(rgb_ref(r), rgb_ref(reference)));
      std::printf(" %.2f | %.4f |", q, t);
      mean_360.psnr += q / poses.size();
      mean_360.ssim += t / poses.size();
    }
    for (size_t vi = 0; vi < variants.size(); ++vi) {
      const LightfieldRenderOptions o =
          need(march_range_for(views, cam.position, variants[vi].options));
      const LightfieldCpuRenderer renderer = make_renderer(views, o);
      RenderedImage img;
      const double t0 = now_s();
      if (Status s = renderer.render(cam, &img); !s.ok()) die(s);
      if (g_gt_depth != GtDepth::kNone) shade_at_reference_depth(renderer, cam, p.reference, &img);
      img = box_down(img, g_supersample);
      Score s;
      s.ms = 1e3 * (now_s() - t0);
      s.psnr = need(psnr(rgb_ref(img), rgb_ref(reference)));
      s.ssim = need(ssim(rgb_ref(img), rgb_ref(reference)));
      s.depth_ok = depth_ok_share(img, reference);
      if (g_breakdown) {
        // With --supersample K the compared images are K times smaller than the render: the
        // camera that names their pixels' directions is at their size.
        const Camera small = capture::camera_from_pose(p.pose, reference.width, reference.height);
        add_breakdown(img, reference, views, small, &breakdown[vi]);
      }
      std::printf(" %.2f | %.4f | %.1f%% | %.0f |", s.psnr, s.ssim, 100 * s.depth_ok, s.ms);
      mean[vi].psnr += s.psnr / poses.size();
      mean[vi].ssim += s.ssim / poses.size();
      mean[vi].depth_ok += s.depth_ok / poses.size();
      mean[vi].ms += s.ms / poses.size();
      worst[vi].psnr = std::min(worst[vi].psnr, s.psnr);
      worst[vi].ssim = std::min(worst[vi].ssim, s.ssim);
      if (!out_dir.empty()) {
        const std::string stem = fmt::format("{}_{:03}_{}", section, pi, variants[vi].name);
        if (Status e = write_png(out_dir / (stem + ".png"), rgb_ref(img)); !e.ok()) die(e);
        if (Status e = write_heat_map_png(out_dir / (stem + "_heat.png"), rgb_ref(img),
                                          rgb_ref(reference));
            !e.ok()) {
          die(e);
        }
        if (Status e = write_montage(out_dir / (stem + "_montage.png"), reference, img, 3);
            !e.ok()) {
          die(e);
        }
      }
    }
    if (!out_dir.empty()) {
      const fs::path ref = out_dir / fmt::format("{}_{:03}_reference.png", section, pi);
      if (Status e = write_png(ref, rgb_ref(reference)); !e.ok()) die(e);
    }
    std::printf("\n");
    std::fflush(stdout);
  }
  std::printf("| **mean** | | |");
  if (with_360) std::printf(" %.2f | %.4f |", mean_360.psnr, mean_360.ssim);
  for (const Score& s : mean) {
    std::printf(" **%.2f** | **%.4f** | %.1f%% | %.0f |", s.psnr, s.ssim, 100 * s.depth_ok, s.ms);
  }
  std::printf("\n| worst | | |");
  if (with_360) std::printf(" | |");
  for (const Score& s : worst) std::printf(" %.2f | %.4f | | |", s.psnr, s.ssim);
  std::printf("\n");
  if (g_breakdown) {
    for (size_t vi = 0; vi < variants.size(); ++vi) {
      print_breakdown(std::string(section) + " " + variants[vi].name, breakdown[vi]);
    }
  }
  return mean;
}

// --montage: the worst silhouette region of one pose, ground truth beside renders with other
// coverage settings. Each entry of `settings` is "M" (coverage mode M) or "M+L" (and
// coverage_layers L); the window (`window` pixels square, scaled `scale` times, nearest) is the
// one with the largest squared error of the first entry's render over the pixels that the
// ground truth or that render shows as sky or next to a depth edge (the breakdown's grown, hole
// and edge classes), searched on a grid of window / 4.
void write_silhouette_montage(const fs::path& file, const Pose& p, const ViewSet& views,
                              const LightfieldRenderOptions& base,
                              const std::vector<std::string>& settings, uint32_t window,
                              uint32_t scale) {
  const Camera cam = capture::camera_from_pose(p.pose, p.reference.width, p.reference.height);
  const RenderedImage& ref = p.reference;
  const uint32_t w = ref.width, h = ref.height;
  window = std::min({window, w, h});
  std::vector<RenderedImage> renders;
  for (const std::string& setting : settings) {
    LightfieldRenderOptions o = base;
    const size_t plus = setting.find('+');
    o.coverage = static_cast<uint32_t>(std::stoul(setting.substr(0, plus)));
    o.coverage_layers =
        plus == std::string::npos ? 0 : static_cast<uint32_t>(std::stoul(setting.substr(plus + 1)));
    o = need(march_range_for(views, cam.position, o));
    const LightfieldCpuRenderer renderer = make_renderer(views, o);
    RenderedImage img;
    if (Status s = renderer.render(cam, &img); !s.ok()) die(s);
    renders.push_back(std::move(img));
  }
  const auto encoded = [](float linear) {
    return srgb_from_linear(std::clamp(linear, 0.0f, 1.0f));
  };
  std::vector<double> se(size_t{w} * h, 0.0);
  for (uint32_t j = 0; j < h; ++j) {
    for (uint32_t i = 0; i < w; ++i) {
      const size_t k = size_t{j} * w + i;
      bool silhouette = false;
      for (int dj = -1; dj <= 1; ++dj) {
        for (int di = -1; di <= 1; ++di) {
          const int64_t x = int64_t{i} + di, y = int64_t{j} + dj;
          if (x < 0 || y < 0 || x >= w || y >= h) continue;
          const float zn = ref.depth[size_t(y) * w + size_t(x)];
          silhouette = silhouette || std::isinf(zn) || std::isinf(renders[0].depth[k]) ||
                       std::fabs(zn / ref.depth[k] - 1) > 0.05f;
        }
      }
      if (!silhouette) continue;
      for (int c = 0; c < 3; ++c) {
        const double d = encoded(renders[0].color[3 * k + c]) - encoded(ref.color[3 * k + c]);
        se[k] += d * d;
      }
    }
  }
  uint32_t bx = 0, by = 0;
  double worst = -1;
  const uint32_t stride = std::max(window / 4, 1u);
  for (uint32_t y0 = 0; y0 + window <= h; y0 += stride) {
    for (uint32_t x0 = 0; x0 + window <= w; x0 += stride) {
      double sum = 0;
      for (uint32_t y = y0; y < y0 + window; ++y) {
        for (uint32_t x = x0; x < x0 + window; ++x) sum += se[size_t{y} * w + x];
      }
      if (sum > worst) worst = sum, bx = x0, by = y0;
    }
  }
  const uint32_t panels = 1 + static_cast<uint32_t>(renders.size()), side = window * scale;
  const uint32_t gap = scale;  // a dark column between panels
  const uint32_t out_w = panels * side + (panels - 1) * gap;
  std::vector<float> out(size_t{3} * out_w * side, 0.0f);
  for (uint32_t panel = 0; panel < panels; ++panel) {
    const RenderedImage& img = panel == 0 ? ref : renders[panel - 1];
    for (uint32_t y = 0; y < side; ++y) {
      for (uint32_t x = 0; x < side; ++x) {
        const size_t src = size_t{by + y / scale} * w + bx + x / scale;
        const size_t dst = 3 * (size_t{y} * out_w + panel * (side + gap) + x);
        for (int c = 0; c < 3; ++c) out[dst + c] = img.color[3 * src + c];
      }
    }
  }
  if (Status s = write_png(file, {out_w, side, out}); !s.ok()) die(s);
  std::printf("montage %s: window %ux%u at (%u, %u), ground truth", file.string().c_str(), window,
              window, bx, by);
  for (size_t k = 0; k < settings.size(); ++k) {
    std::printf(" | coverage %s", settings[k].c_str());
  }
  std::printf("\n");
}

std::vector<uint32_t> parse_list(const std::string& text) {
  std::vector<uint32_t> out;
  size_t at = 0;
  while (at < text.size()) {
    size_t comma = text.find(',', at);
    if (comma == std::string::npos) comma = text.size();
    const std::string item = text.substr(at, comma - at);
    char* end = nullptr;
    const unsigned long v = std::strtoul(item.c_str(), &end, 10);
    if (item.empty() || *end != 0 || v > 0xFFFFFFFFul) {
      die(Status(ErrorId::kInvalidArgument, "'" + text + "' is not a list of indices"));
    }
    out.push_back(static_cast<uint32_t>(v));
    at = comma + 1;
  }
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Reconstruction quality of the CPU renderer on a capture set.",
               "bench-player_quality"};
  std::string capture_dir, eye_path_file, vp_gt_file, write_vp_file, out_dir, poses_arg;
  std::string variants_arg = "plain,rr", active_arg;
  // LightfieldRenderOptions' defaults: the tuned configuration of docs/RENDERING.md "Quality".
  LightfieldRenderOptions base;
  bool no_reproject = false;
  app.add_option("--capture", capture_dir, "capture set directory (manifest.json)")->required();
  app.add_option("--eye-path", eye_path_file,
                 "ground-truth eye path with images (calf-capture --ground-truth): between "
                 "viewpoints");
  app.add_option("--viewpoint-gt", vp_gt_file,
                 "ground-truth eye path rendered at the viewpoints (from --write-viewpoint-path)");
  app.add_option("--write-viewpoint-path", write_vp_file,
                 "write an eye path with one pose per viewpoint (needs --eye-path) and exit");
  app.add_option("--steps", base.steps, "N_step")->capture_default_str();
  app.add_option("--refine", base.refine_steps, "bisection steps")->capture_default_str();
  app.add_option("--footprint", base.depth_footprint, "depth_footprint")->capture_default_str();
  app.add_option("--smooth", base.smooth_depth_ratio, "smooth_depth_ratio")->capture_default_str();
  app.add_option("--depth-decay", base.depth_decay, "w_depth decay")->capture_default_str();
  app.add_option("--cam-decay", base.cam_decay, "w_cam decay")->capture_default_str();
  app.add_option("--blend-views", base.blend_views,
                 "blend_views: the Unstructured Lumigraph's weights over the K nearest views "
                 "that see the hit instead of cam_decay (0 off, 1..8)")
      ->capture_default_str();
  app.add_option("--colour-tolerance,--color-tolerance", base.colour_depth_tolerance,
                 "colour_depth_tolerance")
      ->capture_default_str();
  app.add_option("--tight-start", base.tight_march_start, "tight_march_start (0/1)")
      ->capture_default_str();
  app.add_option("--hints", base.surface_hints, "surface_hints")->capture_default_str();
  app.add_option("--hint-coverage", base.surface_hint_coverage,
                 "surface_hint_coverage: 0 off, 1 a hint crossing needs its cell covered, 2 or a "
                 "cell next to it, 3 or another view's cell at its depth")
      ->capture_default_str();
  app.add_option("--mixed-penalty", base.mixed_texel_penalty, "mixed_texel_penalty (0 = off)")
      ->capture_default_str();
  app.add_option("--mixed-bend", base.mixed_texel_bend_texels, "mixed_texel_bend_texels")
      ->capture_default_str();
  app.add_option("--coverage", base.coverage,
                 "coverage: 0 off, 1 bilinear front shares, 2 cell mask, 3 grown cell mask, 4 "
                 "every tap's cell, 5 grown cell mask where a texel behind the front answers for "
                 "its own cells (views with coverage)")
      ->capture_default_str();
  app.add_option("--coverage-threshold", base.coverage_threshold, "coverage_threshold")
      ->capture_default_str();
  app.add_option("--coverage-cluster", base.coverage_cluster, "coverage_cluster")
      ->capture_default_str();
  app.add_option("--coverage-agreement", base.coverage_agreement, "coverage_agreement")
      ->capture_default_str();
  app.add_option("--coverage-layers", base.coverage_layers,
                 "coverage_layers: composite at most this many partly covered surfaces per ray "
                 "(0 off)")
      ->capture_default_str();
  app.add_option("--coverage-alpha", base.coverage_alpha,
                 "coverage_alpha: 0 the views' minimum, 1 their colour-weighted mean")
      ->capture_default_str();
  app.add_option("--coverage-layers-hints", base.coverage_layers_hints_only,
                 "coverage_layers_hints_only (0/1): composite only surface hints' hits")
      ->capture_default_str();
  double unmix = -1;
  app.add_option("--coverage-unmix-jump", g_unmix_jump,
                 "unmix only across depth steps above this relative depth")
      ->capture_default_str();
  app.add_option("--colour-sharpen,--color-sharpen", base.colour_sharpen, "colour_sharpen")
      ->capture_default_str();
  app.add_option("--colour-sharpen-jump,--color-sharpen-jump", base.colour_sharpen_jump_texels,
                 "colour_sharpen_jump_texels")
      ->capture_default_str();
  app.add_option("--coverage-unmix", unmix,
                 "unmix edge texels' colour from coverage with this minimum own share "
                 "(unmix_coverage_colour; negative: off)")
      ->capture_default_str();
  app.add_option("--hint-margin", base.surface_hint_margin_texels,
                 "surface_hint_margin_texels (of the vetoing view)")
      ->capture_default_str();
  app.add_option("--hint-vetoes", base.surface_hint_vetoes, "surface_hint_vetoes")
      ->capture_default_str();
  app.add_option("--hint-substeps", base.surface_hint_substeps, "surface_hint_substeps")
      ->capture_default_str();
  app.add_option("--bilinear", base.bilinear_colour, "bilinear_colour (0/1)")
      ->capture_default_str();
  app.add_option("--rr-replace", base.rr_replace_view_reflection, "rr_replace_view_reflection")
      ->capture_default_str();
  app.add_option("--rr-start", base.rr_start, "z_e of secondary rays")->capture_default_str();
  app.add_option("--rr-depth", base.rr_max_depth, "RR bounces")->capture_default_str();
  app.add_option("--threads", base.threads, "render threads")->capture_default_str();
  app.add_option("--variants", variants_arg, "comma-separated: plain, rr")->capture_default_str();
  app.add_option("--poses", poses_arg, "comma-separated pose indices of --eye-path (default all)");
  app.add_option("--active", active_arg, "comma-separated active view indices (default all)");
  app.add_option("--supersample", g_supersample,
                 "compare k x k box-filtered images: ground truth rendered k times the size, "
                 "reconstructions rendered at that size (1..8)")
      ->capture_default_str();
  app.add_option(
         "--render-supersample", base.supersample,
         "LightfieldRenderOptions::supersample: the renderer's own n x n eye rays per pixel, box-"
         "filtered, against the ground truth at its size (calf-play --supersample; 1..8)")
      ->capture_default_str();
  app.add_flag("--no-reproject", no_reproject, "skip the vp-reproj measurement");
  app.add_flag("--breakdown", g_breakdown,
               "print where the squared error sits: sky, grown, hole, edge, wrong depth, surface, "
               "mirror, glass pixels (with --supersample K: by the depth of each K x K block's "
               "sample (K/2, K/2), the pixel centre for an odd K)");
  app.add_option("--out", out_dir, "write renders, references and heat maps (PNG) here");
  std::string montage_file, montage_arg = "0,3";
  uint32_t montage_window = 48, montage_scale = 4;
  app.add_option("--montage", montage_file,
                 "write a PNG of the first picked pose's worst silhouette region: ground truth | "
                 "one render per --montage-coverage entry (the window is the first entry's worst)");
  app.add_option("--montage-coverage", montage_arg,
                 "comma-separated: M (coverage mode) or M+L (and coverage_layers L)")
      ->capture_default_str();
  app.add_option("--montage-window", montage_window, "window side in pixels")
      ->capture_default_str();
  app.add_option("--montage-scale", montage_scale, "pixel scale of the montage")
      ->check(CLI::Range(1, 16))
      ->capture_default_str();
  std::string gt_depth_arg = "none";
  app.add_option("--gt-depth", gt_depth_arg,
                 "none; all: shade every eye ray at the reference's depth instead of where the "
                 "march ends (the error the shading leaves when the geometry is exact); sky: only "
                 "the rays that the reference sends to the sky and the march ends on a surface "
                 "(with --render-supersample 1; use --supersample K for anti-aliased figures; "
                 "the ms column then includes the re-shading); surface: only where both the "
                 "reference and the march end on a surface (the march's silhouettes, exact "
                 "depth); decision: only where they disagree about sky (exact silhouettes, the "
                 "march's depth)")
      ->check(CLI::IsMember({"none", "all", "sky", "surface", "decision"}))
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  g_gt_depth = gt_depth_arg == "all"        ? GtDepth::kAll
               : gt_depth_arg == "sky"      ? GtDepth::kSky
               : gt_depth_arg == "surface"  ? GtDepth::kSurface
               : gt_depth_arg == "decision" ? GtDepth::kDecision
                                            : GtDepth::kNone;
  if (g_gt_depth != GtDepth::kNone && base.supersample != 1) {
    die(Status(ErrorId::kInvalidArgument,
               "--gt-depth needs --render-supersample 1: the reference has one depth per pixel"));
  }

  if (g_supersample < 1 || g_supersample > 8) {
    die(Status(ErrorId::kInvalidArgument, "--supersample must be in 1..8"));
  }
  if (!active_arg.empty()) g_active_views = parse_list(active_arg);
  const capture::CaptureSetReader reader = need(capture::CaptureSetReader::open(capture_dir));
  const capture::CaptureManifest& m = reader.manifest();
  std::vector<Variant> variants;
  for (size_t at = 0; at < variants_arg.size();) {
    size_t comma = variants_arg.find(',', at);
    if (comma == std::string::npos) comma = variants_arg.size();
    Variant v{variants_arg.substr(at, comma - at), base};
    if (v.name != "plain" && v.name != "rr") {
      die(Status(ErrorId::kInvalidArgument, "--variants: unknown variant '" + v.name + "'"));
    }
    v.options.rr = v.name == "rr";
    if (!(v.options.rr && !m.material)) variants.push_back(v);  // RR without material = plain
    at = comma + 1;
  }
  if (!out_dir.empty()) fs::create_directories(out_dir);

  std::vector<Pose> between;
  capture::EyePath path;
  if (!eye_path_file.empty()) {
    path = need(capture::read_eye_path(eye_path_file));
    between = read_path_poses(eye_path_file, path, m);
  }
  if (!write_vp_file.empty()) {
    if (between.empty())
      die(Status(ErrorId::kInvalidArgument, "--write-viewpoint-path needs --eye-path"));
    capture::EyePath vp = viewpoint_path(m, path, between);
    if (Status s = capture::write_file_atomically(write_vp_file, capture::serialize_eye_path(vp));
        !s.ok()) {
      die(s);
    }
    std::printf(
        "wrote %zu viewpoint poses to %s; render them with\n  calf-capture --scene %s "
        "--eye-path %s --out DIR\n",
        vp.poses.size(), write_vp_file.c_str(), m.scene.c_str(), write_vp_file.c_str());
    return 0;
  }
  std::vector<uint32_t> picked_index;
  for (uint32_t i = 0; i < between.size(); ++i) picked_index.push_back(i);
  if (!poses_arg.empty()) {
    std::vector<Pose> picked;
    picked_index.clear();
    for (uint32_t i : parse_list(poses_arg)) {
      if (i < between.size()) picked.push_back(between[i]), picked_index.push_back(i);
    }
    between = std::move(picked);
  }
  // The noise floor of the picked poses: their ground truth against the one calf-capture renders
  // with another seed into noise-floor/ beside the eye path, where there is one.
  const fs::path floor_dir = fs::path(eye_path_file).parent_path() / "noise-floor";
  if (!between.empty() && fs::is_directory(floor_dir)) {
    double sum_p = 0, sum_s = 0;
    for (size_t k = 0; k < between.size(); ++k) {
      const RenderedImage other = from_ground_truth(need(capture::read_perspective_image(
          floor_dir / capture::eye_image_file_name(path, picked_index[k]))));
      sum_p += need(psnr(rgb_ref(other), rgb_ref(between[k].reference)));
      sum_s += need(ssim(rgb_ref(other), rgb_ref(between[k].reference)));
    }
    std::printf(
        "noise floor (%s, another seed): mean PSNR %.2f dB, mean SSIM %.4f over %zu poses\n",
        floor_dir.string().c_str(), sum_p / between.size(), sum_s / between.size(), between.size());
  }

  std::printf(
      "## %s: %zu views, face %u, %u frames; steps %u, refine %u, footprint %.2f, smooth "
      "%.2f, depth_decay %.0f, cam_decay %.0f, blend views %u, colour tolerance %.2f, sharpen %.2f "
      "(jump %.1f "
      "texels), mixed texels %.1f (bend %.2f "
      "texels), tight start %d, "
      "hints %u (margin %.3f texels, vetoes %u, substeps %u), rr_start %.3f, rr replace %d, "
      "supersample %u (renderer %u), threads %u; coverage %u (threshold %.2f, cluster %.3f, "
      "agreement %u, unmix %.2f, layers %u, alpha rule %u, hint coverage %u)\n",
      m.scene.c_str(), m.viewpoints.size(), m.face_size, m.frame_count, base.steps,
      base.refine_steps, base.depth_footprint, base.smooth_depth_ratio, base.depth_decay,
      base.cam_decay, base.blend_views, base.colour_depth_tolerance, base.colour_sharpen,
      base.colour_sharpen_jump_texels, base.mixed_texel_penalty, base.mixed_texel_bend_texels,
      base.tight_march_start, base.surface_hints, base.surface_hint_margin_texels,
      base.surface_hint_vetoes, base.surface_hint_substeps, base.rr_start,
      base.rr_replace_view_reflection, g_supersample, base.supersample, base.threads, base.coverage,
      base.coverage_threshold, base.coverage_cluster, base.coverage_agreement, unmix,
      base.coverage_layers, base.coverage_alpha, base.surface_hint_coverage);
  FrameCache frames(reader, unmix);
  if (!montage_file.empty()) {
    if (between.empty()) die(Status(ErrorId::kInvalidArgument, "--montage needs --eye-path"));
    std::vector<std::string> settings;
    for (size_t at = 0; at < montage_arg.size();) {
      size_t comma = montage_arg.find(',', at);
      if (comma == std::string::npos) comma = montage_arg.size();
      const std::string item = montage_arg.substr(at, comma - at);
      if (item.empty() || item.find_first_not_of("0123456789+") != std::string::npos ||
          item.front() == '+' || item.back() == '+') {
        die(Status(ErrorId::kInvalidArgument, "--montage-coverage: bad entry '" + item + "'"));
      }
      settings.push_back(item);
      at = comma + 1;
    }
    const Pose& p = between.front();
    write_silhouette_montage(montage_file, p, frames.at(capture_frame_at(m, p.pose.time)), base,
                             settings, montage_window, montage_scale);
    return 0;
  }
  if (!between.empty()) measure("between", between, frames, m, variants, out_dir, false);
  if (!vp_gt_file.empty()) {
    const capture::EyePath vp = need(capture::read_eye_path(vp_gt_file));
    std::vector<Pose> at_vp = read_path_poses(vp_gt_file, vp, m);
    measure("vp-gt", at_vp, frames, m, variants, out_dir, true);
  }
  if (!no_reproject && !between.empty()) {
    // The viewpoint poses, with each view's own re-projected cube map as the reference.
    std::vector<Pose> at_vp;
    const capture::EyePath vp = viewpoint_path(m, path, between);
    for (size_t v = 0; v < vp.poses.size(); ++v) {
      Pose p;
      p.pose = vp.poses[v];
      p.viewpoint = static_cast<int>(v);
      const ViewSet& views = frames.at(capture_frame_at(m, p.pose.time));
      p.reference =
          reproject_view(views.views[v], capture::camera_from_pose(p.pose, vp.width, vp.height));
      at_vp.push_back(std::move(p));
    }
    measure("vp-reproj", at_vp, frames, m, variants, out_dir, false);
  }
  return 0;
}
