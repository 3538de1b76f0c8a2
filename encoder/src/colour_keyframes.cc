#include "calf/encoder/colour_keyframes.h"

#include "calf/encoder/noise_estimate.h"
#include "calf/format/colour.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <string>

namespace calf::encoder {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

// A value in the noise model's metric, over its peak (8 stops for log2, 1 for sRGB).
double metric_value(float v, bool log2) {
  return log2 ? noise_metric_value(NoiseMetric::kLog2, v) / 8.0
              : noise_metric_value(NoiseMetric::kSrgb, v);
}

// The median of chi-square with one degree of freedom: median(r^2) / var(r) for Gaussian r.
constexpr double kMedianOfSquares = 0.454936;

// Whether `test` (reconstructed at weight t / 255) passes for `reference` under the noise-aware
// test (KeyframeOptions::noise).
bool noise_aware_passes(const CellNoise& noise, std::span<const float> reference,
                        std::span<const float> test, uint8_t t, double min_quality_db) {
  const double w = t / 255.0;
  const double parts = 1.0 + (1.0 - w) * (1.0 - w) + w * w;
  const double max_error = std::pow(10.0, -min_quality_db / 10.0);
  const uint32_t bx_count = (noise.width + kCellNoiseBlock - 1) / kCellNoiseBlock;
  const uint32_t by_count = (noise.height + kCellNoiseBlock - 1) / kCellNoiseBlock;
  if (noise.block_variance.size() != size_t{bx_count} * by_count ||
      reference.size() != size_t{noise.width} * noise.height * 3 ||
      test.size() != reference.size()) {
    return false;
  }
  for (uint32_t by = 0; by < by_count; ++by) {
    for (uint32_t bx = 0; bx < bx_count; ++bx) {
      double sum = 0;
      size_t count = 0;
      const uint32_t y1 = std::min(noise.height, (by + 1) * kCellNoiseBlock);
      const uint32_t x1 = std::min(noise.width, (bx + 1) * kCellNoiseBlock);
      for (uint32_t y = by * kCellNoiseBlock; y < y1; ++y) {
        for (size_t i = (size_t{y} * noise.width + bx * kCellNoiseBlock) * 3;
             i < (size_t{y} * noise.width + x1) * 3; ++i) {
          const double d =
              metric_value(reference[i], noise.log2) - metric_value(test[i], noise.log2);
          sum += d * d;
          ++count;
        }
      }
      const double expected = parts * noise.block_variance[size_t{by} * bx_count + bx];
      if (!(sum / static_cast<double>(count) - expected <= max_error)) return false;
    }
  }
  return true;
}

// Alg. 2's state for one cell: original frames, the keyframes as shown (cached), scratch space.
class CellSearch {
 public:
  CellSearch(std::span<const float> frames, uint32_t frame_count, size_t frame_size,
             const ShownKeyframeFn& shown, const CellQualityFn& quality,
             const KeyframeOptions& options)
      : frames_(frames),
        frame_size_(frame_size),
        shown_(shown),
        quality_(quality),
        min_quality_(options.min_quality_db),
        noise_(options.noise),
        cache_(frame_count),
        scratch_(frame_size) {}

  std::span<const float> frame(uint32_t f) const {
    return frames_.subspan(static_cast<size_t>(f) * frame_size_, frame_size_);
  }

  Expected<std::span<const float>> keyframe(uint32_t f) {
    if (!cache_[f]) {
      CALF_ASSIGN_OR_RETURN(std::span<const float> k, shown_(f));
      if (k.size() != frame_size_) {
        return Status(ErrorId::kInternal, "shown keyframe " + std::to_string(f) + " has " +
                                              std::to_string(k.size()) + " values, expected " +
                                              std::to_string(frame_size_));
      }
      cache_[f] = k;
    }
    return *cache_[f];
  }

  // The quality of frame x reconstructed from keyframes m and n, and its t.
  Expected<std::pair<double, uint8_t>> reconstruct(uint32_t x, uint32_t m, uint32_t n) {
    CALF_ASSIGN_OR_RETURN(std::span<const float> a, keyframe(m));
    CALF_ASSIGN_OR_RETURN(std::span<const float> b, keyframe(n));
    const uint8_t t = best_interpolation_t(frame(x), a, b);
    interpolate_keyframes(a, b, t, scratch_);
    return std::pair{quality_(frame(x), scratch_), t};
  }

  // Whether frame x reconstructed as `test` at weight t, of quality q, passes: q >= Q, or the
  // noise-aware test.
  bool passes(double q, uint32_t x, std::span<const float> test, uint8_t t) const {
    if (q >= min_quality_) return true;
    return noise_ != nullptr && noise_aware_passes(*noise_, frame(x), test, t, min_quality_);
  }

  // Whether every frame strictly between m and n passes (Eq. 11's indicator).
  Expected<bool> segment_passes(uint32_t m, uint32_t n) {
    for (uint32_t x = m + 1; x < n; ++x) {
      CALF_ASSIGN_OR_RETURN(auto qt, reconstruct(x, m, n));
      if (!passes(qt.first, x, scratch_, qt.second)) return false;
    }
    return true;
  }

  // Whether every frame after m up to and including `last` is reproduced by K_m alone (t = 0).
  Expected<bool> holds(uint32_t m, uint32_t last) {
    CALF_ASSIGN_OR_RETURN(std::span<const float> a, keyframe(m));
    for (uint32_t x = m + 1; x <= last; ++x) {
      if (!passes(quality_(frame(x), a), x, a, 0)) return false;
    }
    return true;
  }

 private:
  std::span<const float> frames_;
  size_t frame_size_;
  const ShownKeyframeFn& shown_;
  const CellQualityFn& quality_;
  double min_quality_;
  const CellNoise* noise_;
  std::vector<std::optional<std::span<const float>>> cache_;
  std::vector<float> scratch_;
};

// The next keyframe after m: the largest n whose segment passes (n = m + 1 always does).
Expected<uint32_t> next_keyframe(CellSearch& search, uint32_t m, uint32_t last,
                                 KeyframeSearch mode) {
  if (mode == KeyframeSearch::kExhaustive) {
    for (uint32_t n = last; n > m + 1; --n) {
      CALF_ASSIGN_OR_RETURN(bool ok, search.segment_passes(m, n));
      if (ok) return n;
    }
    return m + 1;
  }
  uint32_t good = m + 1, bad = 0;
  for (uint64_t d = 2;; d *= 2) {
    const uint32_t n = static_cast<uint32_t>(std::min<uint64_t>(m + d, last));
    if (n <= good) break;
    CALF_ASSIGN_OR_RETURN(bool ok, search.segment_passes(m, n));
    if (!ok) {
      bad = n;
      break;
    }
    good = n;
    if (n == last) break;
  }
  if (bad == 0) return good;
  while (bad - good > 1) {
    const uint32_t mid = good + (bad - good) / 2;
    CALF_ASSIGN_OR_RETURN(bool ok, search.segment_passes(m, mid));
    (ok ? good : bad) = mid;
  }
  return good;
}

}  // namespace

uint8_t best_interpolation_t(std::span<const float> frame, std::span<const float> a,
                             std::span<const float> b) {
  // Minimise |x - a - t (b - a)|^2: t = <x - a, b - a> / |b - a|^2.
  double num = 0, den = 0;
  for (size_t i = 0; i < frame.size(); ++i) {
    const double d = static_cast<double>(b[i]) - a[i];
    num += (static_cast<double>(frame[i]) - a[i]) * d;
    den += d * d;
  }
  if (!(den > 0)) return 0;  // identical keyframes: any t, pick 0
  const double t = std::clamp(num / den, 0.0, 1.0);
  return static_cast<uint8_t>(std::lround(t * 255.0));
}

void interpolate_keyframes(std::span<const float> a, std::span<const float> b, uint8_t t,
                           std::span<float> out) {
  const float w = t / 255.0f;
  for (size_t i = 0; i < out.size(); ++i) out[i] = (1.0f - w) * a[i] + w * b[i];
}

Expected<CellKeyframes> select_cell_keyframes(std::span<const float> frames, uint32_t frame_count,
                                              uint32_t texel_count, const ShownKeyframeFn& shown,
                                              const CellQualityFn& quality,
                                              const KeyframeOptions& options) {
  const size_t frame_size = static_cast<size_t>(texel_count) * 3;
  if (frame_count == 0 || texel_count == 0 || frames.size() != frame_size * frame_count) {
    return Status(ErrorId::kInvalidArgument, "colour cell: " + std::to_string(frames.size()) +
                                                 " values for " + std::to_string(frame_count) +
                                                 " frames of " + std::to_string(texel_count) +
                                                 " RGB texels");
  }
  CellSearch search(frames, frame_count, frame_size, shown, quality, options);
  CellKeyframes out;
  out.keyframes.push_back(0);
  out.t.assign(frame_count, 0);
  out.min_quality_db = kInfinity;
  const uint32_t last = frame_count - 1;
  uint32_t m = 0;
  while (m < last) {
    // A tail that the current keyframe reproduces on its own needs no further keyframe.
    CALF_ASSIGN_OR_RETURN(bool hold, search.holds(m, last));
    if (hold) {
      CALF_ASSIGN_OR_RETURN(std::span<const float> a, search.keyframe(m));
      for (uint32_t x = m + 1; x <= last; ++x) {
        out.min_quality_db = std::min(out.min_quality_db, quality(search.frame(x), a));
      }
      break;
    }
    CALF_ASSIGN_OR_RETURN(uint32_t n, next_keyframe(search, m, last, options.search));
    for (uint32_t x = m + 1; x < n; ++x) {
      CALF_ASSIGN_OR_RETURN(auto qt, search.reconstruct(x, m, n));
      out.t[x] = qt.second;
      out.min_quality_db = std::min(out.min_quality_db, qt.first);
    }
    out.keyframes.push_back(n);
    m = n;
  }
  return out;
}

CellNoise measure_cell_noise(std::span<const float> frames, uint32_t frame_count, uint32_t width,
                             uint32_t height, bool log2, double factor, double max_variance) {
  CellNoise out;
  out.width = width;
  out.height = height;
  out.log2 = log2;
  const uint32_t bx_count = (width + kCellNoiseBlock - 1) / kCellNoiseBlock;
  const uint32_t by_count = (height + kCellNoiseBlock - 1) / kCellNoiseBlock;
  out.block_variance.assign(size_t{bx_count} * by_count, 0.0);
  const size_t n = size_t{width} * height * 3;
  if (frame_count < 2 || width < 3 || height < 3 || frames.size() < n * frame_count) return out;
  // Per block, the squared high-passed differences of every pair (texels on the cell's border,
  // without 4 neighbours, are left out).
  std::vector<std::vector<double>> squares(out.block_variance.size());
  std::vector<double> d(n);
  for (uint32_t f = 1; f < frame_count; ++f) {
    const float* a = &frames[(f - 1) * n];
    const float* b = &frames[f * n];
    for (size_t i = 0; i < n; ++i) d[i] = metric_value(b[i], log2) - metric_value(a[i], log2);
    for (uint32_t y = 1; y + 1 < height; ++y) {
      for (uint32_t x = 1; x + 1 < width; ++x) {
        std::vector<double>& block =
            squares[size_t{y / kCellNoiseBlock} * bx_count + x / kCellNoiseBlock];
        for (uint32_t c = 0; c < 3; ++c) {
          auto at = [&](uint32_t xx, uint32_t yy) { return d[(size_t{yy} * width + xx) * 3 + c]; };
          const double r =
              at(x, y) - (at(x - 1, y) + at(x + 1, y) + at(x, y - 1) + at(x, y + 1)) / 4;
          block.push_back(r * r);
        }
      }
    }
  }
  for (size_t i = 0; i < squares.size(); ++i) {
    std::vector<double>& s = squares[i];
    if (s.empty()) continue;
    auto mid = s.begin() + static_cast<std::ptrdiff_t>(s.size() / 2);
    std::nth_element(s.begin(), mid, s.end());
    out.block_variance[i] =
        std::min(max_variance, factor * *mid / kMedianOfSquares / kNoiseHighPassGain);
  }
  return out;
}

double psnr_srgb(std::span<const float> reference, std::span<const float> test) {
  double sum = 0;
  for (size_t i = 0; i < reference.size(); ++i) {
    const double d = srgb_from_linear(reference[i]) - srgb_from_linear(test[i]);
    sum += d * d;
  }
  if (sum == 0 || reference.empty()) return kInfinity;
  return 10.0 * std::log10(static_cast<double>(reference.size()) / sum);
}

}  // namespace calf::encoder
