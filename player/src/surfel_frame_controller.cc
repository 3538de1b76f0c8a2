// The surfel frame-time controller; the model and its rules are in the public header.
#include "calf/player/surfel_frame_controller.h"

#include <algorithm>
#include <cmath>

namespace calf::player {
namespace {

// Below this coefficient of variation of the recent work, a fitted slope is mostly noise.
constexpr double kMinSpread = 0.05;
// Bisection steps on log s: 2^-40 of the range, far below a prefix's rounding.
constexpr int kBisections = 40;
// The smallest slope a fit may take, as a share of the mean time per unit of work.
constexpr double kMinSlopeShare = 0.1;

}  // namespace

void SurfelFrameController::Fit::add(double work, double ms, double memory) {
  w = memory * w + 1;
  x = memory * x + work;
  y = memory * y + ms;
  xx = memory * xx + work * work;
  xy = memory * xy + work * ms;
  const double mx = x / w, my = y / w;
  const double ratio = mx > 0 ? my / mx : 0;
  const double var = std::max(0.0, xx / w - mx * mx);
  const double fitted = var > kMinSpread * kMinSpread * mx * mx ? (xy / w - mx * my) / var : -1;
  // A fit is kept only when it is physical: more work never costs less (a negative slope is a
  // change of load or noise across the spread, not the pass's cost). Before the first, half the
  // time is taken as fixed, half as proportional: a guess the first spread of work replaces.
  if (fitted >= 0) {
    slope = fitted;
  } else if (slope < 0) {
    slope = 0.5 * ratio;
  }
  // No negative fixed part; and at least kMinSlopeShare of the time proportional, so that the
  // model never concludes the work does not matter (then any size would do).
  slope = std::clamp(slope, kMinSlopeShare * ratio, ratio);
}

double SurfelFrameController::Fit::predict(double work) const {
  if (work <= 0 || w <= 0) return 0;  // the pass is skipped, or never measured
  const double mx = x / w, my = y / w;
  return std::max(0.0, my + slope * (work - mx));
}

SurfelFrameController::SurfelFrameController(const SurfelControllerOptions& options,
                                             double point_size)
    : options_(options), size_(point_size) {}

double SurfelFrameController::predict(const SurfelWork& work) const {
  if (other_w_ <= 0) return 0;
  return other_ / other_w_ + mesh_.predict(static_cast<double>(work.triangles)) +
         surfels_.predict(static_cast<double>(work.surfels));
}

double SurfelFrameController::plan(const std::function<SurfelWork(double)>& work) {
  const SurfelControllerOptions& o = options_;
  if (other_w_ <= 0) return size_;  // no frame measured yet
  const double target = o.target_ms;
  const auto at = [&](double s) { return predict(work(s)); };
  predicted_ = at(size_);
  if (std::abs(predicted_ - target) <= o.deadband * target) return size_;
  // The size whose predicted time meets the target; the prediction does not grow with the size.
  double lo = std::log(o.min_point_size), hi = std::log(o.max_point_size);
  if (at(o.min_point_size) <= target) {
    size_ = o.min_point_size;
  } else if (at(o.max_point_size) >= target) {
    size_ = o.max_point_size;  // unreachable: as cheap as the controller can make it
  } else {
    // Invariant: at(e^lo) > target >= at(e^hi).
    for (int i = 0; i < kBisections; ++i) {
      const double mid = 0.5 * (lo + hi);
      (at(std::exp(mid)) > target ? lo : hi) = mid;
    }
    size_ = std::clamp(std::exp(hi), o.min_point_size, o.max_point_size);
  }
  predicted_ = at(size_);
  return size_;
}

void SurfelFrameController::report(const SurfelWork& work, const SurfelFrameTimes& t) {
  const double m = options_.memory;
  if (work.triangles > 0) mesh_.add(static_cast<double>(work.triangles), t.mesh_ms, m);
  if (work.surfels > 0) surfels_.add(static_cast<double>(work.surfels), t.surfels_ms, m);
  other_w_ = m * other_w_ + 1;
  other_ = m * other_ + std::max(0.0, t.frame_ms - t.mesh_ms - t.surfels_ms);
}

}  // namespace calf::player
