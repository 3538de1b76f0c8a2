// View selection (paper 002 Sec. 6.3). The what and why are in the public header and in
// docs/RENDERING.md ("View selection"); comments here explain the choices inside.
#include "calf/player/view_selection.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <string>

#include "sampling.h"

namespace calf::player {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kInf = std::numeric_limits<double>::infinity();
// Performance culling's back-off: a growth that breaks the budget doubles the wait before the
// next, up to this many times grow_after_frames.
constexpr uint32_t kMaxGrowthBackoff = 32;

std::string out_of_range(const char* field, double value, const char* range) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.9g", value);
  return std::string(field) + " = " + buf + " is outside " + range;
}

// Shortest faithful text of a number ("0.5", "nan", "1e+300"), for messages.
std::string num(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.9g", x);
  return buf;
}

std::string vec_string(const Vec3& v) {
  char buf[104];
  std::snprintf(buf, sizeof buf, "(%.9g, %.9g, %.9g)", v.x, v.y, v.z);
  return buf;
}

Status option_error(const char* field, double value, const char* range) {
  return Status(ErrorId::kViewSelectOptions, std::string("view selection option ") + field + " = " +
                                                 num(value) + " is outside " + range);
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

namespace {

Status check_options(const ViewSelectionOptions& o) {
  if (o.priority != ViewPriority::kDistance && o.priority != ViewPriority::kAngle) {
    return option_error("priority", static_cast<double>(o.priority), "{distance, angle}");
  }
  if (!is_finite(o.reference_point)) {
    return Status(ErrorId::kViewSelectOptions,
                  "view selection option reference_point = " + vec_string(o.reference_point) +
                      " is not finite");
  }
  // `!(x >= lo && x <= hi)` so that NaN fails every range check.
  if (!(o.redundancy_angle_deg >= 0 && o.redundancy_angle_deg <= 180)) {
    return option_error("redundancy_angle_deg", o.redundancy_angle_deg, "[0, 180]");
  }
  if (!(o.view_cone_deg > 0 && o.view_cone_deg <= 180)) {
    return option_error("view_cone_deg", o.view_cone_deg, "(0, 180]");
  }
  if (o.max_active < 1 || o.max_active > kMaxViewpoints) {
    return option_error("max_active", o.max_active, "[1, 65536]");
  }
  if (o.min_active < 1 || o.min_active > o.max_active) {
    return option_error("min_active", o.min_active, "[1, max_active]");
  }
  if (!(o.incumbent_margin >= 0 && o.incumbent_margin < 1)) {
    return option_error("incumbent_margin", o.incumbent_margin, "[0, 1)");
  }
  const std::string budget = frame_budget_problem(o.budget);
  if (!budget.empty()) {
    return Status(ErrorId::kViewSelectOptions, "view selection option budget." + budget);
  }
  return Status::Ok();
}

// The controller's options: the active count, bounded by [min_active, max_active].
FrameControllerOptions controller_options(const ViewSelectionOptions& o) {
  const FrameBudgetOptions& b = o.budget;
  FrameControllerOptions c;
  c.target_ms = b.target_frame_ms;
  c.min = o.min_active;
  c.max = o.max_active;
  c.integer = true;
  c.work_grows = true;
  c.memory = 1 - b.cost_smoothing;
  c.shrink_above = b.over_budget_tolerance;
  c.grow_below = b.grow_headroom;
  c.grow_margin = b.grow_headroom;
  c.grow_step = 1;
  c.grow_after_frames = b.grow_after_frames;
  c.max_growth_backoff = kMaxGrowthBackoff;
  return c;
}

struct Ranked {
  uint32_t view;
  double key;       // priority key after the incumbent discount; smaller ranks first
  double distance;  // |P - eye|, the first tie-break
};

}  // namespace

Expected<ViewSelector> ViewSelector::make(std::vector<Vec3> viewpoints,
                                          const ViewSelectionOptions& options) {
  CALF_RETURN_IF_ERROR(check_options(options));
  if (viewpoints.size() > kMaxViewpoints) {
    return Status(ErrorId::kViewSelectLimit, std::to_string(viewpoints.size()) +
                                                 " viewpoints exceed the selector's limit of " +
                                                 std::to_string(kMaxViewpoints));
  }
  for (size_t i = 0; i < viewpoints.size(); ++i) {
    if (!is_finite(viewpoints[i])) {
      return Status(ErrorId::kViewSelectViewpoint, "viewpoint " + std::to_string(i) + " position " +
                                                       vec_string(viewpoints[i]) +
                                                       " is not finite");
    }
  }
  ViewSelector s;
  s.viewpoints_ = std::move(viewpoints);
  s.options_ = options;
  s.was_active_.assign(s.viewpoints_.size(), 0);
  s.excluded_.assign(s.viewpoints_.size(), 0);
  s.reset();
  return s;
}

void ViewSelector::reset() {
  slots_.clear();
  std::fill(was_active_.begin(), was_active_.end(), 0);
  controller_.set_options(controller_options(options_));
  controller_.reset(options_.max_active);
  units_ = available_ = 0;
}

Status ViewSelector::exclude(uint32_t view) {
  if (view >= viewpoints_.size()) {
    return Status(ErrorId::kViewSelectOptions, "excluded view " + std::to_string(view) +
                                                   " is not one of the " +
                                                   std::to_string(viewpoints_.size()) + " views");
  }
  excluded_[view] = 1;
  return Status::Ok();
}

Status ViewSelector::set_options(const ViewSelectionOptions& options) {
  CALF_RETURN_IF_ERROR(check_options(options));
  options_ = options;
  controller_.set_options(controller_options(options_));
  return Status::Ok();
}

Expected<ViewSelection> ViewSelector::select(const Vec3& position, const Vec3& forward) {
  const ViewSelectionOptions& o = options_;
  const bool cone_on = o.view_cone_deg < 180;
  if (!is_finite(position) || !is_finite(forward)) {
    return Status(ErrorId::kViewSelectEye, "eye position " + vec_string(position) + " or forward " +
                                               vec_string(forward) + " is not finite");
  }
  if (cone_on && length(forward) == 0) {
    return Status(ErrorId::kViewSelectEye,
                  "eye forward is (0, 0, 0) but cone culling (view_cone_deg " +
                      num(o.view_cone_deg) + ") needs a direction");
  }

  // 1. Rank.
  const size_t n = viewpoints_.size();
  const Vec3 eye_from_ref = position - o.reference_point;
  const bool eye_at_ref = length(eye_from_ref) == 0;
  std::vector<Ranked> ranked;
  ranked.reserve(n);
  for (uint32_t i = 0; i < n; ++i) {
    if (excluded_[i]) continue;
    const double distance = length(viewpoints_[i] - position);
    double key = distance;
    if (o.priority == ViewPriority::kAngle) {
      const Vec3 view_from_ref = viewpoints_[i] - o.reference_point;
      // Undefined angles (eye or view at the reference point) count as 0: the distance
      // tie-break then decides, which is the only meaningful order left.
      key = eye_at_ref || length(view_from_ref) == 0 ? 0.0
                                                     : angle_between(eye_from_ref, view_from_ref);
    }
    if (was_active_[i]) key *= 1.0 - o.incumbent_margin;
    // Coordinates near the double range can overflow to inf - inf; a NaN key would break the
    // sort's ordering, so it ranks last (ties then break by index).
    ranked.push_back({i, std::isnan(key) ? kInf : key, std::isnan(distance) ? kInf : distance});
  }
  std::sort(ranked.begin(), ranked.end(), [](const Ranked& a, const Ranked& b) {
    if (a.key != b.key) return a.key < b.key;
    if (a.distance != b.distance) return a.distance < b.distance;
    return a.view < b.view;
  });

  ViewSelection sel;
  const double cone_rad = o.view_cone_deg * kPi / 180.0;
  const double redundancy_rad = o.redundancy_angle_deg * kPi / 180.0;

  // 2.-4. Cull, walking the ranking. Angle culling compares against views kept so far (not
  // against views it dropped: a view close only to a dropped view is not redundant with anything
  // the renderer will use). The walk stops at max_active kept views, so a frame costs
  // O(n log n + n * max_active) whatever the number of viewpoints.
  std::vector<uint32_t> kept;
  kept.reserve(std::min<size_t>(n, o.max_active));
  for (size_t r = 0; r < ranked.size(); ++r) {
    const uint32_t v = ranked[r].view;
    const Vec3 dir = viewpoints_[v] - position;
    const bool at_eye = ranked[r].distance == 0;
    if (cone_on && !at_eye && angle_between(forward, dir) > cone_rad) {
      ++sel.culled_by_cone;
      continue;
    }
    if (kept.size() == o.max_active) {
      ++sel.culled_by_max_active;
      continue;
    }
    bool redundant = false;
    if (redundancy_rad > 0 && !at_eye) {
      for (uint32_t k : kept) {
        const Vec3 kdir = viewpoints_[k] - position;
        if (length(kdir) > 0 && angle_between(dir, kdir) < redundancy_rad) {
          redundant = true;
          break;
        }
      }
    }
    if (redundant) {
      ++sel.culled_by_angle;
      continue;
    }
    kept.push_back(v);
  }
  // 4. The controller's limit (planned at the latest report).
  available_ = static_cast<uint32_t>(kept.size());
  sel.performance_limit = performance_limit();
  const uint32_t cap = sel.performance_limit;
  if (kept.size() > cap) {
    sel.culled_by_performance = static_cast<uint32_t>(kept.size() - cap);
    kept.resize(cap);
  }
  // 5. Never an empty frame when there is something to show: only the cone can empty the set
  // (angle culling always keeps the first view it sees), and then the nearest view stays.
  if (kept.empty() && n > 0) {
    const auto nearest = std::min_element(ranked.begin(), ranked.end(), [](auto& a, auto& b) {
      return a.distance != b.distance ? a.distance < b.distance : a.view < b.view;
    });
    kept.push_back(nearest->view);
    --sel.culled_by_cone;
  }
  sel.active = kept;

  // 6. Slots. Survivors stay where they are; entering views fill the lowest holes, then append.
  std::vector<uint8_t> now_active(n, 0);
  for (uint32_t v : kept) now_active[v] = 1;
  std::vector<uint32_t> slots = slots_;
  for (uint32_t& s : slots) {
    if (s != kNoView && !now_active[s]) {
      sel.left.push_back(s);
      s = kNoView;
    }
  }
  // A smaller max_active (set_options) leaves survivors beyond the slot capacity: move them down
  // into holes, as if they had entered (their layer changes, so they need an upload).
  std::vector<uint32_t> to_place;
  for (size_t s = o.max_active; s < slots.size(); ++s) {
    if (slots[s] != kNoView) to_place.push_back(slots[s]);
    slots[s] = kNoView;
  }
  for (uint32_t v : kept) {
    if (!was_active_[v]) to_place.push_back(v);
  }
  size_t hole = 0;
  std::vector<uint32_t> entered_slots;
  for (uint32_t v : to_place) {
    while (hole < slots.size() && slots[hole] != kNoView) ++hole;
    if (hole == slots.size()) slots.push_back(kNoView);
    slots[hole] = v;
    entered_slots.push_back(static_cast<uint32_t>(hole));
  }
  while (!slots.empty() && slots.back() == kNoView) slots.pop_back();
  std::sort(entered_slots.begin(), entered_slots.end());
  for (uint32_t s : entered_slots) sel.entered.push_back(slots[s]);
  std::sort(sel.left.begin(), sel.left.end());
  sel.slots = slots;

  slots_ = std::move(slots);
  was_active_ = std::move(now_active);
  units_ = static_cast<uint32_t>(kept.size());
  return sel;
}

uint32_t ViewSelector::performance_limit() const {
  return controller_.on() ? static_cast<uint32_t>(controller_.knob()) : options_.max_active;
}

Status ViewSelector::report_frame_time(double frame_ms) {
  if (!(frame_ms >= 0) || !std::isfinite(frame_ms)) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.9g", frame_ms);
    return Status(ErrorId::kViewSelectFrameTime, std::string("reported frame time ") + buf +
                                                     " ms is not a finite non-negative number");
  }
  if (units_ == 0) return Status::Ok();
  FrameWork work;
  work.pass[0] = units_;
  FrameTimes times;
  times.pass_ms[0] = std::max(0.0, frame_ms - options_.budget.fixed_cost_ms);
  times.frame_ms = frame_ms;
  controller_.report(work, times);
  // The next frame's limit, planned for as many views as survived the other cullings this frame:
  // the work at a limit k is min(k, available) views.
  const double available = available_;
  controller_.plan([available](double k) {
    FrameWork w;
    w.pass[0] = std::min(k, available);
    return w;
  });
  return Status::Ok();
}

}  // namespace calf::player
