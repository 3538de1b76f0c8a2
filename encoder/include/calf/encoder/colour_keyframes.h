// Temporal colour coding of one cell (paper 002, Sec. 5.1, Alg. 2, Eqs. 8-12): keyframes as far
// apart as possible such that every frame between two keyframes K_m, K_n, reconstructed as
// (1 - t) K_m + t K_n with its own best t quantised to 8 bits, stays above a quality threshold Q.
//
// Quality is judged on what the decoder will show: the keyframes come from a caller-supplied
// source that returns them *after* spatial compression and decompression (e.g. BC1 encode then
// decode), the t values after quantisation, and the metric is the caller's (e.g. PSNR on sRGB for
// LDR, an HDR-suitable one for HDR). The reference each frame is compared with is the original.
//
// All frames are linear RGB floats, `texels * 3` values per frame: the decoder interpolates in
// linear space (an sRGB texture is linearised by the sampler before the shader mixes).
//
// A cell whose trailing frames are all reproduced by the last keyframe alone (t = 0) does not pay
// for a final keyframe: a static cell costs exactly one keyframe.
#pragma once

#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include "calf/format/status.h"

namespace calf::encoder {

// Frame `f` of the cell as the decoder will show it if f is a keyframe. Called at most once per
// frame per select_cell_keyframes() call (results are cached), for candidate keyframes only; the
// span must stay valid until that call returns.
using ShownKeyframeFn = std::function<Expected<std::span<const float>>(uint32_t frame)>;
// Quality of `test` against `reference` in dB (higher is better; +inf for identical).
using CellQualityFn =
    std::function<double(std::span<const float> reference, std::span<const float> test)>;

enum class KeyframeSearch : uint8_t {
  // From keyframe m, try n = m+1, m+2, m+4, ... until a frame fails, then bisect between the last
  // success and the failure. O(L log L) quality evaluations per segment of length L; optimal when
  // quality falls monotonically with distance, which it does for smooth animation. Default.
  kGalloping,
  // The paper's argmax: the largest n in (m, N) whose whole segment passes, trying every n from
  // the end. O(N * L) evaluations; finds segments that return to an earlier state (cyclic motion).
  kExhaustive,
};

// The noise-aware test's model of one cell's render noise (measure_cell_noise).
struct CellNoise {
  uint32_t width = 0, height = 0;  // the cell in texels (frames are rows of RGB texels)
  bool log2 = false;  // the metric: log2 of max(v, 2^-14) over an 8-stop peak (HDR), else sRGB
  // Per block of kCellNoiseBlock x kCellNoiseBlock texels, row-major: the noise variance per
  // frame not charged for, relative to the metric's peak squared.
  std::vector<double> block_variance;
};
inline constexpr uint32_t kCellNoiseBlock = 8;

struct KeyframeOptions {
  double min_quality_db = 50.0;  // the paper's Q
  KeyframeSearch search = KeyframeSearch::kGalloping;
  // The noise-aware test (null = off). Render noise of variance s^2 per frame, independent between
  // frames, makes a frame reconstructed as (1 - w) K_m + w K_n differ from its own noisy input by
  // its signal error plus a noise part of expected variance (1 + (1 - w)^2 + w^2) s^2 (its own
  // noise and the keyframes', partly averaged). A frame that fails Q as measured still passes when
  // in every block the error less that part, with the block's s^2, keeps Q (the quality function
  // must then be PSNR in noise->log2's metric): noise spreads over the cell, a local change does
  // not hide in the cell's mean.
  const CellNoise* noise = nullptr;
};

struct CellKeyframes {
  // Increasing frame indices, always starting with 0.
  std::vector<uint32_t> keyframes;
  // Per frame, the interpolation weight t * 255 between the keyframes that bracket it (the last
  // keyframe <= frame and the next one > frame). A keyframe itself has t = 0, as does every frame
  // after the last keyframe (held).
  std::vector<uint8_t> t;
  // The lowest quality of any non-keyframe frame as reconstructed (+inf when every frame is a
  // keyframe or reconstructs exactly).
  double min_quality_db = 0;
};

// The best 8-bit t for reconstructing `frame` from `a` (t = 0) and `b` (t = 255): the closed-form
// least-squares t in linear space, clamped to [0, 1] and rounded (the rounded value is the best
// quantised one because the squared error is a parabola in t).
uint8_t best_interpolation_t(std::span<const float> frame, std::span<const float> a,
                             std::span<const float> b);

// (1 - t/255) a + (t/255) b into `out` (all the same size): exactly what the decoder computes.
void interpolate_keyframes(std::span<const float> a, std::span<const float> b, uint8_t t,
                           std::span<float> out);

// Alg. 2 over one cell: `frames` holds frame_count * texel_count * 3 floats, frame-major.
// Errors: sizes that do not match, a zero frame count, or an error from `shown` (passed through).
Expected<CellKeyframes> select_cell_keyframes(std::span<const float> frames, uint32_t frame_count,
                                              uint32_t texel_count, const ShownKeyframeFn& shown,
                                              const CellQualityFn& quality,
                                              const KeyframeOptions& options);

// The render noise of a cell's frames (frame_count frames of width x height RGB texels, as the
// keyframe test sees them) for the noise-aware test: per block, the difference d of consecutive
// frames in the metric goes through a spatial high-pass (d less the mean of its 4 neighbours',
// which cancels smooth signal change; white noise of variance s^2 per frame gives it 2.5 s^2);
// the median of its squares over the block's texels and every pair (a local change does not move
// it) gives s^2, times `factor`, at most max_variance. No pair, or blocks without change: 0.
CellNoise measure_cell_noise(std::span<const float> frames, uint32_t frame_count, uint32_t width,
                             uint32_t height, bool log2, double factor, double max_variance);

// PSNR in dB of two linear-RGB cells after both are encoded to sRGB and clamped to [0, 1]: what an
// LDR display shows. +inf when identical.
double psnr_srgb(std::span<const float> reference, std::span<const float> test);

}  // namespace calf::encoder
