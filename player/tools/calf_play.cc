// calf-play: plays a .calf clip — its lightfield tracks (paper 002 Sec. 6) and mesh tracks (paper
// 004's full scene or visible set), composited by depth: in a GLFW window with fly / orbit
// cameras and a Dear ImGui HUD, or headless through OSMesa along an eye path, writing frames and
// comparing them with calf-capture's ground truth. Errors are one line with a stable id and exit
// status 1; usage errors exit 2 (command_line.h).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <initializer_list>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "calf/capture/eye_path.h"
#include "calf/player/contact_sheet.h"
#include "calf/player/error_breakdown.h"
#include "calf/player/gl_context.h"
#include "calf/player/image_compare.h"
#include "calf/player/playback.h"
#include "calf_play/play_window.h"
#include "command_line.h"
#include "enum_option.h"

namespace {

namespace fs = std::filesystem;
using namespace calf;
using namespace calf::player;

int fail(const Status& status) {
  return tools::print_error("calf-play", status);
}

// Options that contradict each other: E461, exit 2 like every usage error (command_line.h).
int contradiction(const std::string& message) {
  return tools::print_error("calf-play", Status(ErrorId::kPlaybackOption, message),
                            tools::kExitUsage);
}

struct HeadlessArgs {
  std::string eye_path, out, compare, format = "png", contact_sheet;
  // --noise-floor: ground truth of the same path with another seed (default GT_DIR/noise-floor).
  std::string noise_floor;
  // --compare-clip: the full-scene clip played beside CLIP for epsilon (paper 004).
  std::string compare_clip;
  // --breakdown: the capture set the clip was made from (error classes); --breakdown-lossless:
  // a lossless clip of it (the codec class).
  std::string breakdown, breakdown_lossless;
  uint32_t sheet_rows = 8;
  bool heat_maps = true;
  double surfel_target_ms = 0;    // --surfel-target-ms: report render times to the controller
  bool surfel_foveation = false;  // --surfel-foveation: print the peripheral objects per pose
};

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const size_t m = v.size() / 2;
  return v.size() % 2 ? v[m] : (v[m - 1] + v[m]) / 2;
}

// The images of the poses chosen for the contact sheet, kept until the end of the path.
struct SheetTile {
  RenderedImage rendered;
  capture::PerspectiveImage ground_truth;
};

// Per-pose figures of CLIP against the full-scene clip (--compare-clip).
struct ClipComparison {
  double sum_eps = 0, max_eps = 0, sum_psnr = 0, sum_ssim = 0;
  double min_psnr = INFINITY, min_ssim = INFINITY;
  size_t max_eps_pose = 0;
  uint32_t count = 0;
  std::vector<double> render_ms;  // the full-scene clip's
};

// Plays `path` pose by pose; poses sharing a time (a stereo pair) are prepared together. With
// `full`, the same poses are rendered from the full-scene clip too and compared (epsilon).
int run_headless(Playback& play, Playback* full, Playback* lossless, const HeadlessArgs& a) {
  fs::path gt_dir;
  capture::EyePath path;
  if (!a.compare.empty()) gt_dir = a.compare;
  const fs::path path_file =
      !a.eye_path.empty() ? fs::path(a.eye_path) : gt_dir / capture::kEyePathFileName;
  auto loaded = capture::read_eye_path(path_file);
  if (!loaded.ok()) return fail(loaded.status());
  path = std::move(*loaded);
  if (!gt_dir.empty() && path.image_pattern.empty()) {
    return fail(Status(ErrorId::kPlaybackOption,
                       path_file.string() + " names no ground-truth images to compare with"));
  }
  // The noise floor: the ground truth against the same poses rendered with another seed
  // (format/CAPTURE.md, "Noise floor"); no figure measures the reconstruction more finely.
  fs::path floor_dir;
  if (!gt_dir.empty()) {
    std::error_code ec;
    if (!a.noise_floor.empty()) {
      floor_dir = a.noise_floor;
    } else if (fs::exists(gt_dir / capture::kNoiseFloorDirName / capture::kEyePathFileName, ec)) {
      floor_dir = gt_dir / capture::kNoiseFloorDirName;
    }
  }
  capture::EyePath floor_path;
  if (!floor_dir.empty()) {
    auto f = capture::read_eye_path(floor_dir / capture::kEyePathFileName);
    if (!f.ok()) return fail(f.status());
    floor_path = std::move(*f);
    if (floor_path.image_pattern.empty() || floor_path.poses != path.poses ||
        floor_path.width != path.width || floor_path.height != path.height) {
      return fail(Status(ErrorId::kPlaybackOption,
                         (floor_dir / capture::kEyePathFileName).string() +
                             " is not ground truth of the same poses and image size"));
    }
  }
  // The error breakdown: the capture set's views at the frame of each pose, loaded once a frame.
  std::unique_ptr<capture::CaptureSetReader> breakdown_reader;
  if (!a.breakdown.empty()) {
    auto r = capture::CaptureSetReader::open(a.breakdown);
    if (!r.ok()) return fail(r.status());
    breakdown_reader = std::make_unique<capture::CaptureSetReader>(std::move(*r));
  }
  std::optional<CaptureVisibility> visibility;
  ErrorBreakdown breakdown_sum;
  RenderedImage lossless_image;
  double floor_sum_psnr = 0, floor_sum_ssim = 0, floor_min_psnr = INFINITY;
  size_t floor_min_pose = 0;
  if (!a.out.empty()) {
    std::error_code ec;
    fs::create_directories(a.out, ec);
    if (ec) return fail(Status(ErrorId::kFileWrite, a.out + ": " + ec.message()));
  }
  // The light-field figures printed per pose are the first lightfield track's (if any).
  const LightfieldRepresentation* lf = play.lightfield();
  warn_dropped_views(play);
  if (lf != nullptr && lf->options().render.rr && !lf->has_material()) {
    std::fprintf(stderr, "calf-play: notice: the clip has no material stream; --rr is ignored\n");
  }
  double sum_psnr = 0, sum_ssim = 0, sum_decode = 0, sum_mbps = 0;
  double min_psnr = INFINITY, min_ssim = INFINITY;
  size_t min_psnr_pose = 0, min_ssim_pose = 0;
  std::vector<double> decode_ms, render_ms;
  uint32_t compared = 0, outside = 0;
  const std::vector<size_t> sheet_poses =
      a.contact_sheet.empty() ? std::vector<size_t>{}
                              : contact_sheet_poses(path.poses.size(), a.sheet_rows);
  std::vector<SheetTile> sheet;
  RenderedImage image, full_image;
  ClipComparison cc;
  for (size_t i = 0; i < path.poses.size();) {
    size_t j = i + 1;
    while (j < path.poses.size() && path.poses[j].time == path.poses[i].time) ++j;
    std::vector<Camera> eyes;
    for (size_t k = i; k < j; ++k) eyes.push_back(capture::camera_from_pose(path, k));
    const uint32_t frame = play.frame_at_time(path.poses[i].time);
    if (Status s = play.prepare(frame, eyes); !s.ok()) return fail(s);
    if (lossless != nullptr) {
      if (Status s = lossless->prepare(lossless->frame_at_time(path.poses[i].time), eyes); !s.ok())
        return fail(s);
    }
    if (breakdown_reader) {
      const capture::CaptureManifest& m = breakdown_reader->manifest();
      const uint32_t cf = capture::frame_at_time(path.poses[i].time, m.fps, m.frame_count);
      if (!visibility || visibility->frame() != cf) {
        auto v = CaptureVisibility::load(*breakdown_reader, cf);
        if (!v.ok()) return fail(v.status());
        visibility = std::move(*v);
      }
    }
    if (full != nullptr) {
      if (Status s = full->prepare(full->frame_at_time(path.poses[i].time), eyes); !s.ok())
        return fail(s);
    }
    const decoder::FrameStats st = lf != nullptr ? lf->last_stats() : decoder::FrameStats{};
    if (st.errors > 0) {
      std::fprintf(stderr,
                   "calf-play: warning: frame %u: %u damaged chunk(s), last good state "
                   "kept: %s\n",
                   frame, st.errors, st.first_error.c_str());
    }
    for (size_t k = i; k < j; ++k) {
      const Camera& cam = eyes[k - i];
      if (!play.inside_view_volume(cam.position) && outside++ == 0) {
        std::fprintf(stderr,
                     "calf-play: warning: pose %zu is outside the clip's view volume; "
                     "expect holes and stretched parallax\n",
                     k);
      }
      if (Status s = play.render(cam, &image); !s.ok()) return fail(s);
      char name[32];
      std::snprintf(name, sizeof name, "frame_%05zu", k);
      if (!a.out.empty()) {
        if (a.format == "png" || a.format == "both") {
          if (Status s = write_png(fs::path(a.out) / (std::string(name) + ".png"), rgb_ref(image));
              !s.ok())
            return fail(s);
        }
        if (a.format == "exr" || a.format == "both") {
          if (Status s = write_exr(fs::path(a.out) / (std::string(name) + ".exr"), image); !s.ok())
            return fail(s);
        }
      }
      const FrameFigures fig = play.figures();
      if (lf != nullptr) {
        std::printf(
            "pose %zu frame %u: %zu views, %u/%u cells, %.2f Mbps@24, decode %.2f ms, "
            "render %.1f ms",
            k, frame, lf->last_selection().active.size(), st.visible_cells, st.total_cells,
            st.mbps_at_24fps(), st.decode_ms, play.last_render_ms());
      } else if (fig.quads) {
        std::printf("pose %zu frame %u: %zu tiles, overdraw mean %.2f peak %u, render %.1f ms", k,
                    frame, fig.quads->count, fig.quads->mean_overdraw, fig.quads->peak_overdraw,
                    play.last_render_ms());
      } else {
        std::printf("pose %zu frame %u: %llu triangles, render %.1f ms", k, frame,
                    static_cast<unsigned long long>(fig.triangles_drawn), play.last_render_ms());
      }
      if (fig.points) {
        const FrameFigures::Points& pts = *fig.points;
        std::printf(", %llu surfels at %.2f px", static_cast<unsigned long long>(pts.drawn),
                    pts.point_size);
        if (a.surfel_foveation) std::printf(" (%u objects peripheral)", pts.peripheral_objects);
        // The passes the controller models apart, wall and process CPU time; its prediction.
        const SurfelPassTimes& pt = pts.passes;
        std::printf(" (passes: mesh %.1f + surfels %.1f ms; CPU %.1f + %.1f of %.1f ms)",
                    pt.mesh_ms, pt.surfels_ms, pt.mesh_cpu_ms, pt.surfels_cpu_ms, pt.frame_cpu_ms);
        if (a.surfel_target_ms > 0) std::printf(", predicted %.1f ms", pts.predicted_frame_ms);
        // Headless has no display: the render time stands for the frame time the point-size
        // controller follows (only when it has a target; not the first, which compiles shaders).
        if (a.surfel_target_ms > 0 && k > 0) {
          if (Status s = play.report_frame_time(play.last_render_ms()); !s.ok()) return fail(s);
        }
      }
      if (full != nullptr) {
        if (Status s = full->render(cam, &full_image); !s.ok()) return fail(s);
        auto eps = missing_geometry(image, full_image);
        if (!eps.ok()) return fail(eps.status());
        auto p = psnr(rgb_ref(image), rgb_ref(full_image));
        if (!p.ok()) return fail(p.status());
        auto s = ssim(rgb_ref(image), rgb_ref(full_image));
        if (!s.ok()) return fail(s.status());
        std::printf(", vs full (%.1f ms): epsilon %.4f %%, PSNR %.2f dB, SSIM %.4f",
                    full->last_render_ms(), 100 * eps->epsilon, *p, *s);
        cc.sum_eps += eps->epsilon;
        if (eps->epsilon > cc.max_eps || cc.count == 0)
          cc.max_eps = eps->epsilon, cc.max_eps_pose = k;
        cc.sum_psnr += std::min(*p, 100.0);
        cc.sum_ssim += *s;
        cc.min_psnr = std::min(cc.min_psnr, std::min(*p, 100.0));
        cc.min_ssim = std::min(cc.min_ssim, *s);
        cc.render_ms.push_back(full->last_render_ms());
        ++cc.count;
      }
      sum_decode += st.decode_ms;
      sum_mbps += st.mbps_at_24fps();
      decode_ms.push_back(st.decode_ms);
      render_ms.push_back(play.last_render_ms());
      if (!gt_dir.empty()) {
        auto gt = capture::read_perspective_image(gt_dir / capture::eye_image_file_name(path, k));
        if (!gt.ok()) return fail(gt.status());
        auto p = psnr(rgb_ref(image), rgb_ref(*gt));
        if (!p.ok()) return fail(p.status());
        auto s = ssim(rgb_ref(image), rgb_ref(*gt));
        if (!s.ok()) return fail(s.status());
        std::printf(", PSNR %.2f dB, SSIM %.4f", *p, *s);
        if (!floor_dir.empty()) {
          auto other = capture::read_perspective_image(floor_dir /
                                                       capture::eye_image_file_name(floor_path, k));
          if (!other.ok()) return fail(other.status());
          auto fp = psnr(rgb_ref(*gt), rgb_ref(*other));
          if (!fp.ok()) return fail(fp.status());
          auto fssim = ssim(rgb_ref(*gt), rgb_ref(*other));
          if (!fssim.ok()) return fail(fssim.status());
          const double clamped = std::min(*fp, 100.0);
          std::printf(" (noise floor %.2f dB, %.4f)", clamped, *fssim);
          floor_sum_psnr += clamped;
          floor_sum_ssim += *fssim;
          if (clamped < floor_min_psnr) floor_min_psnr = clamped, floor_min_pose = k;
        }
        sum_psnr += std::min(*p, 100.0);  // an exact frame counts as 100 dB, not infinity
        sum_ssim += *s;
        ++compared;
        if (std::min(*p, 100.0) < min_psnr) min_psnr = std::min(*p, 100.0), min_psnr_pose = k;
        if (*s < min_ssim) min_ssim = *s, min_ssim_pose = k;
        if (!a.out.empty() && a.heat_maps) {
          const fs::path heat = fs::path(a.out) / (std::string("heat_") + (name + 6) + ".png");
          if (Status hs = write_heat_map_png(heat, rgb_ref(image), rgb_ref(*gt)); !hs.ok())
            return fail(hs);
        }
        if (visibility) {
          if (lossless != nullptr) {
            if (Status ls = lossless->render(cam, &lossless_image); !ls.ok()) return fail(ls);
          }
          const RgbImageRef lossless_ref = rgb_ref(lossless_image);
          std::vector<uint8_t> classes;
          std::vector<float> squared;
          auto b = classify_errors(image, *gt, cam, *visibility,
                                   lossless != nullptr ? &lossless_ref : nullptr, {}, &classes,
                                   &squared);
          if (!b.ok()) return fail(b.status());
          std::printf(
              ", error: disocclusion %.1f %% silhouette %.1f %% geometry %.1f %% shading %.1f %%",
              100 * b->share(ErrorClass::kDisocclusion), 100 * b->share(ErrorClass::kSilhouette),
              100 * b->share(ErrorClass::kGeometry), 100 * b->share(ErrorClass::kShading));
          if (lossless != nullptr)
            std::printf(" codec %.1f %%", 100 * b->share(ErrorClass::kCodec));
          breakdown_sum += *b;
          if (!a.out.empty()) {
            const fs::path map = fs::path(a.out) / (std::string("classes_") + (name + 6) + ".png");
            if (Status ws = write_error_class_png(map, cam.width, cam.height, classes, squared);
                !ws.ok())
              return fail(ws);
          }
        }
        if (std::binary_search(sheet_poses.begin(), sheet_poses.end(), k)) {
          sheet.push_back({image, std::move(*gt)});
        }
      }
      std::printf("\n");
    }
    i = j;
  }
  const double n = static_cast<double>(path.poses.size());
  // The first render compiles shaders and fills caches: it is reported apart from the rest.
  const double first_render = render_ms.empty() ? 0 : render_ms.front();
  const double later_render =
      render_ms.size() > 1 ? median({render_ms.begin() + 1, render_ms.end()}) : first_render;
  std::printf(
      "%zu poses: mean decode %.2f ms (median %.2f), render first %.1f ms then median "
      "%.1f ms, mean %.2f Mbps@24\n",
      path.poses.size(), sum_decode / n, median(decode_ms), first_render, later_render,
      sum_mbps / n);
  if (cc.count > 0) {
    const double full_first = cc.render_ms.front();
    const double full_later = cc.render_ms.size() > 1
                                  ? median({cc.render_ms.begin() + 1, cc.render_ms.end()})
                                  : full_first;
    std::printf(
        "against the full scene (%u poses): epsilon mean %.4f %% max %.4f %% (pose %zu); PSNR mean "
        "%.2f dB min %.2f dB (an identical pose counts as 100 dB); SSIM mean %.4f min %.4f\n",
        cc.count, 100 * cc.sum_eps / cc.count, 100 * cc.max_eps, cc.max_eps_pose,
        cc.sum_psnr / cc.count, cc.min_psnr, cc.sum_ssim / cc.count, cc.min_ssim);
    std::printf(
        "frame time (median render after the first): %.1f ms this clip, %.1f ms full scene\n",
        later_render, full_later);
  }
  if (compared > 0) {
    std::printf("mean PSNR %.2f dB, mean SSIM %.4f\n", sum_psnr / compared, sum_ssim / compared);
    std::printf("worst pose: PSNR %.2f dB (pose %zu), SSIM %.4f (pose %zu)\n", min_psnr,
                min_psnr_pose, min_ssim, min_ssim_pose);
    if (visibility) {
      const ErrorBreakdown& b = breakdown_sum;
      std::printf(
          "error breakdown (share of the squared error over all poses; share of the pixels): "
          "disocclusion %.1f %% (%.1f %%), silhouette %.1f %% (%.1f %%), geometry %.1f %% "
          "(%.1f %%), shading %.1f %% (%.1f %%), ",
          100 * b.share(ErrorClass::kDisocclusion), 100 * b.pixel_share(ErrorClass::kDisocclusion),
          100 * b.share(ErrorClass::kSilhouette), 100 * b.pixel_share(ErrorClass::kSilhouette),
          100 * b.share(ErrorClass::kGeometry), 100 * b.pixel_share(ErrorClass::kGeometry),
          100 * b.share(ErrorClass::kShading), 100 * b.pixel_share(ErrorClass::kShading));
      if (b.codec_measured) {
        std::printf("codec %.1f %% (%.1f %%)\n", 100 * b.share(ErrorClass::kCodec),
                    100 * b.pixel_share(ErrorClass::kCodec));
      } else {
        std::printf("codec not measured (give --breakdown-lossless)\n");
      }
    }
    if (!floor_dir.empty()) {
      std::printf(
          "noise floor (ground truth against %s, another seed): mean PSNR %.2f dB, mean SSIM "
          "%.4f, lowest %.2f dB (pose %zu)\n",
          floor_dir.string().c_str(), floor_sum_psnr / compared, floor_sum_ssim / compared,
          floor_min_psnr, floor_min_pose);
    } else {
      std::printf(
          "noise floor: unknown (no %s/%s: calf-capture --ground-truth writes it, or give "
          "--noise-floor)\n",
          gt_dir.string().c_str(), capture::kNoiseFloorDirName);
    }
  }
  if (!sheet.empty()) {
    std::vector<ContactSheetRow> rows;
    for (const SheetTile& t : sheet) rows.push_back({rgb_ref(t.ground_truth), rgb_ref(t.rendered)});
    auto composed = compose_contact_sheet(rows);
    if (!composed.ok()) return fail(composed.status());
    if (Status s = write_png_rgb8(a.contact_sheet, *composed); !s.ok()) return fail(s);
    std::printf(
        "contact sheet: %s (%zu poses; ground truth | calf | error heat map, red = "
        "error 0.1 of full scale or more)\n",
        a.contact_sheet.c_str(), rows.size());
  }
  return 0;
}

// The names of the enum options: one table each (the first entry is no default: the options
// structs hold the defaults).
constexpr tools::EnumTable<bool, 2> kRenderers = {{{"gl", true}, {"cpu", false}}};
constexpr tools::EnumTable<ViewPriority, 2> kViewPriorities = {
    {{"distance", ViewPriority::kDistance}, {"angle", ViewPriority::kAngle}}};
constexpr tools::EnumTable<SurfelClock, 2> kSurfelClocks = {
    {{"wall", SurfelClock::kWall}, {"cpu", SurfelClock::kCpu}}};

}  // namespace

static int command_main(int argc, char** argv) {
  CLI::App app{
      "calf-play: play a .calf clip: lightfield tracks (paper 002 Sec. 6) by ray-march "
      "reconstruction from the nearest viewpoints' colour + depth cube maps, decoded "
      "view-dependently; mesh tracks (paper 004: a full scene or its visible set) by "
      "rasterising their triangles; composited by depth.\n"
      "Window: drag to look, WASD/QE to fly, O orbit, R reflections/refractions (RR), C coverage "
      "on/off (--coverage's mode, else 3), V priority, +/- active views, Shift+S stereo, space "
      "pause, H HUD, Esc quit.\n"
      "Headless (--headless): renders an eye path (calf-capture writes one with --ground-truth) "
      "through OSMesa, writes frames to --out and, with --compare, prints PSNR / SSIM per pose "
      "and a final 'mean PSNR <x> dB, mean SSIM <y>' line; with --compare-clip FULL.calf it "
      "compares with the full scene instead (epsilon, PSNR, SSIM, frame times). Output files "
      "(frames, heat maps, "
      "contact sheet) are written whole; an existing directory, FIFO, device or symbolic link "
      "in their place is refused (CALF-E004).\n" +
      std::string(tools::kExitStatusHelp)};
  std::string clip;
  HeadlessArgs h;
  bool headless = false;
  PlaybackOptions play_options;
  LightfieldOptions& o =
      play_options.of<LightfieldOptions>();  // the knobs below are the light field's
  WindowOptions w;
  // Every default --help shows is the value the options structs hold.
  app.option_defaults()->always_capture_default();
  app.add_option("CLIP", clip,
                 "the .calf file: every lightfield and mesh track is played, composited by depth")
      ->required();
  app.add_flag("--headless", headless,
               "render --eye-path (or the --compare directory's path) "
               "without a window, through OSMesa");
  app.add_option("--eye-path", h.eye_path,
                 "eye-path JSON (format/CAPTURE.md) to render; default "
                 "with --compare: GT_DIR/eye_path.json");
  app.add_option("--out", h.out,
                 "directory for rendered frames (frame_NNNNN.png / .exr) and error "
                 "heat maps (heat_NNNNN.png)");
  app.add_option("--format", h.format,
                 "frame files: png (8-bit sRGB), exr (half RGB + float Z, "
                 "the ground-truth layout) or both")
      ->check(CLI::IsMember({"png", "exr", "both"}));
  app.add_option("--compare", h.compare,
                 "ground-truth directory written by calf-capture "
                 "--ground-truth: per-pose PSNR / SSIM and heat maps");
  app.add_flag("!--no-heat-maps", h.heat_maps, "with --compare and --out: do not write heat maps");
  app.add_option("--noise-floor", h.noise_floor,
                 "with --compare: ground truth of the same eye path rendered with another seed; "
                 "its PSNR / SSIM against GT_DIR (the noise floor, what no figure can measure "
                 "below) is printed beside every figure (default: GT_DIR/noise-floor, which "
                 "calf-capture --ground-truth writes, when it exists)");
  app.add_option("--compare-clip", h.compare_clip,
                 "headless: also play FULL.calf (the full scene of a visible-set clip) along the "
                 "same eye path with the same renderer and print per pose and overall epsilon "
                 "(paper 004: the share of pixels whose depth lies farther than the full scene's "
                 "by more than 0.1 %, i.e. where a triangle is missing), PSNR and SSIM against it, "
                 "and the frame time of both");
  app.add_option("--breakdown", h.breakdown,
                 "with --compare: the capture set (manifest directory) the clip was made from; "
                 "each pose's squared error is split into disocclusion (the ground truth's "
                 "surface was seen by no capture view), silhouette (a depth edge within 1 pixel), "
                 "geometry (the clip shows another surface: its depth is off by more than 2 %) "
                 "and shading (the rest), printed per pose and over the path, with class maps "
                 "(classes_NNNNN.png: red, yellow, magenta, blue, codec green; brightness the "
                 "error) in --out "
                 "(docs/PLAYER.md \"Error breakdown\")");
  app.add_option(
      "--breakdown-lossless", h.breakdown_lossless,
      "with --breakdown: a lossless clip of the same capture (calf-encode --color-format "
      "rgba16f --depth-format raw16) rendered at every pose too; the error CLIP adds to it is "
      "the codec class (green)");
  app.add_option("--contact-sheet", h.contact_sheet,
                 "with --compare: write a PNG with one row per "
                 "pose: ground truth | calf | error heat map");
  app.add_option("--sheet-rows", h.sheet_rows,
                 "poses on the contact sheet, spread evenly along "
                 "the path, first and last included")
      ->check(CLI::Range(1, 256));
  SurfelOptions& so = play_options.of<SurfelOptions>();
  app.add_option("--surfel-point-size", so.point_size,
                 "surfels: disc diameter in pixels the prefixes are chosen for (the start value "
                 "with --surfel-target-ms), 1..64")
      ->check(CLI::Range(1.0, 64.0));
  app.add_option("--surfel-target-ms", so.target_frame_ms,
                 "surfels: frame-time target in ms, > 0 and <= 10000; the point size follows it "
                 "between 1 and 16 px (headless: each pose's render time counts as its frame "
                 "time); left out: a fixed point size")
      ->default_str("");
  tools::add_enum_option(app, "--surfel-clock", so.controller_clock, kSurfelClocks,
                         "surfels: the time --surfel-target-ms holds: wall (the frame time) or "
                         "cpu (the process CPU time of the renders, all threads; steadier on a "
                         "loaded machine)");
  app.add_option("--surfel-blend", so.blend_share,
                 "surfels: an object whose prefix needs more than this share of its surfels is "
                 "drawn from the mesh as well (0..1; 1: no blend zone)")
      ->check(CLI::Range(0.0, 1.0));
  std::vector<double> foveation;
  app.add_option("--surfel-foveation", foveation,
                 "surfels: fixed foveated rendering (paper 001 Sec. 4.4) as INNER,OUTER,SCALE: "
                 "an object whose centre lies within INNER of the image centre (in units of the "
                 "half-diagonal: 1 at the corners) keeps the point size, beyond OUTER it is "
                 "SCALE times larger (a shorter prefix), linear between; e.g. 0.35,0.75,2; left "
                 "out: off")
      ->default_str("")
      ->expected(3)
      ->delimiter(',');
  std::string tiles_blend = "sort";
  app.add_option("--tiles-blend", tiles_blend,
                 "tiles: sort (back to front by distance from the eye each frame, premultiplied "
                 "over; paper 000) or alpha-test (depth test, texels below 50 % alpha dropped, "
                 "any order; hard silhouettes)")
      ->check(CLI::IsMember({"sort", "alpha-test"}));
  TilesRenderOptions& tr = play_options.of<TilesOptions>().render;
  app.add_option("--tiles-occlusion-alpha", tr.occlusion_alpha,
                 "tiles, sort: an occlusion pre-pass keeps each pixel's nearest fragment at least "
                 "this opaque, and the sorted pass drops fragments behind it (what one sort "
                 "distance per tile gets wrong where tiles cross or abut at an angle); 0.5..1, "
                 "or 0 for none (Seurat's plain sort; about half the render time)");
  app.add_option("--tiles-occlusion-epsilon", tr.occlusion_epsilon,
                 "tiles, sort: how much farther (relative) than that fragment another must be to "
                 "be dropped, so overlapping tiles of one surface never hide each other; (0, 1]");
  tools::add_enum_option(app, "--renderer", play_options.use_gl, kRenderers,
                         "gl (OpenGL 4.5 ray-march, the product) or cpu (the scalar reference; "
                         "headless only)");
  app.add_option("--steps", o.render.steps, "ray-march steps in log depth")
      ->check(CLI::Range(1, 65536));
  app.add_flag("--rr", o.render.rr,
               "reflection / refraction rays from the material stream "
               "(Alg. 4 _RR); ignored with a notice when the clip has no material");
  app.add_flag("!--no-rr-replace", o.render.rr_replace_view_reflection,
               "with --rr: Alg. 4 as written, c = w c_rfl + ... + (1 - w) c_blend, instead of the "
               "default: the best view's colour with its own reflection / refraction replaced by "
               "the eye's (docs/RENDERING.md)");
  app.add_option("--hints", o.render.surface_hints,
                 "surface hint views followed along the march "
                 "(0 = the paper's march alone)")
      ->check(CLI::Range(0, 4));
  app.add_option("--hint-substeps", o.render.surface_hint_substeps, "hint tests per march step")
      ->check(CLI::Range(1, 64));
  app.add_option("--mixed-texel-penalty", o.render.mixed_texel_penalty,
                 "light field: colour taps on a depth edge of their view (an anti-aliased "
                 "capture mixes both sides' colours there) keep e^-P of their weight, so colour "
                 "comes from texels wholly on one surface; 0..50, 0 = off (docs/RENDERING.md "
                 "\"Mixed texels\")")
      ->check(CLI::Range(0.0, 50.0));
  app.add_option("--coverage", o.render.coverage,
                 "light field: how the renderer (GL or CPU) uses a clip's coverage stream (SPEC "
                 "11.1.11) in its emptiness test, as bench-player_quality --coverage uses a "
                 "capture set's: 0 off, 1 bilinear front shares, 2 cell mask, 3 grown cell mask, 4 "
                 "every tap's cell; "
                 "clips without coverage play as with 0; the window's C key toggles it")
      ->check(CLI::Range(0u, 4u));
  app.add_option("--coverage-agreement", o.render.coverage_agreement,
                 "light field, with --coverage: a point that a view calls empty only through its "
                 "coverage is empty once this many views say so")
      ->check(CLI::Range(1u, 65536u));
  app.add_option(
         "--hint-coverage", o.render.surface_hint_coverage,
         "light field, with coverage: a surface hint's crossing ends the ray only where the "
         "hint view's coverage covers the ray's direction in its texel (the direction's "
         "cell): 0 off, 1 on")
      ->check(CLI::Range(0u, 1u));
  app.add_option("--supersample", o.render.supersample,
                 "light field: N x N eye rays per pixel on an even grid, colour their mean (a box "
                 "filter, as the ground truth's), depth the nearest; anti-aliases silhouettes and "
                 "texture edges for N^2 the render time (1: the pixel centre's ray)")
      ->check(CLI::Range(1, 8));
  app.add_option("--views", o.selection.max_active, "most active viewpoints per frame")
      ->check(CLI::Range(1, 65536));
  tools::add_enum_option(app, "--priority", o.selection.priority, kViewPriorities,
                         "view priority: distance or angle");
  app.add_option("--frame-ms", o.selection.budget.target_frame_ms,
                 "frame-time target of performance "
                 "culling in ms, 0 = off (headless: 0 unless given, quality first)");
  app.add_flag(
      "--no-view-dependent", [&](int64_t) { o.decoder.view_dependent = false; },
      "decode every cell of the active views, not only the visible ones");
  app.add_option("--width", w.width, "window width");
  app.add_option("--height", w.height, "window height");
  app.add_option("--fov", w.fov_y_degrees, "window: vertical field of view in degrees")
      ->check(CLI::Range(10.0, 170.0));
  app.add_flag("--stereo", w.stereo, "window: side-by-side stereo (toggle with Shift+S)");
  app.add_option("--ipd", w.ipd, "window: distance between the eyes in scene units");
  app.add_option("--frames", w.max_frames, "window: quit after this many frames (0 = never)");
  // --help groups the options by what they act on.
  const auto group = [&app](const char* name, std::initializer_list<const char*> options) {
    for (const char* option : options) app.get_option(option)->group(name);
  };
  group(
      "Headless evaluation (--headless)",
      {"--eye-path", "--out", "--format", "--compare", "--no-heat-maps", "--noise-floor",
       "--compare-clip", "--breakdown", "--breakdown-lossless", "--contact-sheet", "--sheet-rows"});
  group("Light field renderer", {"--steps", "--rr", "--no-rr-replace", "--hints", "--hint-substeps",
                                 "--mixed-texel-penalty", "--supersample", "--views", "--priority",
                                 "--frame-ms", "--no-view-dependent"});
  group("Light field coverage", {"--coverage", "--coverage-agreement", "--hint-coverage"});
  group("Surfels", {"--surfel-point-size", "--surfel-target-ms", "--surfel-clock", "--surfel-blend",
                    "--surfel-foveation"});
  group("Tiles", {"--tiles-blend", "--tiles-occlusion-alpha", "--tiles-occlusion-epsilon"});
  group("Window", {"--width", "--height", "--fov", "--stereo", "--ipd", "--frames"});
  if (int rc = tools::parse_command_line(app, "calf-play", argc, argv); rc >= 0) return rc;

  tr.blend = *tiles_blend_from_name(tiles_blend);  // checked above
  if (Status st = validate_tiles_render_options(tr); !st.ok()) {
    return tools::print_error("calf-play", st, tools::kExitUsage);  // CALF-E478, exit 2
  }
  if (app.count("--surfel-target-ms") > 0 &&
      !(so.target_frame_ms > 0 && so.target_frame_ms <= 10000)) {
    return contradiction("--surfel-target-ms " + std::to_string(so.target_frame_ms) +
                         " is not a frame time in (0, 10000] ms (leave it out for a fixed "
                         "point size)");
  }
  if (!foveation.empty()) {
    so.foveation = {.enabled = true,
                    .inner = foveation[0],
                    .outer = foveation[1],
                    .periphery_scale = foveation[2]};
    if (Status s = validate_surfel_options(so); !s.ok()) {
      return tools::print_error("calf-play", s, tools::kExitUsage);
    }
  }
  if (headless && app.count("--frame-ms") == 0) o.selection.budget.target_frame_ms = 0;
  if (headless) {
    if (h.eye_path.empty() && h.compare.empty()) {
      return contradiction("--headless needs --eye-path or --compare");
    }
    if (!h.contact_sheet.empty() && h.compare.empty()) {
      return contradiction("--contact-sheet needs --compare");
    }
    if (!h.noise_floor.empty() && h.compare.empty()) {
      return contradiction("--noise-floor needs --compare");
    }
    if (!h.breakdown.empty() && h.compare.empty()) {
      return contradiction("--breakdown needs --compare");
    }
    if (!h.breakdown_lossless.empty() && h.breakdown.empty()) {
      return contradiction("--breakdown-lossless needs --breakdown");
    }
    if (!h.compare_clip.empty() && fs::path(h.compare_clip) == fs::path(clip)) {
      return contradiction("--compare-clip names CLIP itself");
    }
    std::unique_ptr<OsMesaContext> context;
    const GlFunctions* gl = nullptr;
    if (play_options.use_gl) {
      auto c = OsMesaContext::make();
      if (!c.ok()) return fail(c.status());
      context = std::move(*c);
      gl = &context->gl();
    }
    auto play = Playback::open(clip, play_options, gl);
    if (!play.ok()) return fail(play.status());
    std::unique_ptr<Playback> full;
    if (!h.compare_clip.empty()) {
      auto f = Playback::open(h.compare_clip, play_options, gl);
      if (!f.ok()) return fail(f.status());
      full = std::move(*f);
    }
    std::unique_ptr<Playback> lossless;
    if (!h.breakdown_lossless.empty()) {
      auto f = Playback::open(h.breakdown_lossless, play_options, gl);
      if (!f.ok()) return fail(f.status());
      lossless = std::move(*f);
    }
    h.surfel_target_ms = so.target_frame_ms;
    h.surfel_foveation = so.foveation.enabled;
    return run_headless(**play, full.get(), lossless.get(), h);
  }
  if (!h.breakdown.empty()) {
    return contradiction("--breakdown works only with --headless");
  }
  if (!h.compare_clip.empty()) {
    return contradiction("--compare-clip works only with --headless");
  }
  if (!play_options.use_gl) {
    return contradiction("--renderer cpu works only with --headless");
  }
  if (!h.contact_sheet.empty()) {
    return contradiction("--contact-sheet works only with --headless");
  }
  if (Status s = run_window(clip, play_options, w); !s.ok()) return fail(s);
  return 0;
}

int main(int argc, char** argv) {
  return calf::tools::run_command("calf-play", [&] { return command_main(argc, argv); });
}
