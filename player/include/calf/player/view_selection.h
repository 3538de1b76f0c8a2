// View selection (paper 002 Sec. 6.3, Sec. 7.2): which viewpoints the renderer uses this frame,
// and in which texture slot each one lives.
//
// Not every viewpoint helps every frame, and each active view costs texture updates (the
// bottleneck of playback, Sec. 7.2) and samples in every ray-march step. Each frame the selector
//   1. ranks all viewpoints by a priority (the paper's two):
//        distance: |P_j - eye|, nearest first;
//        angle:    the angle at a reference point (e.g. the centre of a captured object) between
//                  eye - ref and P_j - ref, smallest first;
//      a view active last frame ranks as if its key were (1 - incumbent_margin) times smaller, so
//      that two views of nearly equal priority do not trade places every frame as the eye
//      jitters; ties break by distance to the eye, then by index (deterministic);
//   2. optionally drops views outside a cone around the eye's forward direction (view_cone_deg;
//      off by default: a 360° viewpoint behind the eye still sees what is in front of it);
//   3. angle culling (paper): walking the ranking, drops a view whose direction seen from the eye
//      lies within redundancy_angle_deg of a view already kept — its data is nearly the same;
//   4. performance culling (paper): keeps at most min(max_active, performance limit) views; the
//      limit follows the frame times the caller reports (below);
//   5. if culling left nothing, keeps the nearest view, so a frame always has data;
//   6. places the kept views in slots: a view that stays selected keeps its slot; a view that
//      enters takes the lowest free slot. Slot s is the renderer's texture layer s, so a view
//      that stays never needs a full re-upload (Sec. 6.3: "the order of the active viewpoints is
//      maintained as much as possible with respect to the previous frame").
//
// Performance culling asks the frame controller (calf/player/frame_controller.h) how many views the
// frame may use: its knob is the active count, an integer in [min_active, max_active] whose work
// is the count itself (one pass: the views, the frame less fixed_cost_ms). The caller renders with
// the selection, then reports that frame's time (report_frame_time), which plans the next limit
// for as many views as survived the other cullings. Its knobs are
// ViewSelectionOptions::budget (PerformanceOptions below).
//
// Stereo: pass the midpoint of the two eyes and the mean forward direction.
// Everything is deterministic: same inputs, same calls, same results.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "calf/format/geometry.h"
#include "calf/format/status.h"
#include "calf/player/frame_controller.h"

namespace calf::player {

// How the selector ranks viewpoints (paper 002 Sec. 6.3).
enum class ViewPriority : uint8_t {
  kDistance,  // nearest to the eye first: an eye moving through a field of viewpoints
  kAngle,     // smallest angle at reference_point between eye and viewpoint first: viewpoints
              // surrounding an object (the paper's Spaceship)
};

// Performance culling's knobs, mapped onto the frame controller's (frame_controller.h has the law).
// Checked by ViewSelector::make / set_options (CALF-E450).
struct FrameBudgetOptions {
  // Frame-time target in ms (>= 0, finite); 0 turns the controller off (the limit is max_active).
  // Default: 90 Hz, the rate of head-mounted displays paper 002 aims at (Sec. 7.2).
  double target_frame_ms = 1000.0 / 90.0;
  // The part of a frame's time that does not depend on the view count, in ms (>= 0, finite).
  double fixed_cost_ms = 0.0;
  // Shrink when the predicted frame exceeds target * (1 + tolerance), [0, 1] (the controller's
  // shrink_above).
  double over_budget_tolerance = 0.05;
  // Grow only to a count predicted at most target * (1 - headroom), [0, 1) (the controller's
  // grow_below and grow_margin).
  double grow_headroom = 0.10;
  // Consecutive frames with room before the limit grows by one view, >= 1 (the controller's
  // grow_after_frames; grow_step is one view, the back-off up to 32 times). Default: a third of
  // a second at 90 Hz.
  uint32_t grow_after_frames = 30;
  // Weight of the newest frame in the model, (0, 1] (the controller's memory is 1 - this).
  double cost_smoothing = 0.25;
};

// Why a knob of `options` is out of the ranges above, naming the first ("target_frame_ms = -1 is
// outside [0, inf)"; NaN fails every range), or "" when all are in range.
std::string frame_budget_problem(const FrameBudgetOptions& options);

// Every knob of the selector, with its default. Checked by ViewSelector::make / set_options
// (CALF-E450 names the field and its range).
struct ViewSelectionOptions {
  ViewPriority priority = ViewPriority::kDistance;
  // Origin of the angle priority (finite); unused by distance priority.
  Vec3 reference_point{};
  // Angle culling, in degrees, [0, 180]: a view whose direction from the eye is less than this
  // from a view kept before it is dropped. 0 turns it off. Views at the eye have no direction
  // and are never dropped or dropped for.
  double redundancy_angle_deg = 5.0;
  // Forward-cone culling, in degrees, (0, 180]: views whose direction from the eye is more than
  // this from the eye's forward are dropped. 180 turns it off (the default).
  double view_cone_deg = 180.0;
  // At most this many active views, [1, kMaxViewpoints]. Default 9: the paper's setting for
  // Sponza and Robot (9 of 9 and 9 of 16 viewpoints).
  uint32_t max_active = 9;
  // Performance culling never goes below this many views, [1, max_active].
  uint32_t min_active = 1;
  // Ranking stickiness for views active last frame, [0, 1): their priority key counts
  // (1 - margin) times its value. 0 turns it off.
  double incumbent_margin = 0.05;
  // Performance culling's knobs (above); the count stays in [min_active, max_active].
  FrameBudgetOptions budget;
};

// Views a selector accepts; slot and view indices fit 32 bits with kNoView to spare.
inline constexpr uint32_t kMaxViewpoints = 65536;
// An empty slot.
inline constexpr uint32_t kNoView = 0xFFFFFFFFu;

// One frame's selection.
struct ViewSelection {
  // The active views, best priority first (pass to the renderer's render()).
  std::vector<uint32_t> active;
  // The slot table: slots[s] is the view in texture slot s, or kNoView for a hole left by a view
  // that went inactive. No trailing holes; size <= max_active. A view keeps its slot for as long
  // as it stays active.
  std::vector<uint32_t> slots;
  // Views that took a slot this frame (their textures need a full upload), in slot order, and
  // views that lost theirs (their slots may be reused), increasing.
  std::vector<uint32_t> entered;
  std::vector<uint32_t> left;
  // Why views are missing, for the HUD and benchmarks: outside the forward cone; dropped by angle
  // culling; kept by angle culling but beyond the performance limit; not taken because max_active
  // views were already kept (these were not examined by angle culling).
  uint32_t culled_by_cone = 0;
  uint32_t culled_by_angle = 0;
  uint32_t culled_by_performance = 0;
  uint32_t culled_by_max_active = 0;
  // The performance limit this frame was selected with (max_active when the controller is off).
  uint32_t performance_limit = 0;
};

class ViewSelector {
 public:
  // A selector over fixed viewpoint positions (the clip's). Zero viewpoints is valid (every
  // selection is empty). Errors: CALF-E450 for an option out of range, CALF-E451 for a
  // non-finite position, CALF-E454 for more than kMaxViewpoints viewpoints.
  static Expected<ViewSelector> make(std::vector<Vec3> viewpoints,
                                     const ViewSelectionOptions& options = {});

  // This frame's selection for an eye at `position` looking along `forward` (any length; only
  // read when cone culling is on, where it must not be zero). Updates the slot table.
  // Errors: CALF-E452 for a non-finite position or forward, or a zero forward with cone culling
  // on; nothing changes on error.
  Expected<ViewSelection> select(const Vec3& position, const Vec3& forward);

  // The time the frame rendered with the latest selection took, in ms (finite, >= 0). Feeds the
  // performance controller; ignored while it is off or before the first selection.
  // Errors: CALF-E453 for a negative or non-finite time.
  Status report_frame_time(double frame_ms);

  // Replaces the options (e.g. from the player's HUD), keeping slots and the controller's
  // estimate; the limit is clamped to the new [min_active, max_active]. Views in slots at or
  // beyond a smaller max_active move to free lower slots at the next selection.
  // Errors: CALF-E450; the old options stay.
  Status set_options(const ViewSelectionOptions& options);

  // Never selects `view` again (a view the decoder dropped: its position is unknown); a view in a
  // slot leaves it at the next selection. Errors: CALF-E450 for an index out of range.
  Status exclude(uint32_t view);
  // Forgets the slot table and the controller's state (e.g. after a seek or a teleport).
  void reset();

  const ViewSelectionOptions& options() const { return options_; }
  const std::vector<Vec3>& viewpoints() const { return viewpoints_; }
  // The controller's current limit on the active count.
  uint32_t performance_limit() const;
  // The model's mean cost per active view in ms; 0 before any frame time was reported.
  double per_view_cost_ms() const { return controller_.per_unit_ms(0); }
  // The controller performance culling asks (its knob is the active count).
  const FrameController& controller() const { return controller_; }

 private:
  ViewSelector() = default;

  std::vector<Vec3> viewpoints_;
  ViewSelectionOptions options_;
  std::vector<uint32_t> slots_;      // last frame's slot table
  std::vector<uint8_t> was_active_;  // per view: in slots_
  std::vector<uint8_t> excluded_;    // per view: never selected (exclude)
  bool selected_once_ = false;
  FrameController controller_{{}, 1};  // performance culling
  uint32_t units_ = 0;                 // views of the latest selection
  uint32_t available_ = 0;             // views of the latest selection before performance culling
};

}  // namespace calf::player
