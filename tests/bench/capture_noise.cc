// The noise floor and cost of calf-capture's rendering (docs/RENDERING.md "Converged
// capture"): renders one frame of a built-in scene, every viewpoint of its default rig (cube
// maps) or the first poses of its validation eye path (ground truth), twice with two seeds, and
// prints the PSNR / SSIM between the two renders (image_compare.h: sRGB-encoded, clamped; cube
// maps compared as one N x 6N image), the mean samples per pixel, Mrays/s and seconds per
// view-frame (or pose) of one render.
//
//   bench-capture_noise --scene interior --face-size 512 [--views 9] [--spp 64 --min-spp 8
//                       --tolerance 0.004 --ao-samples 8] [--ground-truth 256x256 --poses 4]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>

#include <CLI/CLI.hpp>

#include "calf/player/image_compare.h"
#include "calf/samples/render.h"
#include "calf/samples/scene.h"

namespace {

using namespace calf;

struct Figures {
  double psnr_sum = 0, ssim_sum = 0, psnr_min = 1e9;
  uint32_t count = 0;
  samples::RenderStats stats;  // of the first seed
  double seconds = 0;
};

void add(Figures* f, const player::RgbImageRef& a, const player::RgbImageRef& b) {
  const double p = std::min(*player::psnr(a, b), 100.0);
  f->psnr_sum += p;
  f->psnr_min = std::min(f->psnr_min, p);
  f->ssim_sum += *player::ssim(a, b);
  ++f->count;
}

double now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"bench-capture_noise: calf-capture's noise floor (two seeds) and cost"};
  std::string scene_name = "interior", gt_size;
  uint32_t face_size = 64, views = 0, poses = 4, frame = 0;
  samples::LightfieldRenderOptions render;
  uint64_t other_seed = 2;
  app.add_option("--scene", scene_name, "built-in scene")->capture_default_str();
  app.add_option("--face-size", face_size, "cube face size")->capture_default_str();
  app.add_option("--views", views, "first N viewpoints of the default rig (0: all)");
  app.add_option("--frame", frame, "frame to render")->capture_default_str();
  app.add_option("--ground-truth", gt_size, "WxH: render validation-path poses instead");
  app.add_option("--poses", poses, "with --ground-truth: the first N poses")->capture_default_str();
  app.add_option("--threads", render.threads, "render threads (0: all)");
  app.add_option("--seed", render.seed, "first seed")->capture_default_str();
  app.add_option("--other-seed", other_seed, "second seed")->capture_default_str();
  app.add_option("--spp", render.spp, "LightfieldRenderOptions::spp")->capture_default_str();
  app.add_option("--min-spp", render.min_spp, "LightfieldRenderOptions::min_spp")
      ->capture_default_str();
  app.add_option("--tolerance", render.tolerance, "LightfieldRenderOptions::tolerance")
      ->capture_default_str();
  app.add_option("--ao-samples", render.ao_samples, "LightfieldRenderOptions::ao_samples")
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  if (Status s = samples::validate_render_options(render); !s.ok()) {
    std::fprintf(stderr, "%s\n", s.to_string().c_str());
    return 2;
  }
  auto scene = samples::make_builtin_scene(scene_name);
  if (!scene.ok()) {
    std::fprintf(stderr, "%s\n", scene.status().to_string().c_str());
    return 1;
  }
  samples::LightfieldRenderOptions second = render;
  second.seed = other_seed;
  const double time = frame / scene->fps;
  auto ta = samples::FrameTracer::create(*scene, time, render);
  auto tb = samples::FrameTracer::create(*scene, time, second);
  if (!ta.ok() || !tb.ok()) return 1;
  Figures f;
  std::string what;
  if (gt_size.empty()) {
    const auto& vps = scene->default_rig.viewpoints;
    const uint32_t n = views ? std::min<uint32_t>(views, vps.size()) : vps.size();
    capture::ViewFrame a, b;
    for (uint32_t v = 0; v < n; ++v) {
      const double t0 = now();
      samples::RenderStats s = (*ta)->render_cube(vps[v].position, v, frame, face_size, false, &a);
      f.seconds += now() - t0;
      f.stats.rays += s.rays, f.stats.samples += s.samples, f.stats.pixels += s.pixels;
      (*tb)->render_cube(vps[v].position, v, frame, face_size, false, &b);
      add(&f, {face_size, 6 * face_size, a.color}, {face_size, 6 * face_size, b.color});
    }
    what = std::to_string(n) + " views, faces " + std::to_string(face_size) + "^2";
  } else {
    unsigned w = 0, h = 0;
    if (std::sscanf(gt_size.c_str(), "%ux%u", &w, &h) != 2 || !w || !h) return 2;
    const capture::EyePath path =
        scene->validation_path(std::max(poses, scene->frame_count), scene->fps, w, h);
    const uint32_t n = std::min<uint32_t>(poses, path.poses.size());
    capture::PerspectiveImage a, b;
    for (uint32_t i = 0; i < n; ++i) {
      auto tpa = samples::FrameTracer::create(*scene, path.poses[i].time, render);
      auto tpb = samples::FrameTracer::create(*scene, path.poses[i].time, second);
      if (!tpa.ok() || !tpb.ok()) return 1;
      const double t0 = now();
      samples::RenderStats s = (*tpa)->render_perspective(path.poses[i], w, h, i, &a);
      f.seconds += now() - t0;
      f.stats.rays += s.rays, f.stats.samples += s.samples, f.stats.pixels += s.pixels;
      (*tpb)->render_perspective(path.poses[i], w, h, i, &b);
      add(&f, player::rgb_ref(a), player::rgb_ref(b));
    }
    what = std::to_string(n) + " poses, " + gt_size;
  }
  std::printf(
      "%s %s: spp %u min %u tolerance %g ao %u: seed %llu vs %llu PSNR mean %.2f dB min %.2f dB, "
      "SSIM %.5f; %.2f samples/px, %.2f Mrays and %.2f s per %s (%.2f Mrays/s)\n",
      scene_name.c_str(), what.c_str(), render.spp, render.min_spp, render.tolerance,
      render.ao_samples, static_cast<unsigned long long>(render.seed),
      static_cast<unsigned long long>(other_seed), f.psnr_sum / f.count, f.psnr_min,
      f.ssim_sum / f.count, static_cast<double>(f.stats.samples) / f.stats.pixels,
      f.stats.rays * 1e-6 / f.count, f.seconds / f.count, gt_size.empty() ? "view" : "pose",
      f.stats.rays / f.seconds * 1e-6);
  return 0;
}
