// calf-bench: the speed <-> accuracy sweeps of calf (docs/BENCH.md).
//
// What one run does, per built-in scene: capture it once, render ground truth along its eye
// path once, then measure a base configuration (the calf-encode / calf-play defaults with colour
// cell 32) and, one knob at a time, the configurations around it:
//   encode knobs  Q, cell size, depth window W, AABB limit A, depth format, colour format,
//                 supercompression: each point is a fresh encode, then a headless playback;
//                 AV1 colour (chroma and CRF), render-noise pre-filter window, --psnr auto's
//                 noise margin (the last two on a capture given render noise, --noise);
//   play knobs    active view count, ray-march steps: the base clip played again.
// Every point records bytes (clip, colour, depth, material), encode seconds, decode and render
// milliseconds per frame (median over the eye path's frames, the first frame apart) and the mean
// PSNR / SSIM of the playback against ground truth. This header holds the types the parts of the
// program share: the knobs, a configuration, a point and what was measured for it.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "calf/encoder/lightfield_encode.h"
#include "calf/encoder/noise_estimate.h"
#include "calf/format/container_types.h"

namespace calf::bench {

// The knobs, in the order the tables list them. kBase marks the base point itself.
enum class Knob : uint8_t {
  kBase,
  kQ,
  kCell,
  kWindow,
  kAabbs,
  kDepth,
  kColour,
  kSuper,
  kViews,
  kSteps,
  kAv1,
  kDenoise,
  kMargin
};

// The command-line name of a knob ("q", "cell", ...) and the heading a table gets.
const char* knob_name(Knob knob);
const char* knob_title(Knob knob);
// Whether changing the knob needs a new encode (else the base clip is played again).
bool is_encode_knob(Knob knob);
// Every knob but kBase, in table order.
const std::vector<Knob>& all_knobs();
// The knobs "--knobs all" sweeps: all_knobs() but kAv1 (named on its own: AV1 encodes are the
// slowest points, and the default run keeps the committed run's points) and, unless `noisy`, the
// render-noise knobs (kDenoise, kMargin), which act only on a capture given render noise.
std::vector<Knob> default_knobs(bool noisy);
// Whether a knob acts only on a capture with render noise (calf-bench --noise).
bool is_noise_knob(Knob knob);

// What calf-encode gets for one point.
struct EncodeConfig {
  uint32_t cell = 32;
  double q = 50;
  encoder::ColourCoding colour = encoder::ColourCoding::kAuto;
  encoder::DepthCoding depth = encoder::DepthCoding::kRaw16;
  uint32_t window = 2;
  uint32_t aabbs = 2;
  container::Compression super = container::Compression::kZstd;
  // AV1 colour (colour == kAv1): 4:4:4 (libaom) or 4:2:0 (SVT-AV1), the CRF, the cell size is
  // `cell`, a key frame every av1_keyframe_interval frames (calf-encode --av1-*).
  bool av1_444 = false;
  uint32_t av1_crf = 32;
  uint32_t av1_keyframe_interval = 30;
  // Q from the capture's render noise (calf-encode --psnr auto --psnr-noise-margin M, with
  // --denoise-window auto: the window calf-encode picks); false: Q = q and the window below.
  bool psnr_auto = false;
  double noise_margin = encoder::kDefaultPsnrNoiseMargin;
  uint32_t denoise_window = 0;  // --denoise-window W without psnr_auto, 0 or 1 = off
  friend bool operator==(const EncodeConfig&, const EncodeConfig&) = default;
};

// What calf-play --headless gets for one point. views = the most active views (calf-play
// --views); a value at or above the clip's view count means "all".
struct PlayConfig {
  uint32_t views = 9;
  uint32_t steps = 64;
  friend bool operator==(const PlayConfig&, const PlayConfig&) = default;
};

const char* colour_coding_name(encoder::ColourCoding c);  // "auto", "bc1", ...
const char* depth_coding_name(encoder::DepthCoding d);    // "raw16", "bc5"
const char* super_name(container::Compression c);         // "zstd", "lzma2", "none"

// One point of a scene's sweep: the base configuration with `knob` set to `value`.
struct SweepPoint {
  Knob knob = Knob::kBase;
  std::string value;  // as the tables print it: "35", "bc7", "all (14)", ...
  std::string label;  // short plot label: "Q35", "c16", "W1", "v4", "s128", "base"
  EncodeConfig encode;
  PlayConfig play;
};

// What was measured for a point. Times are wall clock.
struct PointResult {
  // Encode (shared by every point played from the same clip).
  uint64_t clip_bytes = 0, colour_bytes = 0, depth_bytes = 0, material_bytes = 0;
  uint64_t colour_raw = 0,
           depth_raw = 0;  // the encoder's raw stream sizes (encoder::StreamBytes::raw)
  double encode_s = 0, encode_cpu_s = 0;
  std::string colour_format;  // as stored: "bc6h", "bc1", ...
  bool hdr = false;
  uint64_t colour_keyframes = 0, colour_cells = 0;
  double bc5_max_rel_error = 0;  // BC5 depth only
  // What the encode used: Q (psnr_auto: from the noise estimate), the estimate (dB, 0 = none or
  // not asked), the pre-filter's window and the texel-frames it averaged.
  double q_used = 0, noise_db = 0;
  uint32_t denoise_used = 0;
  uint64_t colour_denoised = 0;
  // Playback over the eye path (first frame excluded from the medians, reported apart).
  // decode: LightfieldDecoder::advance (what calf-play prints as "decode"); upload: the rest of
  // Playback::prepare (view selection, texture upload); render: Playback::render (GL: draw and
  // read-back).
  // *_cpu_ms: the process's CPU time over the same call (every thread: llvmpipe's, the decoder's
  // prefetch thread), which other load on a shared machine hardly changes.
  uint32_t frames = 0;
  double decode_ms = 0, upload_ms = 0, render_ms = 0;                    // medians of frames 2..n
  double prepare_cpu_ms = 0, render_cpu_ms = 0;                          // medians of frames 2..n
  double first_decode_ms = 0, first_upload_ms = 0, first_render_ms = 0;  // frame 1
  double mean_active_views = 0;
  double mean_mbps = 0;          // texture-update bitrate at 24 fps (decoder statistics)
  double psnr_db = 0, ssim = 0;  // means over the poses (a pose's PSNR capped at 100 dB)
  double worst_psnr_db = 0;
  // Pareto front membership within the scene (filled by the report).
  bool front_bytes = false, front_ms = false;
  // A frame's decode + upload + render, wall clock and CPU time.
  double total_ms() const { return decode_ms + upload_ms + render_ms; }
  double total_cpu_ms() const { return prepare_cpu_ms + render_cpu_ms; }
};

// A point and its result.
struct MeasuredPoint {
  SweepPoint point;
  PointResult result;
  // true when the point is the base configuration itself (its row repeats in every knob table).
  bool is_base = false;
};

// One row of a scene's peer table (tests/bench/ffmpeg_peers.h and the raw-stream coders).
struct PeerRow {
  std::string stream;  // "depth" or "colour"
  std::string method;
  bool available = false;
  uint64_t bytes = 0;
  uint64_t raw_bytes = 0;   // what this method codes
  uint64_t calf_bytes = 0;  // calf's bytes of the same stream (base configuration)
  double encode_s = 0;
  double decode_ms_per_frame = 0;     // the whole clip decoded, per frame
  double marginal_ms_per_frame = -1;  // ffmpeg: without its start-up (-1: not applicable)
  std::string quality;                // "exact", "44.1 dB", ...
  std::string note;
};

// Everything measured on one scene.
struct SceneResult {
  std::string scene;
  uint32_t views = 0, face_size = 0, frames = 0, gt_width = 0, gt_height = 0, poses = 0;
  bool material = false;
  double capture_s = 0, ground_truth_s = 0;
  std::vector<MeasuredPoint> points;  // base first
  // Per knob, the rows of its table: indices into `points` (the base's where a value is the base).
  std::vector<std::pair<Knob, std::vector<size_t>>> tables;
  std::vector<PeerRow> peers;
  std::string peer_notes;  // how the peers' inputs were made
};

}  // namespace calf::bench
