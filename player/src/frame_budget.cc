// The frame budget's controller; the model and its rules are in the public header.
#include "calf/player/frame_budget.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

namespace calf::player {
namespace {

constexpr uint32_t kMaxGrowthBackoff = 32;
// The largest count the model's fit is allowed to propose (the selector's viewpoint limit).
constexpr double kMaxFit = 65536;

std::string out_of_range(const char* field, double value, const char* range) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.9g", value);
  return std::string(field) + " = " + buf + " is outside " + range;
}

}  // namespace

std::string frame_budget_problem(const FrameBudgetOptions& o) {
  // `!(x >= lo && x <= hi)` so that NaN fails every range check.
  if (!(o.target_frame_ms >= 0 && std::isfinite(o.target_frame_ms))) {
    return out_of_range("target_frame_ms", o.target_frame_ms, "[0, inf)");
  }
  if (!(o.fixed_cost_ms >= 0 && std::isfinite(o.fixed_cost_ms))) {
    return out_of_range("fixed_cost_ms", o.fixed_cost_ms, "[0, inf)");
  }
  if (!(o.over_budget_tolerance >= 0 && o.over_budget_tolerance <= 1)) {
    return out_of_range("over_budget_tolerance", o.over_budget_tolerance, "[0, 1]");
  }
  if (!(o.grow_headroom >= 0 && o.grow_headroom < 1)) {
    return out_of_range("grow_headroom", o.grow_headroom, "[0, 1)");
  }
  if (o.grow_after_frames < 1) return out_of_range("grow_after_frames", 0, "[1, 2^32)");
  if (!(o.cost_smoothing > 0 && o.cost_smoothing <= 1)) {
    return out_of_range("cost_smoothing", o.cost_smoothing, "(0, 1]");
  }
  return "";
}

FrameBudget::FrameBudget(const FrameBudgetOptions& options) : options_(options) {
  reset();
}

void FrameBudget::reset() {
  units_ = 0;
  limit_ = options_.max_units;
  per_unit_ms_ = 0;
  under_budget_frames_ = 0;
  frames_since_growth_ = 0;
  growth_on_probation_ = false;
  growth_backoff_ = 1;
}

void FrameBudget::set_options(const FrameBudgetOptions& options) {
  options_ = options;
  limit_ = on() ? std::clamp(limit_, options_.min_units, options_.max_units) : options_.max_units;
}

uint32_t FrameBudget::allowed() const {
  return on() ? std::min(limit_, options_.max_units) : options_.max_units;
}

Status FrameBudget::report_frame_time(double frame_ms) {
  if (!(frame_ms >= 0) || !std::isfinite(frame_ms)) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.9g", frame_ms);
    return Status(ErrorId::kViewSelectFrameTime, std::string("reported frame time ") + buf +
                                                     " ms is not a finite non-negative number");
  }
  const FrameBudgetOptions& o = options_;
  if (!on() || units_ == 0) return Status::Ok();
  const uint32_t n = units_;

  // Per-unit cost: the frame's variable part shared out over the units that caused it.
  const double sample = std::max(0.0, frame_ms - o.fixed_cost_ms) / n;
  per_unit_ms_ =
      per_unit_ms_ > 0 ? per_unit_ms_ + o.cost_smoothing * (sample - per_unit_ms_) : sample;
  if (frames_since_growth_ < UINT32_MAX) ++frames_since_growth_;
  if (growth_on_probation_ && frames_since_growth_ > o.grow_after_frames) {
    growth_on_probation_ = false;  // the growth held: trust the model again
    growth_backoff_ = 1;
  }

  if (frame_ms > o.target_frame_ms * (1 + o.over_budget_tolerance)) {
    under_budget_frames_ = 0;
    // The count the model says fits the target; never more than n - 1, since n is too many
    // (the running estimate may lag behind a sudden jump in cost).
    uint32_t fit = o.min_units;
    if (per_unit_ms_ > 0 && o.target_frame_ms > o.fixed_cost_ms) {
      const double f = std::floor((o.target_frame_ms - o.fixed_cost_ms) / per_unit_ms_);
      fit = static_cast<uint32_t>(std::min<double>(f, kMaxFit));
    }
    const uint32_t fewer = n > o.min_units ? n - 1 : o.min_units;
    limit_ = std::clamp(std::min(fit, fewer), o.min_units, o.max_units);
    if (growth_on_probation_) {
      // The latest growth broke the budget: wait longer before the next one.
      growth_backoff_ = std::min(growth_backoff_ * 2, kMaxGrowthBackoff);
      growth_on_probation_ = false;
    }
    return Status::Ok();
  }
  if (frame_ms >= o.target_frame_ms || limit_ > n || limit_ >= o.max_units) {
    // Inside the tolerance band, or the limit is not what bounds the count (culling left fewer
    // units), or nothing to grow to: hold.
    under_budget_frames_ = 0;
    return Status::Ok();
  }
  // A frame counts towards growth only if the model says one more unit would still fit with
  // headroom: frames just under the target must not pile up credit for a later jump.
  const double predicted = o.fixed_cost_ms + (n + 1) * per_unit_ms_;
  if (predicted > o.target_frame_ms * (1 - o.grow_headroom)) {
    under_budget_frames_ = 0;
    return Status::Ok();
  }
  ++under_budget_frames_;
  if (under_budget_frames_ >= static_cast<uint64_t>(o.grow_after_frames) * growth_backoff_) {
    limit_ = n + 1;
    under_budget_frames_ = 0;
    frames_since_growth_ = 0;
    growth_on_probation_ = true;
  }
  return Status::Ok();
}

}  // namespace calf::player
