// Render noise of a capture set's colour, as a PSNR figure the colour keyframe test can be set
// against (calf-encode --psnr auto; docs/ENCODER.md "Keyframes and render noise").
//
// A path tracer's noise that changes from frame to frame makes interpolating two keyframes fail
// Q wherever Q lies above the noise: every frame of such a cell becomes a keyframe, and the bytes
// buy nothing but a different draw of the same noise. The estimate says where that level is.
//
// Method (temporal, robust). For a pair of consecutive frames, a texel is on static geometry
// when its depth and material and those of its 4 neighbours are the same in both frames (texels
// on a face's border are left out). There the colour difference d = m(b) - m(a), in the metric m
// of the keyframe test (sRGB-encoded values for LDR colour, log2 of max(v, 2^-14) for HDR:
// psnr_srgb, psnr_log2), is signal change plus the difference of two noise draws. A spatial
// high-pass r = d - (sum of the 4 neighbours' d) / 4 removes smooth signal change (lighting,
// exposure); for white noise of variance s^2 in d it has variance 1.25 s^2. The mean of r^2 over
// each block of B x B texels (at least half of them on static geometry) is one sample; blocks
// whose colour did not change at all (static content, which costs one keyframe whatever Q is) are
// left out. The median over every sample of the set (robust against blocks with edges or motion)
// is M; a frame's noise variance is then sigma^2 = M / (2 * 1.25), and the estimate
// 10 log10(peak^2 / sigma^2) dB, peak 1 (sRGB) or 8 stops (log2): the PSNR of one frame against
// its noise-free self, when frames carry independent noise.
//
// Noise that is the same in every frame (a renderer with a fixed seed on static content) does not
// change from frame to frame and costs no keyframes: it is not measured. A set of one frame, or
// one where fewer than min_blocks samples, or fewer than min_share of all the blocks examined,
// changed on static geometry, has no estimate: a few changing blocks (shading beside a moving
// part of converged content) say more about that content than about noise.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <vector>

#include "calf/capture/capture_set.h"
#include "calf/encoder/lightfield_encode.h"
#include "calf/format/status.h"

namespace calf::encoder {

// The metric of the colour keyframe test: kSrgb = PSNR on sRGB-encoded values (LDR colour),
// kLog2 = log2-PSNR with an 8-stop peak (HDR colour).
enum class NoiseMetric : uint8_t { kSrgb, kLog2 };

// A linear colour value in `m`: its sRGB encoding, or log2 of it (at least 2^-14, psnr_log2's
// floor). The estimate and the keyframe test's noise model measure in it.
float noise_metric_value(NoiseMetric m, float linear);

// The variance of the high-pass r = d - mean of d's 4 neighbours over one frame's noise variance,
// for d the difference of two frames with independent white noise: 2 (d) x 1.25 (r).
constexpr double kNoiseHighPassGain = 2.5;

struct NoiseEstimateOptions {
  uint32_t block = 8;        // B, the block side in texels, 4..64
  uint64_t min_blocks = 16;  // fewer samples than this: no estimate, >= 1
  double min_share = 0.02;   // fewer samples than this share of the blocks examined: none
  uint32_t max_pairs = 8;    // consecutive frame pairs measured per view, evenly spread, >= 1
  uint32_t threads = 1;      // views read at once; 0 = all cores; never changes the result
  uint64_t max_image_pixels = capture::kDefaultMaxImagePixels;  // CaptureSetReader::open's
};

// The resolution of an estimate (its samples are binned by their PSNR in steps of this many dB).
inline constexpr double kNoiseBinDb = 0.02;

struct NoiseEstimate {
  std::optional<double> psnr_db;  // none: too few samples (see above)
  uint64_t samples = 0;           // blocks x frame pairs measured
};

// The estimate of a whole capture set.
struct CaptureNoise {
  NoiseMetric metric = NoiseMetric::kSrgb;  // the keyframe test's metric for this set
  NoiseEstimate set;                        // over every view's samples together
  std::vector<NoiseEstimate> views;         // per view, manifest order
};

// Samples of several frame pairs, mergeable in any order with the same result.
class NoiseSamples {
 public:
  NoiseSamples();
  // Adds the samples of frames a and b (consecutive frames of one view: same face size and
  // material presence) in `metric`.
  void add_pair(const capture::ViewFrame& a, const capture::ViewFrame& b, NoiseMetric metric,
                uint32_t block);
  void merge(const NoiseSamples& other);
  NoiseEstimate estimate(uint64_t min_blocks, double min_share) const;
  uint64_t count() const { return count_; }

 private:
  std::vector<uint64_t> bins_;  // by a sample's own PSNR, kNoiseBinDb wide
  uint64_t count_ = 0;          // samples
  uint64_t examined_ = 0;       // blocks examined, samples or not
};

// The estimate of one view's frames (in frame order) in `metric`, over every consecutive pair
// (max_pairs and threads ignored). Invalid options: no estimate.
NoiseEstimate estimate_view_noise(std::span<const capture::ViewFrame> frames, NoiseMetric metric,
                                  const NoiseEstimateOptions& options);

// Reads every frame of every view of `input` once (the set's HDR-ness needs every frame) and
// measures options.max_pairs pairs per view. The metric follows the colour format as the encoder
// resolves it: kLog2 for BC6H / RGBA16F, and for kAuto and AV1 when some colour value exceeds 1.
// Errors: kEncoderOption (options out of range); the capture reader's; kEncoderInput (a frame
// whose face size or material presence differs from the manifest).
Expected<CaptureNoise> estimate_capture_noise(const capture::CaptureSetReader& input,
                                              ColourCoding colour,
                                              const NoiseEstimateOptions& options);

// The light-field encoder's own option check (kEncoderOption naming the flag), for a caller that
// estimates the noise before it encodes: a bad option is reported before any image is read.
Status check_lightfield_options(const LightfieldEncodeOptions& options);

// --psnr auto: Q = min(cap, estimate - margin), never below kAutoPsnrFloorDb; `cap` (50, the
// encoder's default Q) without an estimate.
inline constexpr double kAutoPsnrCapDb = 50;
inline constexpr double kAutoPsnrFloorDb = 10;
// The margin calf-encode uses unless told (docs/ENCODER.md "Keyframes and render noise").
inline constexpr double kDefaultPsnrNoiseMargin = 3;
double auto_psnr_db(const NoiseEstimate& estimate, double margin, double cap = kAutoPsnrCapDb);

// --psnr auto's noise-aware keyframe test (LightfieldEncodeOptions::noise_psnr_db): the estimate,
// or 0 (off) without one and where Q = auto_psnr_db(estimate, margin, cap) is the cap (content
// whose noise lies far below Q codes as with a number).
double auto_noise_psnr_db(const NoiseEstimate& estimate, double margin,
                          double cap = kAutoPsnrCapDb);

// --psnr auto as calf-encode applies it: checks `options`, estimates the render noise of the
// capture set at `dir` (estimate_capture_noise with options' threads and image limit) and sets
// options->min_psnr_db = auto_psnr_db and noise_psnr_db = auto_noise_psnr_db with `margin`; with
// `denoise_auto` (--denoise-window auto) also options->denoise_window: kDefaultDenoiseWindow
// (colour_denoise.h) where the noise-aware test is on and colour is not AV1, else 0. Returns the
// estimate. Errors: check_lightfield_options', the capture set's, estimate_capture_noise's.
Expected<CaptureNoise> apply_auto_psnr(const std::filesystem::path& dir, double margin,
                                       bool denoise_auto, LightfieldEncodeOptions* options);

}  // namespace calf::encoder
