// calf-bench: measuring one scene — capture, ground truth, an encode, a headless playback.
//
// The capture set and the ground truth are rendered once per scene (calf-capture's library,
// samples/render.h) into a work directory; every encode is a fresh
// encoder::encode_lightfield_file() of that capture set; every playback a fresh Playback
// (player/playback.h) of the clip, driven pose by pose along the ground truth's eye path exactly as
// calf-play --headless --compare does it: poses sharing a time are prepared together, each is
// rendered and compared (image_compare.h PSNR / SSIM; a pose's PSNR is capped at 100 dB like
// calf-play's mean). Nothing is cached between points: a point's numbers come from its own encode
// (or the base clip, for play knobs) and its own playback.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "calf/capture/eye_path.h"
#include "calf/format/status.h"
#include "calf/player/gl_context.h"
#include "sweep.h"

namespace calf::bench {

struct MeasureSettings {
  uint32_t face_size = 128;
  uint32_t frames = 8;
  uint32_t gt_width = 128, gt_height = 128;
  uint32_t threads = 0;  // capture, encode and CPU-render threads; 0 = all cores
  float noise = 0;       // the capture's per-frame colour noise (calf-capture --noise), [0, 1]; the
                         // ground truth is rendered without it
  bool use_gl = true;    // false: the CPU reference renderer
  const player::GlFunctions* gl = nullptr;  // the current OSMesa context's (use_gl)
};

// What an encode gave.
struct EncodeOutcome {
  encoder::LightfieldEncodeStats stats;
  uint64_t file_bytes = 0;
  double seconds = 0, cpu_seconds = 0;  // wall; CPU time of the process (every thread)
  double q_used = 0;                    // Q the encode used (psnr_auto: from the estimate)
  double noise_db = 0;                  // psnr_auto: the render-noise estimate, 0 = none
  uint32_t denoise_window = 0;          // the pre-filter's window the encode used
};

// A scene's capture set and ground truth on disk, and the ground truth in memory.
class SceneInputs {
 public:
  // Renders the capture set (the scene's default rig, `settings.face_size`, `settings.frames`)
  // into work/capture and the ground truth along the scene's validation eye path into work/gt;
  // `work` must not hold an earlier capture (the caller gives each run a fresh directory).
  static Expected<std::unique_ptr<SceneInputs>> make(const std::string& scene,
                                                     const MeasureSettings& settings,
                                                     const std::filesystem::path& work);

  const std::filesystem::path& capture_dir() const { return capture_dir_; }
  uint32_t view_count() const { return view_count_; }
  bool material() const { return material_; }
  double capture_seconds() const { return capture_s_; }
  double ground_truth_seconds() const { return gt_s_; }
  const capture::EyePath& eye_path() const { return path_; }

  // Encodes the capture set with `config` into `clip` (wall time measured around the call; with
  // config.psnr_auto the noise estimate, as calf-encode --psnr auto makes it, is inside it).
  Expected<EncodeOutcome> encode(const EncodeConfig& config,
                                 const std::filesystem::path& clip) const;

  // Plays `clip` headless along the eye path with `config` and fills the playback fields of
  // `out` (frames, decode / render medians and first frame, PSNR, SSIM, ...).
  Status play(const std::filesystem::path& clip, const PlayConfig& config, PointResult* out) const;

 private:
  SceneInputs() = default;
  MeasureSettings settings_;
  std::filesystem::path capture_dir_;
  uint32_t view_count_ = 0;
  bool material_ = false;
  double capture_s_ = 0, gt_s_ = 0;
  capture::EyePath path_;
  std::vector<capture::PerspectiveImage> ground_truth_;
};

// The median of `values` (the mean of the middle two for an even count; 0 when empty).
double median(std::vector<double> values);

// Seconds on a monotonic clock.
double now_seconds();
// CPU seconds of the whole process so far (every thread).
double cpu_seconds();

}  // namespace calf::bench
