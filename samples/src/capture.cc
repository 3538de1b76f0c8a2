// Capture-set and ground-truth drivers: validate everything first, render frame by frame, write
// each file whole, and write the file that marks a set complete (manifest / eye path) last.
#include <chrono>
#include <cmath>
#include <system_error>

#include "calf/capture/capture_shard.h"
#include "calf/format/files.h"
#include "calf/samples/render.h"

namespace calf::samples {

namespace {

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

std::string point_text(const Vec3& p) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "(%g, %g, %g)", p.x, p.y, p.z);
  return buf;
}

Status check_request(const CaptureRequest& r) {
  if (r.face_size < 1 || r.face_size > 4096) {
    return Status(ErrorId::kCaptureOption,
                  "face size " + std::to_string(r.face_size) + " is outside 1..4096");
  }
  if (r.frames > 100000) {
    return Status(ErrorId::kCaptureOption,
                  "frames " + std::to_string(r.frames) + " is outside 1..100000");
  }
  if (r.rig.viewpoints.empty()) return Status(ErrorId::kRigSyntax, "the rig has no viewpoints");
  return validate_render_options(r.render);
}

}  // namespace

Status check_viewpoints(const Scene& scene, const Rig& rig, uint32_t frames, double fps,
                        const LightfieldRenderOptions& options) {
  for (uint32_t f = 0; f < frames; ++f) {
    CALF_ASSIGN_OR_RETURN(auto tracer, FrameTracer::create(scene, f / fps, options));
    for (size_t v = 0; v < rig.viewpoints.size(); ++v) {
      if (tracer->inside_geometry(rig.viewpoints[v].position)) {
        return Status(ErrorId::kViewpointInsideGeometry,
                      "viewpoint " + std::to_string(v) + " '" + rig.viewpoints[v].name + "' at " +
                          point_text(rig.viewpoints[v].position) + " is inside geometry at frame " +
                          std::to_string(f));
      }
    }
  }
  return Status::Ok();
}

Expected<RenderStats> render_capture_set(const Scene& scene, const CaptureRequest& request,
                                         const std::filesystem::path& directory,
                                         const ProgressFn& progress) {
  CALF_RETURN_IF_ERROR(check_request(request));
  CALF_RETURN_IF_ERROR(validate_scene(scene));
  const uint32_t frames = request.frames ? request.frames : scene.frame_count;
  capture::CaptureManifest manifest;
  manifest.frame_count = frames;
  manifest.fps = scene.fps;
  manifest.face_size = request.face_size;
  manifest.view_volume = request.rig.view_volume;
  manifest.viewpoints = request.rig.viewpoints;
  manifest.material = scene.has_mirror_or_glass();
  if (request.coverage) {
    manifest.version = capture::kCaptureCoverageVersion;
    manifest.coverage = true;
  }
  manifest.scene = scene.name;
  manifest.generator = request.generator;
  CALF_RETURN_IF_ERROR(capture::validate_manifest(manifest));
  // The shard's views and frames (the whole set unless request.shard).
  std::vector<uint32_t> views = request.views;
  if (views.empty()) {
    for (uint32_t v = 0; v < manifest.viewpoints.size(); ++v) views.push_back(v);
  }
  const uint32_t first = request.shard ? request.first_frame : 0;
  const uint32_t last = request.shard ? request.last_frame : frames - 1;
  if (first > last || last >= frames) {
    return Status(ErrorId::kShardRange, "frames " + std::to_string(first) + "-" +
                                            std::to_string(last) + " are outside the set's " +
                                            std::to_string(frames) + " frames");
  }
  for (size_t i = 0; i < views.size(); ++i) {
    if (views[i] >= manifest.viewpoints.size() || (i > 0 && views[i] <= views[i - 1])) {
      return Status(ErrorId::kShardRange, "views " + capture::index_list_text(views) +
                                              ": not ascending within the rig's " +
                                              std::to_string(manifest.viewpoints.size()));
    }
  }
  if (request.shard) {
    // Only this shard's viewpoints and frames: another shard checks its own.
    for (uint32_t f = first; f <= last; ++f) {
      CALF_ASSIGN_OR_RETURN(auto tracer, FrameTracer::create(scene, f / scene.fps, request.render));
      for (const uint32_t v : views) {
        if (tracer->inside_geometry(request.rig.viewpoints[v].position)) {
          return Status(ErrorId::kViewpointInsideGeometry,
                        "viewpoint " + std::to_string(v) + " '" + request.rig.viewpoints[v].name +
                            "' at " + point_text(request.rig.viewpoints[v].position) +
                            " is inside geometry at frame " + std::to_string(f));
        }
      }
    }
  } else {
    CALF_RETURN_IF_ERROR(check_viewpoints(scene, request.rig, frames, scene.fps, request.render));
  }

  CALF_ASSIGN_OR_RETURN(capture::CaptureSetWriter writer,
                        capture::CaptureSetWriter::create(directory, manifest));
  const auto start = std::chrono::steady_clock::now();
  RenderStats stats;
  capture::ViewFrame image;
  const uint64_t total = static_cast<uint64_t>(last - first + 1) * views.size();
  uint64_t done = 0;
  for (uint32_t f = first; f <= last; ++f) {
    auto tracer = FrameTracer::create(scene, f / scene.fps, request.render);
    if (!tracer.ok()) {
      writer.abandon();
      return tracer.status();
    }
    for (const uint32_t v : views) {
      RenderStats s =
          (*tracer)->render_cube(manifest.viewpoints[v].position, v, f, request.face_size,
                                 manifest.material, &image, manifest.coverage);
      stats.rays += s.rays;
      stats.images += s.images;
      stats.pixels += s.pixels;
      stats.samples += s.samples;
      if (Status st = writer.write(v, f, image); !st.ok()) {
        writer.abandon();
        return st;
      }
      if (progress) progress(++done, total);
    }
  }
  const Status finished =
      request.shard ? capture::write_capture_shard_marker(directory, manifest, views, first, last)
                    : writer.finish();
  if (!finished.ok()) {
    writer.abandon();
    return finished;
  }
  stats.seconds = seconds_since(start);
  return stats;
}

Expected<RenderStats> render_ground_truth(const Scene& scene, const capture::EyePath& path_in,
                                          const LightfieldRenderOptions& options,
                                          const std::filesystem::path& directory,
                                          const ProgressFn& progress) {
  CALF_RETURN_IF_ERROR(validate_render_options(options));
  CALF_RETURN_IF_ERROR(validate_scene(scene));
  capture::EyePath path = path_in;
  if (path.image_pattern.empty()) path.image_pattern = capture::kDefaultImagePattern;
  if (path.poses.empty() || path.width == 0 || path.height == 0 || path.width > 16384 ||
      path.height > 16384) {
    return Status(ErrorId::kCaptureOption, "the eye path has no poses or a bad image size");
  }
  // Check every eye first: a bad pose must fail before any file is written.
  for (size_t i = 0; i < path.poses.size(); ++i) {
    CALF_ASSIGN_OR_RETURN(auto tracer, FrameTracer::create(scene, path.poses[i].time, options));
    if (tracer->inside_geometry(path.poses[i].position)) {
      return Status(ErrorId::kViewpointInsideGeometry,
                    "eye path pose " + std::to_string(i) + " at " +
                        point_text(path.poses[i].position) + " is inside geometry");
    }
  }
  std::error_code ec;
  std::filesystem::create_directories(directory, ec);
  if (ec || !std::filesystem::is_directory(directory, ec)) {
    return Status(ErrorId::kFileWrite, directory.string() + ": cannot create directory");
  }
  // A FIFO or link under the eye path's name is refused, not removed (calf/format/files.h).
  CALF_RETURN_IF_ERROR(files::check_output_file((directory / capture::kEyePathFileName).string()));
  std::filesystem::remove(directory / capture::kEyePathFileName, ec);
  const auto start = std::chrono::steady_clock::now();
  RenderStats stats;
  capture::PerspectiveImage image;
  std::vector<std::filesystem::path> written;
  auto fail = [&](Status st) {
    for (const auto& p : written) std::filesystem::remove(p, ec);
    return st;
  };
  for (uint32_t i = 0; i < path.poses.size(); ++i) {
    auto tracer = FrameTracer::create(scene, path.poses[i].time, options);
    if (!tracer.ok()) return fail(tracer.status());
    RenderStats s =
        (*tracer)->render_perspective(path.poses[i], path.width, path.height, i, &image);
    stats.rays += s.rays;
    stats.images += s.images;
    stats.pixels += s.pixels;
    stats.samples += s.samples;
    std::filesystem::path file = directory / capture::eye_image_file_name(path, i);
    if (Status st = capture::write_perspective_image(file, image); !st.ok()) return fail(st);
    written.push_back(file);
    if (progress) progress(i + 1, path.poses.size());
  }
  if (Status st = capture::write_file_atomically(directory / capture::kEyePathFileName,
                                                 capture::serialize_eye_path(path));
      !st.ok()) {
    return fail(st);
  }
  stats.seconds = seconds_since(start);
  return stats;
}

}  // namespace calf::samples
