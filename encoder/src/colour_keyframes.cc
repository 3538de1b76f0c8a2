#include "calf/encoder/colour_keyframes.h"

#include "calf/format/colour.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <string>

namespace calf::encoder {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

// Alg. 2's state for one cell: original frames, the keyframes as shown (cached), scratch space.
class CellSearch {
 public:
  CellSearch(std::span<const float> frames, uint32_t frame_count, size_t frame_size,
             const ShownKeyframeFn& shown, const CellQualityFn& quality, double min_quality)
      : frames_(frames),
        frame_size_(frame_size),
        shown_(shown),
        quality_(quality),
        min_quality_(min_quality),
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

  // Whether every frame strictly between m and n passes (Eq. 11's indicator).
  Expected<bool> segment_passes(uint32_t m, uint32_t n) {
    for (uint32_t x = m + 1; x < n; ++x) {
      CALF_ASSIGN_OR_RETURN(auto qt, reconstruct(x, m, n));
      if (!(qt.first >= min_quality_)) return false;
    }
    return true;
  }

  // Whether every frame after m up to and including `last` is reproduced by K_m alone (t = 0).
  Expected<bool> holds(uint32_t m, uint32_t last) {
    CALF_ASSIGN_OR_RETURN(std::span<const float> a, keyframe(m));
    for (uint32_t x = m + 1; x <= last; ++x) {
      if (!(quality_(frame(x), a) >= min_quality_)) return false;
    }
    return true;
  }

 private:
  std::span<const float> frames_;
  size_t frame_size_;
  const ShownKeyframeFn& shown_;
  const CellQualityFn& quality_;
  double min_quality_;
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
  CellSearch search(frames, frame_count, frame_size, shown, quality, options.min_quality_db);
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
