// The frame-time controller every representation shares: it sets one knob, a value in
// [min, max] on which a frame's work depends monotonically, so that frames meet a time target.
// The light field's knob is its active-view count (an integer, work grows with it); the surfel
// mode's is the point size (continuous, work shrinks as it grows; paper 001 Sec. 4.3). Paper 002
// Sec. 7.2's performance culling and paper 001's size control are the two uses of one law:
//
//   model:   frame_ms = other + sum over passes of pass_i(work_i). A frame reports the time of
//            each pass and of the whole frame; `other` is the weighted mean of the time outside
//            the passes, and each pass scales from the weighted mean of its recent measurements:
//            pass(w) = mean_ms * ((1 - share) + share * w / mean_w). A frame weighs
//            memory^age. The light field reports one pass (its views, the frame less
//            fixed_cost_ms); the surfel mode reports the mesh pass (share 3/4: the near meshes
//            cost per triangle and per covered pixel) and the surfel pass (share 1). The shares
//            are fixed, not fitted: a slope fitted from the controller's own frames confounds
//            the load's swings with the work's, and a share at or above the true one can only
//            make steps too short, never overshoot. A skipped pass (no work) costs 0.
//   plan:    before a frame the caller gives the work its view needs at any knob value (exact:
//            what the representation would draw), so the prediction at the current knob p(k)
//            answers a change of view in the frame that brings it (feed-forward). Then
//              - p(k) > target * (1 + shrink_above), or the latest frame took that long: the
//                knob moves at once to the value with the most work whose prediction meets the
//                target (the cheapest end when none does), and after a frame measured over, to
//                one with less work than that frame had (the model may lag a jump in cost);
//              - p(k) < target * (1 - grow_below): the value with the most work predicted at or
//                under target * (1 - grow_margin) is a candidate, if it has more work than k.
//                The knob moves to it, but at most grow_step (in knob units) towards more work,
//                and only after grow_after_frames consecutive frames had a candidate. A growth
//                followed within grow_after_frames by a frame over target * (1 + shrink_above)
//                doubles that wait (up to max_growth_backoff times), so a wrong model cannot make
//                the knob oscillate; a growth that holds resets it;
//              - otherwise the knob is kept (the deadband: no flicker).
//            The search is a bisection (on log k for a continuous knob, on integers for an
//            integer one); the prediction is monotone in the knob.
//   report:  after the frame, the times of its passes and of the whole frame refit the model.
//
// Before the first report, and while the target is 0, the knob is kept. Deterministic: the same
// reports and work give the same knob. Pure logic with no clock: tests drive it with simulated
// costs (tests/player/frame_controller_test.cc).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>

namespace calf::player {

// Passes a frame may report apart.
inline constexpr size_t kMaxFramePasses = 2;

// The work of one frame, per pass (views, triangles, surfels: any unit the pass's time is
// proportional to); 0 for a pass the frame skips.
struct FrameWork {
  std::array<double, kMaxFramePasses> pass{};
};

// Measured times of one frame, ms (finite, >= 0). frame_ms >= the sum of the passes is
// expected; less counts as no time outside the passes.
struct FrameTimes {
  std::array<double, kMaxFramePasses> pass_ms{};
  double frame_ms = 0;
};

struct FrameControllerOptions {
  double target_ms = 0;     // >= 0, finite; 0 turns the controller off (the knob is kept)
  double min = 1, max = 1;  // the knob's range, 0 < min <= max
  bool integer = false;     // the knob takes integer values
  bool work_grows = false;  // work increases with the knob (a count), else decreases (a size)
  // Each pass's proportional share of its time, (0, 1].
  std::array<double, kMaxFramePasses> pass_share{1, 1};
  double memory = 0.7;              // weight of a frame one report older, [0, 1)
  double shrink_above = 0.05;       // [0, 1]
  double grow_below = 0.05;         // [0, 1)
  double grow_margin = 0;           // [0, 1)
  double grow_step = 0;             // > 0, or 0: unlimited
  uint32_t grow_after_frames = 1;   // >= 1
  uint32_t max_growth_backoff = 1;  // >= 1
};

class FrameController {
 public:
  // `knob` is the start value, clamped to [min, max] (the caller validated the options).
  FrameController(const FrameControllerOptions& options, double knob);

  // Replaces the options, keeping the model; the knob is clamped to the new range.
  void set_options(const FrameControllerOptions& options);
  // Forgets the model and the growth history; the knob becomes `knob` (clamped).
  void reset(double knob);

  bool on() const { return options_.target_ms > 0; }
  // The knob of the coming frame, given the work its view needs at any knob value (monotone as
  // options.work_grows says). Keeps the knob while off or before the first report.
  double plan(const std::function<FrameWork(double knob)>& work);
  // The frame drawn with `work` (at the knob plan returned) took `times`. Ignored while off.
  void report(const FrameWork& work, const FrameTimes& times);

  double knob() const { return knob_; }
  // The prediction for the knob plan returned (0 before any report).
  double predicted_ms() const { return predicted_; }
  // The model's prediction of a frame with `work` (0 before any report).
  double predict(const FrameWork& work) const;
  // The mean time per unit of work of pass `i` in ms (0 before it was measured).
  double per_unit_ms(size_t i) const;
  const FrameControllerOptions& options() const { return options_; }

 private:
  // The knob value with the most work whose prediction is at most `limit_ms` (the cheapest end
  // when none is).
  double most_work_within(const std::function<FrameWork(double)>& work, double limit_ms) const;
  // One pass's model: decayed sums of its work and times.
  struct Fit {
    double w = 0, x = 0, y = 0;
    void add(double work, double ms, double memory);
    double predict(double work, double share) const;
  };
  FrameControllerOptions options_;
  double knob_ = 1;
  double predicted_ = 0;
  std::array<Fit, kMaxFramePasses> passes_{};
  double other_w_ = 0, other_ = 0;  // decayed weight and sum of the time outside the passes
  uint32_t grow_frames_ = 0;        // consecutive frames with a growth candidate
  uint32_t frames_since_growth_ = 0;
  bool growth_on_probation_ = false;  // the latest growth has not yet held grow_after_frames
  uint32_t growth_backoff_ = 1;       // multiplies grow_after_frames
  FrameWork last_work_;               // the latest reported frame's
  bool last_over_ = false;            // it took more than target * (1 + shrink_above)
};

}  // namespace calf::player
