// The frame-time controller; the model and its rules are in the public header.
#include "calf/player/frame_controller.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace calf::player {
namespace {

// Bisection steps on log k for a continuous knob: 2^-40 of the range, far below any rounding of
// the work.
constexpr int kBisections = 40;

}  // namespace

void FrameController::Fit::add(double work, double ms, double memory) {
  w = memory * w + 1;
  x = memory * x + work;
  y = memory * y + ms;
}

double FrameController::Fit::predict(double work, double share) const {
  if (work <= 0 || w <= 0 || x <= 0) return 0;  // the pass is skipped, or never measured
  const double mx = x / w, my = y / w;
  // The line through the recent mean whose proportional part is `share` of it.
  return my * (1 - share) + share * my * work / mx;
}

FrameController::FrameController(const FrameControllerOptions& options, double knob)
    : options_(options) {
  reset(knob);
}

void FrameController::set_options(const FrameControllerOptions& options) {
  options_ = options;
  knob_ = std::clamp(knob_, options_.min, options_.max);
}

void FrameController::reset(double knob) {
  knob_ = std::clamp(knob, options_.min, options_.max);
  predicted_ = 0;
  passes_ = {};
  other_w_ = other_ = 0;
  grow_frames_ = 0;
  frames_since_growth_ = 0;
  growth_on_probation_ = false;
  growth_backoff_ = 1;
  last_work_ = {};
  last_over_ = false;
}

double FrameController::predict(const FrameWork& work) const {
  if (other_w_ <= 0) return 0;
  double ms = other_ / other_w_;
  for (size_t i = 0; i < kMaxFramePasses; ++i) {
    ms += passes_[i].predict(work.pass[i], options_.pass_share[i]);
  }
  return ms;
}

double FrameController::per_unit_ms(size_t i) const {
  const Fit& f = passes_[i];
  return f.x > 0 ? f.y / f.x : 0;
}

double FrameController::most_work_within(const std::function<FrameWork(double)>& work,
                                         double limit_ms) const {
  const FrameControllerOptions& o = options_;
  const auto fits = [&](double k) { return predict(work(k)) <= limit_ms; };
  const double rich = o.work_grows ? o.max : o.min;
  const double cheap = o.work_grows ? o.min : o.max;
  if (fits(rich)) return rich;
  if (!fits(cheap)) return cheap;  // unreachable: as cheap as the controller can make it
  if (o.integer) {
    // Invariant: fits(c), !fits(r); the two meet at the boundary.
    int64_t c = static_cast<int64_t>(cheap), r = static_cast<int64_t>(rich);
    while (c - r > 1 || r - c > 1) {
      const int64_t mid = c + (r - c) / 2;
      (fits(static_cast<double>(mid)) ? c : r) = mid;
    }
    return static_cast<double>(c);
  }
  // Invariant: !fits(e^lo), fits(e^hi).
  double lo = std::log(rich), hi = std::log(cheap);
  for (int i = 0; i < kBisections; ++i) {
    const double mid = 0.5 * (lo + hi);
    (fits(std::exp(mid)) ? hi : lo) = mid;
  }
  return std::clamp(std::exp(hi), o.min, o.max);
}

double FrameController::plan(const std::function<FrameWork(double)>& work) {
  const FrameControllerOptions& o = options_;
  if (!on() || other_w_ <= 0) return knob_;  // off, or no frame measured yet
  const double target = o.target_ms;
  const auto at = [&](double k) { return predict(work(k)); };
  predicted_ = at(knob_);
  if (predicted_ > target * (1 + o.shrink_above) || last_over_) {
    grow_frames_ = 0;
    knob_ = most_work_within(work, target);
    // A frame measured over the target had too much work, whatever the model (which may lag a
    // sudden jump in cost) says: the next has less.
    const double last_ms = predict(last_work_);
    if (last_over_ && at(knob_) >= last_ms) {
      knob_ = most_work_within(work, std::nextafter(last_ms, 0.0));
    }
    last_over_ = false;
  } else if (predicted_ < target * (1 - o.grow_below)) {
    double candidate = most_work_within(work, target * (1 - o.grow_margin));
    if (at(candidate) > predicted_) {
      ++grow_frames_;
      if (grow_frames_ >= static_cast<uint64_t>(o.grow_after_frames) * growth_backoff_) {
        if (o.grow_step > 0) {
          candidate = o.work_grows ? std::min(candidate, knob_ + o.grow_step)
                                   : std::max(candidate, knob_ - o.grow_step);
        }
        knob_ = candidate;
        grow_frames_ = 0;
        frames_since_growth_ = 0;
        growth_on_probation_ = true;
      }
    } else {
      grow_frames_ = 0;  // nothing more to draw, or the model leaves no room for it
    }
  } else {
    grow_frames_ = 0;  // inside the deadband: keep
  }
  predicted_ = at(knob_);
  return knob_;
}

void FrameController::report(const FrameWork& work, const FrameTimes& t) {
  const FrameControllerOptions& o = options_;
  if (!on()) return;
  double passes_ms = 0;
  for (size_t i = 0; i < kMaxFramePasses; ++i) {
    if (work.pass[i] > 0) passes_[i].add(work.pass[i], t.pass_ms[i], o.memory);
    passes_ms += t.pass_ms[i];
  }
  other_w_ = o.memory * other_w_ + 1;
  other_ = o.memory * other_ + std::max(0.0, t.frame_ms - passes_ms);
  last_work_ = work;
  last_over_ = t.frame_ms > o.target_ms * (1 + o.shrink_above);
  if (frames_since_growth_ < UINT32_MAX) ++frames_since_growth_;
  if (growth_on_probation_ && frames_since_growth_ > o.grow_after_frames) {
    growth_on_probation_ = false;  // the growth held: trust the model again
    growth_backoff_ = 1;
  }
  if (growth_on_probation_ && last_over_) {
    // The latest growth broke the target: wait longer before the next one.
    growth_backoff_ = std::min(growth_backoff_ * 2, std::max<uint32_t>(o.max_growth_backoff, 1));
    growth_on_probation_ = false;
  }
}

}  // namespace calf::player
