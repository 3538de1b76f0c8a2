#include "calf/player/headless_session.h"

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <utility>

#include "calf/player/contact_sheet.h"
#include "calf/player/image_compare.h"

namespace calf::player {

namespace fs = std::filesystem;

namespace {

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

// Per-pose figures of the clip against the full-scene clip.
struct ClipComparison {
  double sum_eps = 0, max_eps = 0, sum_psnr = 0, sum_ssim = 0;
  double min_psnr = INFINITY, min_ssim = INFINITY;
  size_t max_eps_pose = 0;
  uint32_t count = 0;
  std::vector<double> render_ms;  // the full-scene clip's
};

// printf-style text into a sink.
class Writer {
 public:
  explicit Writer(const std::function<void(std::string_view)>& sink) : sink_(sink) {}
  __attribute__((format(printf, 2, 3))) void operator()(const char* format, ...) const {
    if (!sink_) return;
    va_list args, again;
    va_start(args, format);
    va_copy(again, args);
    const int n = std::vsnprintf(nullptr, 0, format, args);
    va_end(args);
    std::string text(n > 0 ? static_cast<size_t>(n) : 0, '\0');
    if (n > 0) std::vsnprintf(text.data(), text.size() + 1, format, again);
    va_end(again);
    sink_(text);
  }

 private:
  const std::function<void(std::string_view)>& sink_;
};

}  // namespace

struct HeadlessSession::Impl {
  Playback* play = nullptr;
  Playback* full = nullptr;
  Playback* lossless = nullptr;
  HeadlessSessionOptions options;
  capture::EyePath path;
  fs::path floor_dir;
  capture::EyePath floor_path;
  std::unique_ptr<capture::CaptureSetReader> breakdown_reader;
};

HeadlessSession::HeadlessSession(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
HeadlessSession::HeadlessSession(HeadlessSession&&) noexcept = default;
HeadlessSession& HeadlessSession::operator=(HeadlessSession&&) noexcept = default;
HeadlessSession::~HeadlessSession() = default;

const capture::EyePath& HeadlessSession::eye_path() const {
  return impl_->path;
}

Expected<HeadlessSession> HeadlessSession::open(Playback& play, Playback* full, Playback* lossless,
                                                const HeadlessSessionOptions& a) {
  auto d = std::make_unique<Impl>();
  d->play = &play;
  d->full = full;
  d->lossless = lossless;
  d->options = a;
  const fs::path& gt_dir = a.compare;
  if (a.eye_path.empty() && gt_dir.empty()) {
    return Status(ErrorId::kPlaybackOption, "a headless session needs an eye path or ground truth");
  }
  const fs::path path_file = !a.eye_path.empty() ? a.eye_path : gt_dir / capture::kEyePathFileName;
  CALF_ASSIGN_OR_RETURN(d->path, capture::read_eye_path(path_file));
  if (!gt_dir.empty() && d->path.image_pattern.empty()) {
    return Status(ErrorId::kPlaybackOption,
                  path_file.string() + " names no ground-truth images to compare with");
  }
  // The noise floor: the ground truth against the same poses rendered with another seed
  // (format/CAPTURE.md, "Noise floor"); no figure measures the reconstruction more finely.
  if (!gt_dir.empty()) {
    std::error_code ec;
    if (!a.noise_floor.empty()) {
      d->floor_dir = a.noise_floor;
    } else if (fs::exists(gt_dir / capture::kNoiseFloorDirName / capture::kEyePathFileName, ec)) {
      d->floor_dir = gt_dir / capture::kNoiseFloorDirName;
    }
  }
  if (!d->floor_dir.empty()) {
    CALF_ASSIGN_OR_RETURN(d->floor_path,
                          capture::read_eye_path(d->floor_dir / capture::kEyePathFileName));
    const capture::EyePath& f = d->floor_path;
    if (f.image_pattern.empty() || f.poses != d->path.poses || f.width != d->path.width ||
        f.height != d->path.height) {
      return Status(ErrorId::kPlaybackOption,
                    (d->floor_dir / capture::kEyePathFileName).string() +
                        " is not ground truth of the same poses and image size");
    }
  }
  // The error breakdown: the capture set's views at the frame of each pose, loaded once a frame.
  if (!a.breakdown.empty()) {
    CALF_ASSIGN_OR_RETURN(capture::CaptureSetReader r,
                          capture::CaptureSetReader::open(a.breakdown));
    d->breakdown_reader = std::make_unique<capture::CaptureSetReader>(std::move(r));
  }
  if (!a.out.empty()) {
    std::error_code ec;
    fs::create_directories(a.out, ec);
    if (ec) return Status(ErrorId::kFileWrite, a.out.string() + ": " + ec.message());
  }
  return HeadlessSession(std::move(d));
}

Expected<HeadlessSummary> HeadlessSession::run(const HeadlessSinks& sinks) {
  Impl& d = *impl_;
  Playback& play = *d.play;
  Playback* const full = d.full;
  Playback* const lossless = d.lossless;
  const HeadlessSessionOptions& a = d.options;
  const capture::EyePath& path = d.path;
  const fs::path& gt_dir = a.compare;
  const fs::path& floor_dir = d.floor_dir;
  const Writer print(sinks.report);
  const Writer notice(sinks.notice);
  HeadlessSummary summary;

  std::optional<CaptureVisibility> visibility;
  ErrorBreakdown breakdown_sum;
  RenderedImage lossless_image;
  double floor_sum_psnr = 0, floor_sum_ssim = 0, floor_min_psnr = INFINITY;
  size_t floor_min_pose = 0;
  // The light-field figures reported per pose are the first lightfield track's (if any).
  const LightfieldRepresentation* lf = play.lightfield();
  if (lf != nullptr && lf->options().render.rr && !lf->has_material()) {
    notice("notice: the clip has no material stream; --rr is ignored");
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
  const bool png = a.frame_files != FrameFiles::kExr, exr = a.frame_files != FrameFiles::kPng;
  for (size_t i = 0; i < path.poses.size();) {
    size_t j = i + 1;
    while (j < path.poses.size() && path.poses[j].time == path.poses[i].time) ++j;
    std::vector<Camera> eyes;
    for (size_t k = i; k < j; ++k) eyes.push_back(capture::camera_from_pose(path, k));
    const uint32_t frame = play.frame_at_time(path.poses[i].time);
    CALF_RETURN_IF_ERROR(play.prepare(frame, eyes));
    if (lossless != nullptr) {
      CALF_RETURN_IF_ERROR(lossless->prepare(lossless->frame_at_time(path.poses[i].time), eyes));
    }
    if (d.breakdown_reader) {
      const capture::CaptureManifest& m = d.breakdown_reader->manifest();
      const uint32_t cf = capture::frame_at_time(path.poses[i].time, m.fps, m.frame_count);
      if (!visibility || visibility->frame() != cf) {
        CALF_ASSIGN_OR_RETURN(CaptureVisibility v,
                              CaptureVisibility::load(*d.breakdown_reader, cf));
        visibility = std::move(v);
      }
    }
    if (full != nullptr) {
      CALF_RETURN_IF_ERROR(full->prepare(full->frame_at_time(path.poses[i].time), eyes));
    }
    const decoder::FrameStats st = lf != nullptr ? lf->last_stats() : decoder::FrameStats{};
    if (st.errors > 0) {
      notice("warning: frame %u: %u damaged chunk(s), last good state kept: %s", frame, st.errors,
             st.first_error.c_str());
    }
    for (size_t k = i; k < j; ++k) {
      const Camera& cam = eyes[k - i];
      if (!play.inside_view_volume(cam.position) && outside++ == 0) {
        notice(
            "warning: pose %zu is outside the clip's view volume; expect holes and stretched "
            "parallax",
            k);
      }
      CALF_RETURN_IF_ERROR(play.render(cam, &image));
      HeadlessPose record{.pose = k, .frame = frame, .render_ms = play.last_render_ms()};
      char name[32];
      std::snprintf(name, sizeof name, "frame_%05zu", k);
      if (!a.out.empty()) {
        if (png) {
          CALF_RETURN_IF_ERROR(write_png(a.out / (std::string(name) + ".png"), rgb_ref(image)));
          ++summary.files_written;
        }
        if (exr) {
          CALF_RETURN_IF_ERROR(write_exr(a.out / (std::string(name) + ".exr"), image));
          ++summary.files_written;
        }
      }
      const FrameFigures fig = play.figures();
      if (lf != nullptr) {
        print(
            "pose %zu frame %u: %zu views, %u/%u cells, %.2f Mbps@24, decode %.2f ms, "
            "render %.1f ms",
            k, frame, lf->last_selection().active.size(), st.visible_cells, st.total_cells,
            st.mbps_at_24fps(), st.decode_ms, play.last_render_ms());
      } else if (fig.quads) {
        print("pose %zu frame %u: %zu tiles, overdraw mean %.2f peak %u, render %.1f ms", k, frame,
              fig.quads->count, fig.quads->mean_overdraw, fig.quads->peak_overdraw,
              play.last_render_ms());
      } else {
        print("pose %zu frame %u: %llu triangles, render %.1f ms", k, frame,
              static_cast<unsigned long long>(fig.triangles_drawn), play.last_render_ms());
      }
      if (fig.points) {
        const FrameFigures::Points& pts = *fig.points;
        print(", %llu surfels at %.2f px", static_cast<unsigned long long>(pts.drawn),
              pts.point_size);
        if (a.surfel_foveation) print(" (%u objects peripheral)", pts.peripheral_objects);
        // The passes the controller models apart, wall and process CPU time; its prediction.
        const SurfelPassTimes& pt = pts.passes;
        print(" (passes: mesh %.1f + surfels %.1f ms; CPU %.1f + %.1f of %.1f ms)", pt.mesh_ms,
              pt.surfels_ms, pt.mesh_cpu_ms, pt.surfels_cpu_ms, pt.frame_cpu_ms);
        if (a.surfel_target_ms > 0) print(", predicted %.1f ms", pts.predicted_frame_ms);
        // Headless has no display: the render time stands for the frame time the point-size
        // controller follows (only when it has a target; not the first, which compiles shaders).
        if (a.surfel_target_ms > 0 && k > 0) {
          CALF_RETURN_IF_ERROR(play.report_frame_time(play.last_render_ms()));
        }
      }
      if (full != nullptr) {
        CALF_RETURN_IF_ERROR(full->render(cam, &full_image));
        CALF_ASSIGN_OR_RETURN(const MissingGeometry eps, missing_geometry(image, full_image));
        CALF_ASSIGN_OR_RETURN(const double p, psnr(rgb_ref(image), rgb_ref(full_image)));
        CALF_ASSIGN_OR_RETURN(const double s, ssim(rgb_ref(image), rgb_ref(full_image)));
        print(", vs full (%.1f ms): epsilon %.4f %%, PSNR %.2f dB, SSIM %.4f",
              full->last_render_ms(), 100 * eps.epsilon, p, s);
        cc.sum_eps += eps.epsilon;
        if (eps.epsilon > cc.max_eps || cc.count == 0)
          cc.max_eps = eps.epsilon, cc.max_eps_pose = k;
        cc.sum_psnr += std::min(p, 100.0);
        cc.sum_ssim += s;
        cc.min_psnr = std::min(cc.min_psnr, std::min(p, 100.0));
        cc.min_ssim = std::min(cc.min_ssim, s);
        cc.render_ms.push_back(full->last_render_ms());
        ++cc.count;
      }
      sum_decode += st.decode_ms;
      sum_mbps += st.mbps_at_24fps();
      decode_ms.push_back(st.decode_ms);
      render_ms.push_back(play.last_render_ms());
      if (!gt_dir.empty()) {
        CALF_ASSIGN_OR_RETURN(
            capture::PerspectiveImage gt,
            capture::read_perspective_image(gt_dir / capture::eye_image_file_name(path, k)));
        CALF_ASSIGN_OR_RETURN(const double p, psnr(rgb_ref(image), rgb_ref(gt)));
        CALF_ASSIGN_OR_RETURN(const double s, ssim(rgb_ref(image), rgb_ref(gt)));
        print(", PSNR %.2f dB, SSIM %.4f", p, s);
        if (!floor_dir.empty()) {
          CALF_ASSIGN_OR_RETURN(const capture::PerspectiveImage other,
                                capture::read_perspective_image(
                                    floor_dir / capture::eye_image_file_name(d.floor_path, k)));
          CALF_ASSIGN_OR_RETURN(const double fp, psnr(rgb_ref(gt), rgb_ref(other)));
          CALF_ASSIGN_OR_RETURN(const double fssim, ssim(rgb_ref(gt), rgb_ref(other)));
          const double clamped = std::min(fp, 100.0);
          print(" (noise floor %.2f dB, %.4f)", clamped, fssim);
          floor_sum_psnr += clamped;
          floor_sum_ssim += fssim;
          if (clamped < floor_min_psnr) floor_min_psnr = clamped, floor_min_pose = k;
        }
        record.psnr = std::min(p, 100.0);  // an exact frame counts as 100 dB, not infinity
        record.ssim = s;
        sum_psnr += record.psnr;
        sum_ssim += s;
        ++compared;
        if (record.psnr < min_psnr) min_psnr = record.psnr, min_psnr_pose = k;
        if (s < min_ssim) min_ssim = s, min_ssim_pose = k;
        if (!a.out.empty() && a.heat_maps) {
          const fs::path heat = a.out / (std::string("heat_") + (name + 6) + ".png");
          CALF_RETURN_IF_ERROR(write_heat_map_png(heat, rgb_ref(image), rgb_ref(gt)));
          ++summary.files_written;
        }
        if (visibility) {
          if (lossless != nullptr) {
            CALF_RETURN_IF_ERROR(lossless->render(cam, &lossless_image));
          }
          const RgbImageRef lossless_ref = rgb_ref(lossless_image);
          std::vector<uint8_t> classes;
          std::vector<float> squared;
          CALF_ASSIGN_OR_RETURN(const ErrorBreakdown b,
                                classify_errors(image, gt, cam, *visibility,
                                                lossless != nullptr ? &lossless_ref : nullptr, {},
                                                &classes, &squared));
          print(", error: disocclusion %.1f %% silhouette %.1f %% geometry %.1f %% shading %.1f %%",
                100 * b.share(ErrorClass::kDisocclusion), 100 * b.share(ErrorClass::kSilhouette),
                100 * b.share(ErrorClass::kGeometry), 100 * b.share(ErrorClass::kShading));
          if (lossless != nullptr) print(" codec %.1f %%", 100 * b.share(ErrorClass::kCodec));
          breakdown_sum += b;
          if (!a.out.empty()) {
            const fs::path map = a.out / (std::string("classes_") + (name + 6) + ".png");
            CALF_RETURN_IF_ERROR(
                write_error_class_png(map, cam.width, cam.height, classes, squared));
            ++summary.files_written;
          }
        }
        if (std::binary_search(sheet_poses.begin(), sheet_poses.end(), k)) {
          sheet.push_back({image, std::move(gt)});
        }
      }
      print("\n");
      summary.poses.push_back(record);
    }
    i = j;
  }
  const double n = static_cast<double>(path.poses.size());
  // The first render compiles shaders and fills caches: it is reported apart from the rest.
  const double first_render = render_ms.empty() ? 0 : render_ms.front();
  const double later_render =
      render_ms.size() > 1 ? median({render_ms.begin() + 1, render_ms.end()}) : first_render;
  print(
      "%zu poses: mean decode %.2f ms (median %.2f), render first %.1f ms then median "
      "%.1f ms, mean %.2f Mbps@24\n",
      path.poses.size(), sum_decode / n, median(decode_ms), first_render, later_render,
      sum_mbps / n);
  if (cc.count > 0) {
    const double full_first = cc.render_ms.front();
    const double full_later = cc.render_ms.size() > 1
                                  ? median({cc.render_ms.begin() + 1, cc.render_ms.end()})
                                  : full_first;
    print(
        "against the full scene (%u poses): epsilon mean %.4f %% max %.4f %% (pose %zu); PSNR mean "
        "%.2f dB min %.2f dB (an identical pose counts as 100 dB); SSIM mean %.4f min %.4f\n",
        cc.count, 100 * cc.sum_eps / cc.count, 100 * cc.max_eps, cc.max_eps_pose,
        cc.sum_psnr / cc.count, cc.min_psnr, cc.sum_ssim / cc.count, cc.min_ssim);
    print("frame time (median render after the first): %.1f ms this clip, %.1f ms full scene\n",
          later_render, full_later);
  }
  if (compared > 0) {
    summary.compared = compared;
    summary.mean_psnr = sum_psnr / compared;
    summary.mean_ssim = sum_ssim / compared;
    summary.min_psnr = min_psnr;
    summary.min_ssim = min_ssim;
    summary.min_psnr_pose = min_psnr_pose;
    summary.min_ssim_pose = min_ssim_pose;
    print("mean PSNR %.2f dB, mean SSIM %.4f\n", summary.mean_psnr, summary.mean_ssim);
    print("worst pose: PSNR %.2f dB (pose %zu), SSIM %.4f (pose %zu)\n", min_psnr, min_psnr_pose,
          min_ssim, min_ssim_pose);
    if (visibility) {
      const ErrorBreakdown& b = breakdown_sum;
      print(
          "error breakdown (share of the squared error over all poses; share of the pixels): "
          "disocclusion %.1f %% (%.1f %%), silhouette %.1f %% (%.1f %%), geometry %.1f %% "
          "(%.1f %%), shading %.1f %% (%.1f %%), ",
          100 * b.share(ErrorClass::kDisocclusion), 100 * b.pixel_share(ErrorClass::kDisocclusion),
          100 * b.share(ErrorClass::kSilhouette), 100 * b.pixel_share(ErrorClass::kSilhouette),
          100 * b.share(ErrorClass::kGeometry), 100 * b.pixel_share(ErrorClass::kGeometry),
          100 * b.share(ErrorClass::kShading), 100 * b.pixel_share(ErrorClass::kShading));
      if (b.codec_measured) {
        print("codec %.1f %% (%.1f %%)\n", 100 * b.share(ErrorClass::kCodec),
              100 * b.pixel_share(ErrorClass::kCodec));
      } else {
        print("codec not measured (give --breakdown-lossless)\n");
      }
    }
    if (!floor_dir.empty()) {
      print(
          "noise floor (ground truth against %s, another seed): mean PSNR %.2f dB, mean SSIM "
          "%.4f, lowest %.2f dB (pose %zu)\n",
          floor_dir.string().c_str(), floor_sum_psnr / compared, floor_sum_ssim / compared,
          floor_min_psnr, floor_min_pose);
    } else {
      print(
          "noise floor: unknown (no %s/%s: calf-capture --ground-truth writes it, or give "
          "--noise-floor)\n",
          gt_dir.string().c_str(), capture::kNoiseFloorDirName);
    }
  }
  if (!sheet.empty()) {
    std::vector<ContactSheetRow> rows;
    for (const SheetTile& t : sheet) rows.push_back({rgb_ref(t.ground_truth), rgb_ref(t.rendered)});
    CALF_ASSIGN_OR_RETURN(const Rgb8Image composed, compose_contact_sheet(rows));
    CALF_RETURN_IF_ERROR(write_png_rgb8(a.contact_sheet, composed));
    ++summary.files_written;
    print(
        "contact sheet: %s (%zu poses; ground truth | calf | error heat map, red = "
        "error 0.1 of full scale or more)\n",
        a.contact_sheet.string().c_str(), rows.size());
  }
  return summary;
}

}  // namespace calf::player
