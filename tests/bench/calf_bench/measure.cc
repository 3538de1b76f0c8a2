#include "measure.h"

#include <time.h>

#include <algorithm>
#include <chrono>
#include <thread>

#include <fmt/format.h>

#include "calf/capture/capture_set.h"
#include "calf/encoder/colour_denoise.h"
#include "calf/encoder/noise_estimate.h"
#include "calf/player/capture_views.h"
#include "calf/player/image_compare.h"
#include "calf/player/playback.h"
#include "calf/samples/render.h"
#include "calf/samples/scene.h"

namespace calf::bench {

namespace fs = std::filesystem;

double now_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

double cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

double median(std::vector<double> values) {
  if (values.empty()) return 0;
  std::sort(values.begin(), values.end());
  const size_t n = values.size();
  return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

Expected<std::unique_ptr<SceneInputs>> SceneInputs::make(const std::string& name,
                                                         const MeasureSettings& settings,
                                                         const fs::path& work) {
  std::unique_ptr<SceneInputs> in(new SceneInputs());
  in->settings_ = settings;
  CALF_ASSIGN_OR_RETURN(samples::Scene scene, samples::make_builtin_scene(name));
  samples::LightfieldRenderOptions render;
  render.threads = settings.threads;

  // `work` is this run's own fresh directory: the capture is never one left by an earlier run.
  in->capture_dir_ = work / "capture";
  samples::CaptureRequest request;
  request.face_size = settings.face_size;
  request.frames = settings.frames;
  request.rig = scene.default_rig;
  request.render = render;
  request.render.noise = settings.noise;
  request.generator = "calf-bench";
  double t0 = now_seconds();
  CALF_RETURN_IF_ERROR(
      samples::render_capture_set(scene, request, in->capture_dir_, nullptr).status());
  in->capture_s_ = now_seconds() - t0;
  in->view_count_ = static_cast<uint32_t>(request.rig.viewpoints.size());
  in->material_ = scene.has_mirror_or_glass();

  // Ground truth along the scene's validation path: one pose per frame.
  const fs::path gt_dir = work / "gt";
  const capture::EyePath path =
      scene.validation_path(settings.frames, scene.fps, settings.gt_width, settings.gt_height);
  t0 = now_seconds();
  CALF_RETURN_IF_ERROR(samples::render_ground_truth(scene, path, render, gt_dir, nullptr).status());
  in->gt_s_ = now_seconds() - t0;
  // Read back what was written, as calf-play --compare does: the file is the reference.
  CALF_ASSIGN_OR_RETURN(in->path_, capture::read_eye_path(gt_dir / capture::kEyePathFileName));
  for (uint32_t k = 0; k < in->path_.poses.size(); ++k) {
    CALF_ASSIGN_OR_RETURN(
        capture::PerspectiveImage image,
        capture::read_perspective_image(gt_dir / capture::eye_image_file_name(in->path_, k)));
    in->ground_truth_.push_back(std::move(image));
  }
  return in;
}

Expected<EncodeOutcome> SceneInputs::encode(const EncodeConfig& c, const fs::path& clip) const {
  encoder::LightfieldEncodeOptions o;
  o.cell_size = c.cell;
  o.min_psnr_db = c.q;
  o.colour = c.colour;
  o.depth = c.depth;
  o.depth_window = c.window;
  o.max_aabbs = c.aabbs;
  o.supercompression = c.super;
  o.threads = settings_.threads;
  o.av1.chroma444 = c.av1_444;
  o.av1.crf = c.av1_crf;
  o.av1.keyframe_interval = c.av1_keyframe_interval;
  o.denoise_window = c.denoise_window;
  EncodeOutcome out;
  const double t0 = now_seconds(), c0 = cpu_seconds();
  if (c.psnr_auto) {
    // calf-encode --psnr auto --psnr-noise-margin M --denoise-window auto: Q, the noise-aware
    // test and the pre-filter's window from the capture's render-noise estimate.
    CALF_ASSIGN_OR_RETURN(const encoder::CaptureNoise noise,
                          encoder::apply_auto_psnr(capture_dir_, c.noise_margin, true, &o));
    out.noise_db = noise.set.psnr_db.value_or(0);
  }
  out.q_used = o.min_psnr_db;
  out.denoise_window = o.denoise_window;
  CALF_ASSIGN_OR_RETURN(out.stats, encoder::encode_lightfield_file(capture_dir_, clip.string(), o));
  out.seconds = now_seconds() - t0;
  out.cpu_seconds = cpu_seconds() - c0;
  std::error_code ec;
  out.file_bytes = fs::file_size(clip, ec);
  if (ec) return Status(ErrorId::kFileOpen, clip.string() + ": " + ec.message());
  return out;
}

Status SceneInputs::play(const fs::path& clip, const PlayConfig& config, PointResult* out) const {
  player::PlaybackOptions o;
  o.of<player::LightfieldOptions>().render.steps = config.steps;
  o.of<player::LightfieldOptions>().selection.max_active = config.views;
  o.of<player::LightfieldOptions>().selection.budget.target_frame_ms =
      0;  // calf-play --headless: quality first, no performance culling
  o.use_gl = settings_.use_gl;
  const uint32_t cores = std::max(1u, std::thread::hardware_concurrency());
  o.of<player::LightfieldOptions>().render.threads =
      std::min(256u, settings_.threads ? settings_.threads : cores);
  CALF_ASSIGN_OR_RETURN(std::unique_ptr<player::Playback> play,
                        player::Playback::open(clip.string(), o, settings_.gl));

  std::vector<double> decode, prepare, render, prepare_cpu, render_cpu;
  double sum_psnr = 0, sum_ssim = 0, worst = 1e300, sum_views = 0, sum_mbps = 0;
  player::RenderedImage image;
  const capture::EyePath& path = path_;
  for (size_t i = 0; i < path.poses.size();) {
    // Poses sharing a time (a stereo pair) are prepared together, as calf-play does.
    size_t j = i + 1;
    while (j < path.poses.size() && path.poses[j].time == path.poses[i].time) ++j;
    std::vector<Camera> eyes;
    for (size_t k = i; k < j; ++k) {
      eyes.push_back(capture::camera_from_pose(path, k));
    }
    const uint32_t frame = play->frame_at_time(path.poses[i].time);
    const double t0 = now_seconds(), c0 = cpu_seconds();
    CALF_RETURN_IF_ERROR(play->prepare(frame, eyes));
    prepare.push_back(1e3 * (now_seconds() - t0));
    prepare_cpu.push_back(1e3 * (cpu_seconds() - c0));
    const decoder::FrameStats& st = play->lightfield()->last_stats();
    if (st.errors > 0) {
      return Status(ErrorId::kInternal,
                    fmt::format("{}: frame {}: {} damaged chunk(s): {}", clip.string(), frame,
                                st.errors, st.first_error));
    }
    decode.push_back(st.decode_ms);
    sum_views += static_cast<double>(play->lightfield()->last_selection().active.size());
    sum_mbps += st.mbps_at_24fps();
    for (size_t k = i; k < j; ++k) {
      const double r0 = cpu_seconds();
      CALF_RETURN_IF_ERROR(play->render(eyes[k - i], &image));
      render_cpu.push_back(1e3 * (cpu_seconds() - r0));
      render.push_back(play->last_render_ms());
      const auto gt = player::rgb_ref(ground_truth_[k]);
      CALF_ASSIGN_OR_RETURN(double p, player::psnr(player::rgb_ref(image), gt));
      CALF_ASSIGN_OR_RETURN(double s, player::ssim(player::rgb_ref(image), gt));
      p = std::min(p, 100.0);  // an exact frame counts as 100 dB, as in calf-play's mean
      sum_psnr += p;
      sum_ssim += s;
      worst = std::min(worst, p);
    }
    i = j;
  }
  const double poses = static_cast<double>(path.poses.size());
  const double groups = static_cast<double>(decode.size());
  out->frames = static_cast<uint32_t>(decode.size());
  out->first_decode_ms = decode.empty() ? 0 : decode.front();
  out->first_upload_ms = prepare.empty() ? 0 : prepare.front() - decode.front();
  out->first_render_ms = render.empty() ? 0 : render.front();
  // Medians without the first frame, which uploads every visible cell and (GL) compiles the
  // shader; with a single frame there is nothing else to take.
  auto tail = [](const std::vector<double>& v) {
    return v.size() > 1 ? std::vector<double>(v.begin() + 1, v.end()) : v;
  };
  std::vector<double> upload;
  for (size_t k = 0; k < prepare.size(); ++k) upload.push_back(prepare[k] - decode[k]);
  out->decode_ms = median(tail(decode));
  out->upload_ms = median(tail(upload));
  out->render_ms = median(tail(render));
  out->prepare_cpu_ms = median(tail(prepare_cpu));
  out->render_cpu_ms = median(tail(render_cpu));
  out->mean_active_views = groups > 0 ? sum_views / groups : 0;
  out->mean_mbps = groups > 0 ? sum_mbps / groups : 0;
  out->psnr_db = poses > 0 ? sum_psnr / poses : 0;
  out->ssim = poses > 0 ? sum_ssim / poses : 0;
  out->worst_psnr_db = poses > 0 ? worst : 0;
  return Status::Ok();
}

}  // namespace calf::bench
