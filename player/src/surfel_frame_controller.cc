// The surfel frame-time controller; the model and its rules are in the public header.
#include "calf/player/surfel_frame_controller.h"

#include <algorithm>
#include <cmath>

namespace calf::player {
namespace {

// Bisection steps on log s: 2^-40 of the range, far below a prefix's rounding.
constexpr int kBisections = 40;
// The proportional shares of the passes' models (why these, and why fixed: the header).
constexpr double kSurfelShare = 1.0;
constexpr double kMeshShare = 0.75;

}  // namespace

void SurfelFrameController::Fit::add(double work, double ms, double memory) {
  w = memory * w + 1;
  x = memory * x + work;
  y = memory * y + ms;
}

double SurfelFrameController::Fit::predict(double work) const {
  if (work <= 0 || w <= 0) return 0;  // the pass is skipped, or never measured
  const double mx = x / w, my = y / w;
  // The line through the recent mean whose proportional part is `share` of it.
  return my * (1 - share) + share * my * work / mx;
}

SurfelFrameController::SurfelFrameController(const SurfelControllerOptions& options,
                                             double point_size)
    : options_(options), size_(point_size) {
  mesh_.share = kMeshShare;
  surfels_.share = kSurfelShare;
}

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
