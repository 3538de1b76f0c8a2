// calf-capture: renders capture sets (cube-map colour + depth [+ material] per viewpoint and
// frame) and ground truth of the built-in sample scenes or of any file assimp imports.
// Errors are one line with a stable id and exit status 1; usage errors exit 2 (command_line.h).
// SIGINT / SIGTERM / SIGHUP remove the image being written (calf/format/files.h).
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <initializer_list>
#include <string>
#include <thread>

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include "calf/capture/capture_shard.h"
#include "calf/samples/render.h"
#include "calf/samples/rig_placement.h"
#include "calf/samples/scene.h"
#include "calf/samples/scene_export.h"
#include "calf/samples/surfel_candidates.h"
#include "command_line.h"

namespace {

using calf::Status;
namespace samples = calf::samples;

int fail(const Status& status) {
  return calf::tools::print_error("calf-capture", status);
}

// An option value outside its range, found after parsing: its own id, exit 2 like every usage
// error (command_line.h).
int bad_option(const Status& status) {
  return calf::tools::print_error("calf-capture", status, calf::tools::kExitUsage);
}

// Progress on stderr: one updating line on a terminal, a line per ~10 % otherwise.
class Progress {
 public:
  Progress(const char* what, bool quiet) : what_(what), quiet_(quiet), tty_(isatty(2) != 0) {}
  void operator()(uint64_t done, uint64_t total) {
    if (quiet_) return;
    double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    double eta = done ? elapsed / static_cast<double>(done) * static_cast<double>(total - done) : 0;
    int percent = static_cast<int>(100 * done / total);
    if (!tty_ && percent < next_percent_ && done != total) return;
    next_percent_ = percent + 10;
    std::fprintf(stderr, "%scalf-capture: %s %llu/%llu (%d%%) elapsed %.1f s, ETA %.1f s%s",
                 tty_ ? "\r" : "", what_, static_cast<unsigned long long>(done),
                 static_cast<unsigned long long>(total), percent, elapsed, eta,
                 tty_ && done != total ? "" : "\n");
    std::fflush(stderr);
  }

 private:
  const char* what_;
  bool quiet_, tty_;
  int next_percent_ = 0;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

// --surfel-candidates: ray casts and writes, with progress and a summary line.
int write_candidates(const calf::capture::SceneFile& scene,
                     const samples::SurfelCandidateOptions& options, const std::string& path,
                     bool quiet) {
  Progress progress("surfel view", quiet);
  auto stats = samples::write_surfel_candidates(scene, options, path,
                                                [&](uint64_t d, uint64_t t) { progress(d, t); });
  if (!stats.ok()) return fail(stats.status());
  if (!quiet) {
    std::fprintf(stderr,
                 "calf-capture: %s: %llu candidates of %llu meshes (%u^2 x %u views), %.1f MB in "
                 "%.2f s, %.1f Mrays/s\n",
                 path.c_str(), static_cast<unsigned long long>(stats->candidates),
                 static_cast<unsigned long long>(stats->meshes), options.resolution,
                 options.directions, static_cast<double>(stats->bytes) * 1e-6, stats->seconds,
                 stats->seconds > 0 ? static_cast<double>(stats->rays) / stats->seconds * 1e-6 : 0);
  }
  return 0;
}

// --rig auto / hammersley: the curve and the rig on stdout, the table and plot into `out_dir`.
int report_placement(const samples::PlacementResult& r, const samples::PlacementOptions& o,
                     const std::string& scene, const std::string& hand_made,
                     const std::string& out_dir) {
  const std::string table = samples::placement_table(r);
  std::printf(
      "calf-capture: placement %s on %s: %u candidates outside geometry%s, %u surface points, "
      "length scale %g (k is per it), %.1f M visibility rays, %.2f s; Alg. 1 stopped: %s\n%s",
      o.text.c_str(), scene.c_str(), r.candidates,
      r.rig.keep_out_radius > 0
          ? fmt::format(" and the keep-out ball (radius {:g})", r.rig.keep_out_radius).c_str()
          : "",
      r.surface_samples, r.length_scale, static_cast<double>(r.rays) * 1e-6, r.seconds,
      r.stop_reason.c_str(), table.c_str());
  std::printf("hand-made rig %s: %u views, coverage %.6f\n", hand_made.c_str(), r.hand_made_count,
              r.hand_made_coverage);
  std::string list;
  for (const calf::capture::Viewpoint& v : r.rig.viewpoints) {
    list += fmt::format("{}{},{},{}", list.empty() ? "list:" : "/", v.position.x, v.position.y,
                        v.position.z);
  }
  std::printf("rig (%zu views, coverage %.6f): %s\n", r.rig.viewpoints.size(),
              o.kind == samples::PlacementOptions::Kind::kAuto
                  ? (r.curve.empty() ? 0.0 : r.curve.back().coverage)
                  : r.hammersley_coverage,
              list.c_str());
  std::fflush(stdout);
  std::error_code ec;
  std::filesystem::create_directories(out_dir, ec);
  if (ec) {
    return fail(
        Status(calf::ErrorId::kFileWrite, "cannot create " + out_dir + ": " + ec.message()));
  }
  const std::filesystem::path dir(out_dir);
  if (Status s = calf::capture::write_file_atomically(dir / "rig_placement.tsv", table); !s.ok()) {
    return fail(s);
  }
  const std::string svg =
      samples::placement_svg(r, "coverage vs cameras: " + scene + ", --rig " + o.text);
  if (Status s = calf::capture::write_file_atomically(dir / "rig_placement.svg", svg); !s.ok()) {
    return fail(s);
  }
  return 0;
}

}  // namespace

static int command_main(int argc, char** argv) {
  CLI::App app{
      "calf-capture: ray-trace capture sets (format/CAPTURE.md) and ground truth of sample "
      "scenes.\n"
      "Writes DIR/manifest.json last, so an interrupted run never leaves a set that looks "
      "complete; every file is written whole (a temporary file renamed into place, removed on "
      "an error or on SIGINT / SIGTERM / SIGHUP).\n" +
          std::string(calf::tools::kExitStatusHelp),
      "calf-capture"};
  std::string scene_arg, out_dir, rig_arg = "default", eye_path_file, export_dir;
  uint32_t face_size = 256, frames = 0, threads = 0;
  // Rendering defaults are LightfieldRenderOptions' (calf/samples/render.h), one place.
  samples::LightfieldRenderOptions render;
  bool noise_floor = true;
  std::string gt_size = "256x256";
  bool list = false, ground_truth = false, quiet = false;
  std::string surfel_path, surfel_corners = "cube";
  samples::SurfelCandidateOptions surfel;
  app.add_option("--scene", scene_arg,
                 "built-in scene name (see --list-scenes) or a glTF/GLB/OBJ/PLY/FBX file");
  app.add_option("--out", out_dir, "output directory (created if missing)");
  app.add_option("--face-size", face_size, "cube face size in texels, 1..4096")
      ->capture_default_str();
  app.add_option("--frames", frames,
                 "frames to render, 1..100000 (default: the scene's own, 30 for built-ins)")
      ->check(CLI::Range(1u, 100000u));
  app.add_option("--rig", rig_arg,
                 std::string("viewpoints, one of:\n") + samples::kRigSyntaxHelp + "\n" +
                     samples::kPlacementSyntaxHelp +
                     "\nauto and hammersley print the coverage-versus-count curve and the rig, "
                     "and write DIR/rig_placement.tsv and DIR/rig_placement.svg "
                     "(docs/CAMERA_PLACEMENT.md)")
      ->capture_default_str();
  bool rig_only = false;
  app.add_flag("--rig-only", rig_only,
               "with --rig auto or hammersley: choose the rig, print and write its report, and "
               "render nothing");
  app.add_option("--threads", threads,
                 "render threads 0..256, 0 = all hardware threads; output is identical for any "
                 "count")
      ->check(CLI::Range(0u, calf::tools::kMaxThreads))
      ->capture_default_str();
  uint64_t max_image_pixels = calf::capture::kDefaultMaxImagePixels;
  app.add_option("--max-image-pixels", max_image_pixels,
                 std::string("model and scene-file textures: ") +
                     calf::capture::kMaxImagePixelsHelp +
                     "; the ray tracer keeps about 16 bytes per texel")
      ->check(CLI::Range(uint64_t{1}, calf::capture::kMaxImagePixelsLimit));
  app.add_option("--seed", render.seed, "seed of sample positions, AO directions and noise")
      ->capture_default_str();
  app.add_option("--spp", render.spp,
                 "most colour samples per pixel (texel), 1..4096, at stratified positions in the "
                 "pixel's square, averaged (a box filter); 1 = one ray through the pixel centre, "
                 "calf's rendering before anti-aliasing, bit for bit. Depth and material are "
                 "always the centre ray's (docs/RENDERING.md, \"Converged capture\")")
      ->capture_default_str();
  bool coverage = false;
  app.add_flag("--coverage", coverage,
               "also write each texel's coverage: the shares of its square whose first surface "
               "lies nearer and farther than its depth, from the colour samples (capture set "
               "version 2, format/CAPTURE.md \"Coverage\"). calf-encode carries it as the clip's "
               "coverage stream (SPEC 11.1.11), and the renderers read it from the clip or the "
               "set: 5-15 % more clip bytes (docs/ENCODER.md) for silhouettes placed inside the "
               "texel (calf-play --coverage, --hint-coverage). Default off");
  app.add_option("--min-spp", render.min_spp,
                 "samples of the first round, 1..4096; rounds double the count until the "
                 "pixel's standard error is within --tolerance or --spp samples are taken")
      ->capture_default_str();
  app.add_option("--tolerance", render.tolerance,
                 "target standard error of a pixel's mean, in sRGB-encoded units (1 = full "
                 "scale), [0, 1]; 0 = always --spp samples")
      ->capture_default_str();
  app.add_option("--ao-samples", render.ao_samples,
                 "ambient-occlusion rays per diffuse hit of each sample, 0..256 (a pixel's AO rays "
                 "at a surface: samples x this, stratified together)")
      ->capture_default_str();
  app.add_option("--max-bounces", render.max_bounces, "mirror/glass recursion depth, 0..32")
      ->capture_default_str();
  app.add_option("--noise", render.noise,
                 "per-frame colour noise amplitude in [0, 1] mimicking a path tracer (0 = off)")
      ->capture_default_str();
  app.add_flag("!--no-noise-floor", noise_floor,
               "ground truth: do not also render DIR/noise-floor/ (the same poses with --seed + 1, "
               "from which calf-play --compare prints the noise floor of every figure)");
  app.add_flag("--ground-truth", ground_truth,
               "render perspective colour + depth along the scene's validation eye path instead "
               "of a capture set; writes DIR/gt_NNNNN.exr and DIR/eye_path.json (last)");
  app.add_option("--eye-path", eye_path_file,
                 "render ground truth along this eye-path JSON (CAPTURE.md) instead");
  app.add_option("--gt-size", gt_size, "image size WxH of --ground-truth images")
      ->capture_default_str();
  app.add_option("--export-scene", export_dir,
                 "also write the scene as a scene file (format/SCENE.md: DIR/scene.json last, "
                 "scene.bin) with --frames frames; without --out, only export");
  app.add_option("--surfel-candidates", surfel_path,
                 "also ray-cast the initial surfel candidates (paper 001 Sec. 3.1) of every mesh "
                 "prototype of the scene, as --export-scene numbers them, into this file "
                 "(format/SURFEL_CANDIDATES.md): an orthographic G-buffer per direction, one "
                 "candidate (position, normal, unshaded base colour per material) per hit pixel; "
                 "without --out, only this. --scene may then also name a scene-file folder "
                 "(DIR/scene.json)");
  app.add_option("--surfel-resolution", surfel.resolution,
                 "G-buffer side R in pixels of --surfel-candidates, 1..4096 (the paper: 1024)")
      ->capture_default_str();
  app.add_option("--surfel-directions", surfel.directions,
                 "G-buffers per prototype: 8 (from the corners towards the centre) or 16 (those "
                 "8 and the same turned 45 degrees about +Y)")
      ->capture_default_str();
  app.add_option("--surfel-corners", surfel_corners,
                 "which corners the 8 directions come from: cube (the bounding box made cubical: "
                 "the diagonals, a flat or long part is never seen edge-on) or box (the bounding "
                 "box's own corners, the paper's rule)")
      ->capture_default_str();
  std::string shard_views, shard_frames;
  bool join = false;
  app.add_option("--views", shard_views,
                 "render a capture shard (docs/FARM.md): only these views, e.g. 0-2,5 (inclusive "
                 "ranges, ascending, 0-based rig order); the shard writes its images and "
                 "DIR/capture-shard.v<views>.f<first>-<last>.json, never manifest.json "
                 "(default: every view, a complete set)");
  app.add_option("--frame-range", shard_frames,
                 "render a capture shard of frames FIRST-LAST only (inclusive, 0-based) (default: "
                 "every frame)");
  app.add_flag("--join", join,
               "join the capture shards rendered into --out: check that every shard marker holds "
               "the same manifest and every image is there, write manifest.json, remove the "
               "markers; nothing is rendered");
  app.add_flag("--list-scenes", list, "print the built-in scenes and exit");
  app.add_flag("--quiet", quiet, "no progress or summary lines on stderr");
  // --help groups the options by what they act on.
  const auto group = [&app](const char* name, std::initializer_list<const char*> options) {
    for (const char* option : options) app.get_option(option)->group(name);
  };
  group("Rig", {"--rig", "--rig-only", "--face-size"});
  group("Rendering", {"--seed", "--spp", "--min-spp", "--tolerance", "--ao-samples",
                      "--max-bounces", "--noise"});
  group("Coverage", {"--coverage"});
  group("Ground truth", {"--ground-truth", "--eye-path", "--gt-size", "--no-noise-floor"});
  group("Scene file and surfel candidates",
        {"--export-scene", "--surfel-candidates", "--surfel-resolution", "--surfel-directions",
         "--surfel-corners"});
  group("Capture shards (docs/FARM.md)", {"--views", "--frame-range", "--join"});
  if (int rc = calf::tools::parse_command_line(app, "calf-capture", argc, argv); rc >= 0) return rc;

  if (list) {
    for (const samples::SceneInfo& s : samples::builtin_scenes()) {
      auto scene = samples::make_builtin_scene(s.name);
      std::printf("%-11s %s; default rig %s, %u frames at %g fps\n", s.name, s.description,
                  scene->default_rig.description.c_str(), scene->frame_count, scene->fps);
    }
    return 0;
  }
  if (join) {
    if (out_dir.empty() || !scene_arg.empty() || !shard_views.empty() || !shard_frames.empty()) {
      return calf::tools::usage_error("calf-capture", "--join takes --out only");
    }
    auto joined = calf::capture::join_capture_shards(out_dir);
    if (!joined.ok()) return fail(joined.status());
    if (!quiet) {
      std::fprintf(stderr, "calf-capture: %s: joined %u capture shards\n", out_dir.c_str(),
                   *joined);
    }
    return 0;
  }
  if (scene_arg.empty() || (out_dir.empty() && export_dir.empty() && surfel_path.empty())) {
    return calf::tools::usage_error(
        "calf-capture", "--scene and --out (or --export-scene, --surfel-candidates) are required");
  }

  if (rig_only && !samples::is_placement_rig(rig_arg)) {
    return calf::tools::usage_error("calf-capture", "--rig-only needs --rig auto or hammersley");
  }
  render.threads = threads;
  if (Status s = samples::validate_render_options(render); !s.ok()) return bad_option(s);
  if (face_size < 1 || face_size > 4096) {
    return bad_option(Status(calf::ErrorId::kCaptureOption,
                             fmt::format("--face-size {} is outside 1..4096", face_size)));
  }
  if (!surfel_path.empty()) {
    surfel.threads = threads;
    if (surfel_corners == "cube") {
      surfel.corners = calf::capture::SurfelCorners::kCube;
    } else if (surfel_corners == "box") {
      surfel.corners = calf::capture::SurfelCorners::kBox;
    } else {
      return bad_option(Status(calf::ErrorId::kSurfelOption, "--surfel-corners '" + surfel_corners +
                                                                 "' is neither cube nor box"));
    }
    if (Status s = samples::validate_surfel_candidate_options(surfel); !s.ok()) {
      return bad_option(s);
    }
  }
  // A scene-file folder feeds --surfel-candidates alone: its meshes are what an encoder reads.
  std::error_code ec;
  const std::filesystem::path scene_json =
      std::filesystem::path(scene_arg) / calf::capture::kSceneManifestFileName;
  if (std::filesystem::is_directory(scene_arg, ec) && std::filesystem::exists(scene_json, ec)) {
    if (surfel_path.empty() || !out_dir.empty() || !export_dir.empty()) {
      return calf::tools::usage_error(
          "calf-capture", "--scene " + scene_arg +
                              " is a scene-file folder, which goes with --surfel-candidates "
                              "alone (--out and --export-scene take a built-in scene or a model "
                              "file; calf-encode --mode mesh encodes a scene file)");
    }
    auto file = calf::capture::read_scene_file(scene_arg, max_image_pixels);
    if (!file.ok()) return fail(file.status());
    return write_candidates(*file, surfel, surfel_path, quiet);
  }
  auto scene = samples::load_scene(scene_arg, max_image_pixels);
  if (!scene.ok()) return fail(scene.status());
  const uint32_t frame_count = frames ? frames : scene->frame_count;
  if (!surfel_path.empty()) {
    auto file = samples::export_scene(*scene, frame_count);
    if (!file.ok()) return fail(file.status());
    if (int rc = write_candidates(*file, surfel, surfel_path, quiet); rc != 0) return rc;
    if (out_dir.empty() && export_dir.empty()) return 0;
  }
  if (!export_dir.empty()) {
    if (Status s = samples::write_scene(*scene, frame_count, export_dir); !s.ok()) return fail(s);
    if (!quiet) std::fprintf(stderr, "calf-capture: scene file %s written\n", export_dir.c_str());
    if (out_dir.empty()) return 0;
  }

  samples::RenderStats stats;
  if (ground_truth || !eye_path_file.empty()) {
    calf::capture::EyePath path;
    if (!eye_path_file.empty()) {
      auto read = calf::capture::read_eye_path(eye_path_file);
      if (!read.ok()) return fail(read.status());
      path = std::move(*read);
    } else {
      unsigned w = 0, h = 0;
      char x = 0, extra = 0;
      if (std::sscanf(gt_size.c_str(), "%u%c%u%c", &w, &x, &h, &extra) != 3 || x != 'x' || w < 1 ||
          h < 1 || w > 16384 || h > 16384) {
        return bad_option(Status(calf::ErrorId::kCaptureOption,
                                 "--gt-size '" + gt_size + "' is not WxH with sizes in 1..16384"));
      }
      path = scene->validation_path(frame_count, scene->fps, w, h);
    }
    // The noise floor first, so that DIR/eye_path.json, written last, marks both complete: the
    // same poses with the next seed, what calf-play --compare measures the ground truth against
    // itself with.
    if (noise_floor) {
      samples::LightfieldRenderOptions other = render;
      other.seed = render.seed + 1;
      Progress progress("noise-floor pose", quiet);
      auto result = samples::render_ground_truth(
          *scene, path, other, std::filesystem::path(out_dir) / calf::capture::kNoiseFloorDirName,
          [&](uint64_t d, uint64_t t) { progress(d, t); });
      if (!result.ok()) return fail(result.status());
    }
    Progress progress("ground truth pose", quiet);
    auto result = samples::render_ground_truth(*scene, path, render, out_dir,
                                               [&](uint64_t d, uint64_t t) { progress(d, t); });
    if (!result.ok()) return fail(result.status());
    stats = *result;
  } else {
    samples::CaptureRequest request;
    request.face_size = face_size;
    request.coverage = coverage;
    request.frames = frame_count;
    request.render = render;
    request.generator = "calf-capture";
    if (rig_arg == "default") {
      request.rig = scene->default_rig;
    } else if (samples::is_placement_rig(rig_arg)) {
      auto placement = samples::parse_placement(rig_arg);
      if (!placement.ok()) return bad_option(placement.status());
      placement->threads = threads;
      auto placed = samples::place_cameras(*scene, *placement, frame_count);
      if (!placed.ok()) return fail(placed.status());
      if (int rc = report_placement(*placed, *placement, scene->name,
                                    scene->default_rig.description, out_dir);
          rc != 0) {
        return rc;
      }
      if (rig_only) return 0;
      request.rig = std::move(placed->rig);
      request.generator = "calf-capture --rig " + rig_arg;
    } else {
      auto rig = samples::parse_rig(rig_arg);
      if (!rig.ok()) return fail(rig.status());
      request.rig = std::move(*rig);
    }
    if (!shard_views.empty() || !shard_frames.empty()) {
      if (ground_truth || !eye_path_file.empty()) {
        return calf::tools::usage_error("calf-capture",
                                        "--views / --frame-range make capture sets");
      }
      request.shard = true;
      request.first_frame = 0;
      request.last_frame = frame_count - 1;
      if (!shard_views.empty()) {
        auto v = calf::capture::parse_index_list(
            shard_views, static_cast<uint32_t>(request.rig.viewpoints.size()), "views");
        if (!v.ok()) return bad_option(v.status());
        request.views = std::move(*v);
      }
      if (!shard_frames.empty()) {
        auto f = calf::capture::parse_index_list(shard_frames, frame_count, "frames");
        if (!f.ok()) return bad_option(f.status());
        if (f->back() - f->front() + 1 != f->size()) {
          return bad_option(calf::Status(calf::ErrorId::kShardRange,
                                         "--frame-range '" + shard_frames + "' is not one range"));
        }
        request.first_frame = f->front();
        request.last_frame = f->back();
      }
    }
    Progress progress("view-frame", quiet);
    auto result = samples::render_capture_set(*scene, request, out_dir,
                                              [&](uint64_t d, uint64_t t) { progress(d, t); });
    if (!result.ok()) return fail(result.status());
    stats = *result;
  }
  if (!quiet) {
    const bool gt = ground_truth || !eye_path_file.empty();
    const double images = static_cast<double>(stats.images);
    std::fprintf(stderr,
                 "calf-capture: %s: %.1f Mrays in %.2f s, %.2f Mrays/s, %u threads, %.2f samples "
                 "per pixel, %.3f s per %s\n",
                 out_dir.c_str(), static_cast<double>(stats.rays) * 1e-6, stats.seconds,
                 stats.mrays_per_second(),
                 threads ? threads : std::max(1u, std::thread::hardware_concurrency()),
                 stats.pixels ? static_cast<double>(stats.samples) / stats.pixels : 0.0,
                 images > 0 ? stats.seconds / images : 0.0, gt ? "pose" : "view-frame");
  }
  return 0;
}

int main(int argc, char** argv) {
  return calf::tools::run_command("calf-capture", [&] { return command_main(argc, argv); });
}
