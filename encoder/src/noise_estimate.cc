// Render-noise estimate of a capture set's colour (calf/encoder/noise_estimate.h).
#include "calf/encoder/noise_estimate.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "calf/encoder/colour_denoise.h"
#include "calf/format/colour.h"
#include "lightfield_internal.h"

namespace calf::encoder {
namespace {

constexpr double kTopDb = 200;  // samples at or above this PSNR (or without energy) share a bin
constexpr size_t kBins = static_cast<size_t>(kTopDb / kNoiseBinDb) + 1;
// sigma^2 = M / kNoiseHighPassGain.
const double kResidualGainDb = 10.0 * std::log10(kNoiseHighPassGain);

double peak_squared(NoiseMetric m) {
  return m == NoiseMetric::kLog2 ? 64.0 : 1.0;
}

// Same depth and material in both frames (sky against sky counts as the same).
bool same_geometry(const capture::ViewFrame& a, const capture::ViewFrame& b, size_t i) {
  if (!(a.depth[i] == b.depth[i])) return false;
  if (a.has_material) {
    for (int c = 0; c < 3; ++c) {
      if (!(a.material[3 * i + c] == b.material[3 * i + c])) return false;
    }
  }
  return true;
}

Status validate(const NoiseEstimateOptions& o) {
  if (o.block < 4 || o.block > 64) {
    return Status(ErrorId::kEncoderOption,
                  "noise block " + std::to_string(o.block) + ": expected [4, 64]");
  }
  if (o.min_blocks < 1 || o.max_pairs < 1 || !(o.min_share >= 0 && o.min_share <= 1)) {
    return Status(ErrorId::kEncoderOption,
                  "noise estimate: min_blocks and max_pairs must be >= 1, min_share in [0, 1]");
  }
  return Status::Ok();
}

}  // namespace

float noise_metric_value(NoiseMetric m, float linear) {
  constexpr float kFloor = 1.0f / 16384.0f;  // psnr_log2's floor, 2^-14
  return m == NoiseMetric::kLog2 ? std::log2(std::max(linear, kFloor)) : srgb_from_linear(linear);
}

NoiseSamples::NoiseSamples() : bins_(kBins, 0) {}

void NoiseSamples::add_pair(const capture::ViewFrame& a, const capture::ViewFrame& b,
                            NoiseMetric metric, uint32_t block) {
  const uint32_t n = a.face_size;
  if (n < 3 || b.face_size != n || a.has_material != b.has_material || block == 0) return;
  const size_t face_texels = static_cast<size_t>(n) * n;
  std::vector<uint8_t> still(face_texels), eligible(face_texels), have(face_texels);
  std::vector<float> d(face_texels * 3);
  for (uint32_t face = 0; face < 6; ++face) {
    const size_t base = face * face_texels;
    for (size_t j = 0; j < face_texels; ++j) still[j] = same_geometry(a, b, base + j) ? 1 : 0;
    std::fill(eligible.begin(), eligible.end(), uint8_t{0});
    for (uint32_t y = 1; y + 1 < n; ++y) {
      for (uint32_t x = 1; x + 1 < n; ++x) {
        const size_t j = static_cast<size_t>(y) * n + x;
        eligible[j] = still[j] && still[j - 1] && still[j + 1] && still[j - n] && still[j + n];
      }
    }
    std::fill(have.begin(), have.end(), uint8_t{0});
    // d of face texel j, computed once.
    auto diff = [&](size_t j) -> const float* {
      if (!have[j]) {
        for (int c = 0; c < 3; ++c) {
          d[3 * j + c] = noise_metric_value(metric, b.color[3 * (base + j) + c]) -
                         noise_metric_value(metric, a.color[3 * (base + j) + c]);
        }
        have[j] = 1;
      }
      return &d[3 * j];
    };
    for (uint32_t by = 0; by < n; by += block) {
      for (uint32_t bx = 0; bx < n; bx += block) {
        const uint32_t x1 = std::min(n, bx + block), y1 = std::min(n, by + block);
        const uint64_t area = uint64_t{x1 - bx} * (y1 - by);
        ++examined_;
        uint64_t count = 0;
        bool changed = false;
        for (uint32_t y = by; y < y1; ++y) {
          for (uint32_t x = bx; x < x1; ++x) {
            const size_t j = static_cast<size_t>(y) * n + x;
            if (!eligible[j]) continue;
            ++count;
            for (int c = 0; c < 3 && !changed; ++c) {
              changed = a.color[3 * (base + j) + c] != b.color[3 * (base + j) + c];
            }
          }
        }
        // Too little static geometry, or nothing changed (static content: one keyframe at any Q).
        if (!changed || 2 * count < area) continue;
        double energy = 0;
        for (uint32_t y = by; y < y1; ++y) {
          for (uint32_t x = bx; x < x1; ++x) {
            const size_t j = static_cast<size_t>(y) * n + x;
            if (!eligible[j]) continue;
            const float* c0 = diff(j);
            const float *l = diff(j - 1), *r = diff(j + 1), *u = diff(j - n), *w = diff(j + n);
            for (int c = 0; c < 3; ++c) {
              const double res = double{c0[c]} -
                                 0.25 * (double{l[c]} + double{r[c]} + double{u[c]} + double{w[c]});
              energy += res * res;
            }
          }
        }
        energy /= static_cast<double>(3 * count);
        size_t bin = kBins - 1;
        if (energy > 0) {
          const double db = 10.0 * std::log10(peak_squared(metric) / energy);
          if (db < kTopDb) bin = static_cast<size_t>(std::max(0.0, db) / kNoiseBinDb);
        }
        bins_[std::min(bin, kBins - 1)] += 1;
        count_ += 1;
      }
    }
  }
}

void NoiseSamples::merge(const NoiseSamples& other) {
  for (size_t i = 0; i < kBins; ++i) bins_[i] += other.bins_[i];
  count_ += other.count_;
  examined_ += other.examined_;
}

NoiseEstimate NoiseSamples::estimate(uint64_t min_blocks, double min_share) const {
  NoiseEstimate e;
  e.samples = count_;
  if (count_ == 0 || count_ < min_blocks ||
      static_cast<double>(count_) < min_share * static_cast<double>(examined_)) {
    return e;
  }
  // The lower median of the samples' PSNR (the median block energy).
  const uint64_t rank = (count_ + 1) / 2;
  uint64_t seen = 0;
  size_t k = 0;
  for (; k < kBins; ++k) {
    seen += bins_[k];
    if (seen >= rank) break;
  }
  if (k >= kBins - 1) return e;  // noise-free: the median block has no measurable residual
  // Both metrics' peaks are inside the sample's PSNR already.
  e.psnr_db = (static_cast<double>(k) + 0.5) * kNoiseBinDb + kResidualGainDb;
  return e;
}

NoiseEstimate estimate_view_noise(std::span<const capture::ViewFrame> frames, NoiseMetric metric,
                                  const NoiseEstimateOptions& options) {
  if (!validate(options).ok()) return {};
  NoiseSamples s;
  for (size_t f = 1; f < frames.size(); ++f)
    s.add_pair(frames[f - 1], frames[f], metric, options.block);
  return s.estimate(options.min_blocks, options.min_share);
}

Expected<CaptureNoise> estimate_capture_noise(const capture::CaptureSetReader& input,
                                              ColourCoding colour,
                                              const NoiseEstimateOptions& options) {
  CALF_RETURN_IF_ERROR(validate(options));
  CALF_RETURN_IF_ERROR(input.check_files());
  const capture::CaptureManifest& m = input.manifest();
  const uint32_t n = static_cast<uint32_t>(m.viewpoints.size());
  const uint32_t frames = m.frame_count;
  // Which metrics to measure: the one the format implies, or both until the set's HDR-ness is
  // known (kAuto, and AV1, which codes LDR and HDR input alike).
  const bool from_input = colour == ColourCoding::kAuto || colour == ColourCoding::kAv1;
  const bool want_srgb = colour != ColourCoding::kBc6h && colour != ColourCoding::kRgba16f;
  const bool want_log2 = from_input || !want_srgb;
  // The measured pairs (f, f + 1): every one, or max_pairs spread evenly.
  const uint32_t pairs = frames > 1 ? frames - 1 : 0;
  std::vector<uint8_t> measured(frames, 0);
  if (pairs <= options.max_pairs) {
    for (uint32_t f = 0; f < pairs; ++f) measured[f] = 1;
  } else {
    for (uint32_t k = 0; k < options.max_pairs; ++k)
      measured[uint64_t{k} * pairs / options.max_pairs] = 1;
  }
  struct ViewResult {
    NoiseSamples srgb, log2;
    bool hdr = false;
    Status status;
  };
  std::vector<ViewResult> results(n);
  std::atomic<uint32_t> first_failure{n};
  tbb::task_arena arena(options.threads == 0 ? tbb::task_arena::automatic
                                             : static_cast<int>(options.threads));
  arena.execute([&] {
    tbb::parallel_for(
        tbb::blocked_range<uint32_t>(0, n, 1), [&](const tbb::blocked_range<uint32_t>& range) {
          for (uint32_t v = range.begin(); v < range.end(); ++v) {
            if (v > first_failure.load()) continue;
            ViewResult& r = results[v];
            capture::ViewFrame previous, current;
            for (uint32_t f = 0; f < frames && r.status.ok(); ++f) {
              r.status = lightfield_internal::read_frame(input, v, f, &current);
              if (!r.status.ok()) break;
              r.hdr = r.hdr || std::any_of(current.color.begin(), current.color.end(),
                                           [](float c) { return c > 1.0f; });
              if (f > 0 && measured[f - 1]) {
                if (want_srgb)
                  r.srgb.add_pair(previous, current, NoiseMetric::kSrgb, options.block);
                if (want_log2)
                  r.log2.add_pair(previous, current, NoiseMetric::kLog2, options.block);
              }
              std::swap(previous, current);
            }
            if (r.status.ok()) continue;
            uint32_t seen = first_failure.load();
            while (v < seen && !first_failure.compare_exchange_weak(seen, v)) {
            }
          }
        });
  });
  if (first_failure.load() < n) return results[first_failure.load()].status;

  CaptureNoise out;
  bool hdr = !want_srgb;
  if (from_input) {
    hdr = std::any_of(results.begin(), results.end(), [](const ViewResult& r) { return r.hdr; });
  }
  out.metric = hdr ? NoiseMetric::kLog2 : NoiseMetric::kSrgb;
  NoiseSamples all;
  for (const ViewResult& r : results) {
    const NoiseSamples& s = hdr ? r.log2 : r.srgb;
    out.views.push_back(s.estimate(options.min_blocks, options.min_share));
    all.merge(s);
  }
  out.set = all.estimate(options.min_blocks, options.min_share);
  return out;
}

Status check_lightfield_options(const LightfieldEncodeOptions& options) {
  return lightfield_internal::validate_options(options);
}

double auto_psnr_db(const NoiseEstimate& estimate, double margin, double cap) {
  if (!estimate.psnr_db) return cap;
  return std::clamp(*estimate.psnr_db - margin, std::min(kAutoPsnrFloorDb, cap), cap);
}

double auto_noise_psnr_db(const NoiseEstimate& estimate, double margin, double cap) {
  if (!estimate.psnr_db || !(auto_psnr_db(estimate, margin, cap) < cap)) return 0;
  return std::clamp(*estimate.psnr_db, 1e-3, 300.0);
}

Expected<CaptureNoise> apply_auto_psnr(const std::filesystem::path& dir, double margin,
                                       bool denoise_auto, LightfieldEncodeOptions* options) {
  LightfieldEncodeOptions& o = *options;
  CALF_RETURN_IF_ERROR(check_lightfield_options(o));
  CALF_ASSIGN_OR_RETURN(capture::CaptureSetReader input,
                        capture::CaptureSetReader::open(dir, o.max_image_pixels));
  NoiseEstimateOptions no;
  no.threads = o.threads;
  no.max_image_pixels = o.max_image_pixels;
  CALF_ASSIGN_OR_RETURN(CaptureNoise noise, estimate_capture_noise(input, o.colour, no));
  o.min_psnr_db = auto_psnr_db(noise.set, margin);
  o.noise_psnr_db = auto_noise_psnr_db(noise.set, margin);
  if (denoise_auto) {
    o.denoise_window =
        o.noise_psnr_db > 0 && o.colour != ColourCoding::kAv1 ? kDefaultDenoiseWindow : 0;
  }
  return noise;
}

}  // namespace calf::encoder
