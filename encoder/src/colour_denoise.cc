// Temporal pre-filter of render noise on static geometry (calf/encoder/colour_denoise.h).
#include "calf/encoder/colour_denoise.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "calf/encoder/noise_estimate.h"
#include "calf/format/bc.h"

namespace calf::encoder {
namespace {

// The median of chi-square with one degree of freedom: median(r^2) / var(r) for Gaussian r.
constexpr double kMedianOfSquares = 0.454936;
// A block with fewer high-pass samples than this has no noise measure (s^2 = 0: left as is).
constexpr size_t kMinSamples = 16;

// Every half float's linear value and its value in each metric (over the metric's peak), looked
// up rather than computed per texel and frame.
struct HalfTables {
  std::vector<float> linear, srgb, log2;
};

const HalfTables& half_tables() {
  static const HalfTables t = [] {
    HalfTables h;
    h.linear.resize(65536);
    h.srgb.resize(65536);
    h.log2.resize(65536);
    for (uint32_t i = 0; i < 65536; ++i) {
      const float v = bc::half_to_float(static_cast<uint16_t>(i));
      const float safe = std::isfinite(v) ? std::max(v, 0.0f) : 0.0f;
      h.linear[i] = v;
      h.srgb[i] = noise_metric_value(NoiseMetric::kSrgb, safe);
      h.log2[i] = noise_metric_value(NoiseMetric::kLog2, safe) / 8.0f;
    }
    return h;
  }();
  return t;
}

// One face of one view over one segment's frames.
class FaceFrames {
 public:
  FaceFrames(std::span<const uint16_t> colour, std::span<const uint16_t> depth,
             std::span<const uint8_t> material, uint32_t face, uint32_t n, const float* metric)
      : colour_(colour),
        depth_(depth),
        material_(material),
        frame_texels_(size_t{6} * n * n),
        face_base_(size_t{face} * n * n),
        n_(n),
        metric_(metric) {}

  uint32_t n() const { return n_; }
  size_t texel(uint32_t f, uint32_t x, uint32_t y) const {
    return f * frame_texels_ + face_base_ + size_t{y} * n_ + x;
  }
  uint16_t half(uint32_t f, uint32_t x, uint32_t y, int c) const {
    return colour_[3 * texel(f, x, y) + c];
  }
  float metric(uint32_t f, uint32_t x, uint32_t y, int c) const {
    return metric_[half(f, x, y, c)];
  }

  // The same depth and material codes at (x, y) in frames f and g.
  bool same_geometry_at(uint32_t f, uint32_t g, uint32_t x, uint32_t y) const {
    const size_t a = texel(f, x, y), b = texel(g, x, y);
    if (depth_[a] != depth_[b]) return false;
    if (material_.empty()) return true;
    return material_[3 * a] == material_[3 * b] && material_[3 * a + 1] == material_[3 * b + 1] &&
           material_[3 * a + 2] == material_[3 * b + 2];
  }

  // (x, y) and its 4 neighbours inside the face keep their geometry between f and g.
  bool static_between(uint32_t f, uint32_t g, uint32_t x, uint32_t y) const {
    return same_geometry_at(f, g, x, y) && (x == 0 || same_geometry_at(f, g, x - 1, y)) &&
           (x + 1 == n_ || same_geometry_at(f, g, x + 1, y)) &&
           (y == 0 || same_geometry_at(f, g, x, y - 1)) &&
           (y + 1 == n_ || same_geometry_at(f, g, x, y + 1));
  }

 private:
  std::span<const uint16_t> colour_, depth_;
  std::span<const uint8_t> material_;
  size_t frame_texels_, face_base_;
  uint32_t n_;
  const float* metric_;
};

// s^2 of every 8 x 8 block of the face over frames [s0, s1), row-major (see the header).
std::vector<double> block_variances(const FaceFrames& ff, uint32_t s0, uint32_t s1,
                                    double max_variance) {
  const uint32_t n = ff.n();
  const uint32_t blocks = (n + kDenoiseBlock - 1) / kDenoiseBlock;
  std::vector<std::vector<float>> squares(size_t{blocks} * blocks);
  for (uint32_t g = s0 + 1; g < s1; ++g) {
    auto d = [&](uint32_t x, uint32_t y, int c) {
      return ff.metric(g, x, y, c) - ff.metric(g - 1, x, y, c);
    };
    for (uint32_t y = 1; y + 1 < n; ++y) {
      for (uint32_t x = 1; x + 1 < n; ++x) {
        if (!ff.static_between(g - 1, g, x, y)) continue;
        std::vector<float>& block = squares[size_t{y / kDenoiseBlock} * blocks + x / kDenoiseBlock];
        for (int c = 0; c < 3; ++c) {
          const float r = d(x, y, c) - 0.25f * (d(x - 1, y, c) + d(x + 1, y, c) + d(x, y - 1, c) +
                                                d(x, y + 1, c));
          block.push_back(r * r);
        }
      }
    }
  }
  std::vector<double> variance(squares.size(), 0.0);
  for (size_t i = 0; i < squares.size(); ++i) {
    std::vector<float>& s = squares[i];
    if (s.size() < kMinSamples) continue;
    auto mid = s.begin() + static_cast<std::ptrdiff_t>(s.size() / 2);
    std::nth_element(s.begin(), mid, s.end());
    variance[i] = std::min(max_variance, double{*mid} / kMedianOfSquares / kNoiseHighPassGain);
  }
  return variance;
}

// Whether frame g counts for texel (x, y) of frame f: static geometry, and a change that noise
// of standard deviation `sigma` explains at the texel and over its 3 x 3 neighbourhood.
bool noise_only(const FaceFrames& ff, uint32_t f, uint32_t g, uint32_t x, uint32_t y,
                double limit) {
  if (!ff.static_between(f, g, x, y)) return false;
  const uint32_t n = ff.n();
  const uint32_t x0 = x > 0 ? x - 1 : x, x1 = std::min(n - 1, x + 1);
  const uint32_t y0 = y > 0 ? y - 1 : y, y1 = std::min(n - 1, y + 1);
  const double count = static_cast<double>((x1 - x0 + 1) * (y1 - y0 + 1));
  for (int c = 0; c < 3; ++c) {
    if (!(std::abs(double{ff.metric(g, x, y, c)} - ff.metric(f, x, y, c)) <= limit)) return false;
    double sum = 0;
    for (uint32_t yy = y0; yy <= y1; ++yy) {
      for (uint32_t xx = x0; xx <= x1; ++xx) {
        sum += double{ff.metric(g, xx, yy, c)} - ff.metric(f, xx, yy, c);
      }
    }
    if (!(std::abs(sum / count) <= limit / std::sqrt(count))) return false;
  }
  return true;
}

// Filters one face over frames [s0, s1) into `out` (the face's texels of those frames, frame
// after frame, half RGB).
StaticDenoiseStats filter_face(const FaceFrames& ff, uint32_t s0, uint32_t s1,
                               const StaticDenoiseOptions& o, std::vector<uint16_t>& out) {
  const HalfTables& tables = half_tables();
  const uint32_t n = ff.n();
  const size_t face_values = size_t{n} * n * 3;
  const uint32_t len = s1 - s0;
  const uint32_t w = std::min(o.window, len);
  const std::vector<double> variance = block_variances(ff, s0, s1, o.max_variance);
  const uint32_t blocks = (n + kDenoiseBlock - 1) / kDenoiseBlock;
  StaticDenoiseStats stats;
  out.resize(face_values * len);
  for (uint32_t f = s0; f < s1; ++f) {
    // The window [a, a + w): as centred on f as the segment allows.
    const uint32_t a =
        static_cast<uint32_t>(std::clamp<int64_t>(int64_t{f} - (w - 1) / 2, s0, s1 - w));
    for (uint32_t y = 0; y < n; ++y) {
      for (uint32_t x = 0; x < n; ++x) {
        uint16_t* dst = &out[(f - s0) * face_values + (size_t{y} * n + x) * 3];
        stats.texels += 1;
        const double v = variance[size_t{y / kDenoiseBlock} * blocks + x / kDenoiseBlock];
        for (int c = 0; c < 3; ++c) dst[c] = ff.half(f, x, y, c);
        if (!(v > 0) || w < 2) continue;  // no measured noise: nothing is averaged
        const double limit = o.sigmas * std::sqrt(2.0 * v);
        double sum[3] = {0, 0, 0};
        uint32_t count = 0;
        auto take = [&](uint32_t g) {
          for (int c = 0; c < 3; ++c) sum[c] += tables.linear[ff.half(g, x, y, c)];
          ++count;
        };
        take(f);
        for (uint32_t g = f; g > a && noise_only(ff, f, g - 1, x, y, limit); --g) take(g - 1);
        for (uint32_t g = f + 1; g < a + w && noise_only(ff, f, g, x, y, limit); ++g) take(g);
        if (count < 2) continue;
        stats.averaged += 1;
        for (int c = 0; c < 3; ++c) {
          const float mean = static_cast<float>(sum[c] / count);
          dst[c] = bc::float_to_half(std::clamp(mean, 0.0f, 65504.0f));
        }
      }
    }
  }
  return stats;
}

}  // namespace

Expected<StaticDenoiseStats> denoise_static_colour(std::span<uint16_t> colour,
                                                   std::span<const uint16_t> depth,
                                                   std::span<const uint8_t> material,
                                                   uint32_t frames, uint32_t face_size,
                                                   const StaticDenoiseOptions& options) {
  const size_t texels = size_t{6} * face_size * face_size * frames;
  if (colour.size() != texels * 3 || depth.size() != texels ||
      !(material.empty() || material.size() == texels * 3)) {
    return Status(ErrorId::kInvalidArgument,
                  "denoise: " + std::to_string(colour.size()) + " colour values, " +
                      std::to_string(depth.size()) + " depth codes and " +
                      std::to_string(material.size()) + " material codes for " +
                      std::to_string(frames) + " frames of 6 faces of " +
                      std::to_string(face_size) + "^2 texels");
  }
  if (options.window < 1 || options.window > kMaxDenoiseWindow || !(options.sigmas > 0) ||
      !std::isfinite(options.sigmas) || !(options.max_variance >= 0)) {
    return Status(ErrorId::kInvalidArgument,
                  "denoise: window " + std::to_string(options.window) + " (expected 1.." +
                      std::to_string(kMaxDenoiseWindow) + "), sigmas " +
                      std::to_string(options.sigmas) + " (expected > 0), max variance " +
                      std::to_string(options.max_variance) + " (expected >= 0)");
  }
  StaticDenoiseStats total;
  total.texels = texels;
  if (options.window < 2 || frames < 2 || face_size == 0) return total;
  const HalfTables& tables = half_tables();
  const float* metric = options.log2 ? tables.log2.data() : tables.srgb.data();
  const uint32_t seg = options.segment_frames ? options.segment_frames : frames;
  const uint32_t segments = (frames + seg - 1) / seg;
  // One task per (segment, face): each reads and writes only its own face's frames of its own
  // segment, so tasks never see each other's output.
  std::vector<StaticDenoiseStats> stats(size_t{segments} * 6);
  const std::span<const uint16_t> input(colour.data(), colour.size());
  tbb::task_arena arena(options.threads == 0 ? tbb::task_arena::automatic
                                             : static_cast<int>(options.threads));
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, stats.size(), 1),
                      [&](const tbb::blocked_range<size_t>& range) {
                        std::vector<uint16_t> out;
                        for (size_t i = range.begin(); i < range.end(); ++i) {
                          const uint32_t s0 = static_cast<uint32_t>(i / 6) * seg;
                          const uint32_t s1 = std::min(frames, s0 + seg);
                          const uint32_t face = static_cast<uint32_t>(i % 6);
                          const FaceFrames ff(input, depth, material, face, face_size, metric);
                          stats[i] = filter_face(ff, s0, s1, options, out);
                          const size_t face_values = size_t{face_size} * face_size * 3;
                          for (uint32_t f = s0; f < s1; ++f) {
                            std::copy_n(&out[(f - s0) * face_values], face_values,
                                        &colour[3 * ff.texel(f, 0, 0)]);
                          }
                        }
                      });
  });
  for (const StaticDenoiseStats& s : stats) total.averaged += s.averaged;
  return total;
}

}  // namespace calf::encoder
