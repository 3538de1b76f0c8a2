// The frame budget: how many units of work (active views of a light field today; surfel prefixes
// or tiles later) a frame can afford to meet a frame-time target, learnt from the frame times the
// caller reports. Paper 002 Sec. 7.2's performance culling, taken out of view selection so that
// every representation that scales its work with a count can share one controller.
//
// Model: frame_ms = fixed_cost_ms + n * per_unit_ms, n the units the reported frame used
// (record_units); per_unit_ms is a running estimate from the reports (weight cost_smoothing for
// the newest sample). When a frame exceeds the target by more than over_budget_tolerance, the
// limit drops at once to the count the model says fits the target (at least one fewer than now).
// When the limit is what bounds the count and frames have stayed under the target for
// grow_after_frames reports, it grows by one unit, but only if the model predicts the larger count
// still leaves grow_headroom below the target. A growth followed by an over-budget frame within
// grow_after_frames doubles the wait before the next growth (up to 32 times), so a wrong model
// cannot make the count oscillate; a growth that holds resets the wait. With fixed_cost_ms left at
// 0 the per-unit estimate includes the fixed part and is too high: shrinking may take a few frames
// more, growing is cautious — never too eager. docs/RENDERING.md ("Performance culling") has the
// reasoning and the defaults' origin.
//
// Deterministic: the same reports give the same limits.
#pragma once

#include <cstdint>
#include <string>

#include "calf/format/status.h"

namespace calf::player {

// The controller's knobs. The owner validates them with frame_budget_problem (ViewSelector::make /
// set_options do, CALF-E450); FrameBudget assumes valid options.
struct FrameBudgetOptions {
  // Frame-time target in ms (>= 0, finite); 0 turns the controller off (the limit is max_units).
  // Default: 90 Hz, the rate of head-mounted displays paper 002 aims at (Sec. 7.2).
  double target_frame_ms = 1000.0 / 90.0;
  // The part of a frame's time that does not depend on the unit count, in ms (>= 0, finite).
  double fixed_cost_ms = 0.0;
  // Shrink only when a frame takes more than target * (1 + tolerance), [0, 1].
  double over_budget_tolerance = 0.05;
  // Grow only when the predicted time with one more unit is at most target * (1 - headroom),
  // [0, 1).
  double grow_headroom = 0.10;
  // Consecutive under-target frames before the limit grows by one, >= 1. Default: a third of a
  // second at 90 Hz.
  uint32_t grow_after_frames = 30;
  // Weight of the newest sample in the running per-unit cost estimate, (0, 1].
  double cost_smoothing = 0.25;
  // The limit stays in [min_units, max_units], 1 <= min_units <= max_units.
  uint32_t min_units = 1;
  uint32_t max_units = 1;
};

// Why the knobs other than min_units / max_units are out of the ranges above, naming the first
// ("target_frame_ms = -1 is outside [0, inf)"; NaN fails every range), or "" when all are in range.
// The owner checks its own bounds on the units and wraps the text in its error.
std::string frame_budget_problem(const FrameBudgetOptions& options);

class FrameBudget {
 public:
  explicit FrameBudget(const FrameBudgetOptions& options = {});

  // Replaces the options, keeping the estimate; the limit is clamped to the new
  // [min_units, max_units] (max_units when the controller is off).
  void set_options(const FrameBudgetOptions& options);
  // Forgets the estimate and the growth history; the limit goes back to max_units.
  void reset();

  bool on() const { return options_.target_frame_ms > 0; }
  // The controller's current limit on the unit count.
  uint32_t limit() const { return limit_; }
  // What the next frame may use: min(limit, max_units) with the controller on, else max_units.
  uint32_t allowed() const;
  // The running per-unit cost estimate in ms; 0 before any frame time was reported.
  double per_unit_cost_ms() const { return per_unit_ms_; }
  const FrameBudgetOptions& options() const { return options_; }

  // The units the frame about to be rendered uses (0: none, and reports are then ignored).
  void record_units(uint32_t units) { units_ = units; }
  // The time the frame rendered with the latest recorded units took, in ms (finite, >= 0).
  // Ignored while the controller is off or before any units were recorded.
  // Errors: CALF-E453 for a negative or non-finite time; nothing changes.
  Status report_frame_time(double frame_ms);

 private:
  FrameBudgetOptions options_;
  uint32_t units_ = 0;  // n of the latest frame, 0 before the first
  uint32_t limit_ = 1;
  double per_unit_ms_ = 0;
  uint32_t under_budget_frames_ = 0;
  uint32_t frames_since_growth_ = 0;
  bool growth_on_probation_ = false;  // the latest growth has not yet held grow_after_frames
  uint32_t growth_backoff_ = 1;       // multiplies grow_after_frames
};

}  // namespace calf::player
