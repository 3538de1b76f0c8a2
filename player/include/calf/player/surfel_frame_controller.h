// The surfel mode's frame-time controller (paper 001 Sec. 4.3, with the mesh pass modelled apart).
//
// The paper scales the surfel size by the last frame's time over the target. But a surfel frame
// has two passes and the point size s governs only one of them fully: the surfels drawn S(s) go
// as 1 / s², while the triangles T(s) of the objects near the eye (drawn from the mesh track)
// change only when an object crosses the surfel / mesh threshold, and mostly change with the
// view. A controller that sees only the sum lags every such change (on the factory's walk, 9-11
// of 19 poses within +-10 %, docs/SURFELS.md). This one models the passes apart and looks ahead:
//
//   model:   frame_ms = other + mesh(T) + surfels(S). Each term is the weighted mean of its
//            recent measurements (a frame weighs memory^age; memory 0.7: about the last 3
//            frames, the paper's window), and each pass scales from its mean work to the work
//            asked: surfels(S) = mean_ms * S / mean_S (proportional: the surfel pass's cost is
//            the surfels'), mesh(T) = mean_ms * (1/4 + 3/4 * T / mean_T) (the near meshes cost
//            per triangle and per covered pixel, which the triangles predict only in part);
//            a skipped pass (no work) costs 0. The shares are fixed, not fitted: a slope fitted
//            from the controller's own frames confounds the load's swings with the work's
//            (measured on the factory: fits went flat and sent the size to its maximum), and
//            a share at or above the true one can only make steps too short, never overshoot.
//   plan:    before a frame, the caller gives the work its view needs at any point size
//            (work(s), exact: the prefixes and mesh choices the representation would make). The
//            predicted time at the current size p(s) = model(work(s)) is the feed-forward term:
//            a view that brings more near meshes is answered in the frame that draws them. If
//            p(s) lies within +-deadband of the target, s is kept (no flicker, the paper's
//            threshold); otherwise s becomes the size whose prediction meets the target
//            (bisection on log s over [min, max]; the model is non-increasing in s), clamped to
//            [min, max] when the target cannot be met (unreachable: the largest size).
//   report:  after the frame, the times of its passes and the whole frame refit the model.
//
// Before the first report there is no model and the size is kept. Deterministic: the same
// reports and work give the same sizes. Pure logic with no clock: tests drive it with a
// simulated cost (tests/player/surfel_frame_controller_test.cc).
#pragma once

#include <cstdint>
#include <functional>

namespace calf::player {

// The work of one surfel frame.
struct SurfelWork {
  uint64_t triangles = 0;  // drawn by the mesh pass (near objects, the blend zone)
  uint64_t surfels = 0;    // drawn by the surfel pass
};

// Measured times of one frame, ms (finite, >= 0). frame_ms >= mesh_ms + surfels_ms is expected;
// less counts as no time outside the passes.
struct SurfelFrameTimes {
  double mesh_ms = 0;
  double surfels_ms = 0;
  double frame_ms = 0;
};

struct SurfelControllerOptions {
  double target_ms = 0;  // > 0
  double min_point_size = 1, max_point_size = 16;
  double deadband = 0.05;  // keep the size while the prediction is within +-deadband of target
  double memory = 0.7;     // weight of a frame one report older, (0, 1)
};

class SurfelFrameController {
 public:
  // `point_size` is the start size, within [min, max] (the caller validated the options).
  SurfelFrameController(const SurfelControllerOptions& options, double point_size);

  // The size of the coming frame, given the work its view needs at any size (non-increasing in
  // the size). Keeps the size before the first report.
  double plan(const std::function<SurfelWork(double point_size)>& work);
  // The frame drawn with `work` (at the size plan returned) took `times`.
  void report(const SurfelWork& work, const SurfelFrameTimes& times);

  double point_size() const { return size_; }
  // The prediction for the size plan returned (0 before any report).
  double predicted_ms() const { return predicted_; }
  // The model's prediction of a frame with `work` (0 before any report).
  double predict(const SurfelWork& work) const;

 private:
  // One pass's model: decayed sums of its work and times.
  struct Fit {
    double w = 0, x = 0, y = 0;
    double share = 1;  // the proportional share of the time
    void add(double work, double ms, double memory);
    double predict(double work) const;
  };
  SurfelControllerOptions options_;
  double size_;
  double predicted_ = 0;
  Fit mesh_, surfels_;
  double other_w_ = 0, other_ = 0;  // decayed weight and sum of the time outside the passes
};

}  // namespace calf::player
