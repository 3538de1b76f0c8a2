// FrameController against simulated frames, a surfel frame (two passes, the point size as knob)
// and a light-field frame (one pass, the active-view count as knob): no clock, every cost is
// computed from a cost model with deterministic noise, so the tests check the control law, not
// the machine.
#include "calf/player/frame_controller.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

namespace calf::player {
namespace {

// A view of the simulated scene: the surfels it needs at 1 px (S(s) = k / s², the prefix law)
// and the triangles of its near meshes, plus those of objects that become meshes when the point
// size drops below `switch_size` (the blend zone's threshold).
struct View {
  double k = 3e5;
  uint64_t near_triangles = 6000;
  uint64_t switch_triangles = 2000;
  double switch_size = 1.6;
};

constexpr size_t kMesh = 0, kSurfels = 1;  // the surfel frame's passes

FrameWork work_of(const View& v, double s) {
  FrameWork w;
  w.pass[kSurfels] = std::ceil(v.k / (s * s));
  w.pass[kMesh] =
      static_cast<double>(v.near_triangles + (s < v.switch_size ? v.switch_triangles : 0));
  return w;
}

// The machine: each pass a fixed part, a part per unit of work and, for the surfels, a fragment
// part that grows with the disc area (s² per surfel; constant coverage, as on llvmpipe); `load`
// scales everything; +-`noise` deterministic jitter per frame.
struct Machine {
  double load = 1;
  double noise = 0.03;
  uint64_t state = 0x9e3779b97f4a7c15ull;

  double jitter() {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    const double u = static_cast<double>(state >> 11) / 9007199254740992.0;  // [0, 1)
    return 1 + noise * (2 * u - 1);
  }
  FrameTimes run(const FrameWork& w, double s) {
    FrameTimes t;
    const double tris = w.pass[kMesh], surfels = w.pass[kSurfels];
    t.pass_ms[kMesh] = tris > 0 ? load * (25 + 0.004 * tris) * jitter() : 0;
    t.pass_ms[kSurfels] =
        surfels > 0 ? load * (15 + 0.002 * surfels + 5e-5 * surfels * s * s) * jitter() : 0;
    t.frame_ms = t.pass_ms[kMesh] + t.pass_ms[kSurfels] + load * 5 * jitter();
    return t;
  }
};

// The surfel mode's configuration (surfel_representation.cc): the point size in [1, 16],
// continuous, work falling as it grows; the mesh pass's share 3/4; a +-5 % deadband; growth
// unlimited.
FrameControllerOptions options(double target) {
  FrameControllerOptions o;
  o.target_ms = target;
  o.min = 1;
  o.max = 16;
  o.pass_share[kMesh] = 0.75;
  o.pass_share[kSurfels] = 1;
  o.shrink_above = o.grow_below = 0.05;
  return o;
}

struct Trace {
  std::vector<double> frame_ms, sizes;
};

// Plays `views` through the controller: plan, render on `machine`, report.
Trace play(FrameController* c, Machine* machine, const std::vector<View>& views) {
  Trace out;
  for (const View& v : views) {
    const double s = c->plan([&](double size) { return work_of(v, size); });
    EXPECT_GE(s, 1.0);
    EXPECT_LE(s, 16.0);
    const FrameWork w = work_of(v, s);
    const FrameTimes t = machine->run(w, s);
    c->report(w, t);
    out.frame_ms.push_back(t.frame_ms);
    out.sizes.push_back(s);
  }
  return out;
}

// Direction changes of the size between consecutive frames (a hunting controller reverses often).
int reversals(const std::vector<double>& sizes, size_t from) {
  int n = 0, last = 0;
  for (size_t i = from + 1; i < sizes.size(); ++i) {
    const double d = sizes[i] - sizes[i - 1];
    const int dir = d > 1e-9 ? 1 : d < -1e-9 ? -1 : 0;
    if (dir != 0 && last != 0 && dir != last) ++n;
    if (dir != 0) last = dir;
  }
  return n;
}

int within(const std::vector<double>& ms, size_t from, double target, double tol) {
  int n = 0;
  for (size_t i = from; i < ms.size(); ++i) n += std::abs(ms[i] / target - 1) <= tol;
  return n;
}

TEST(FrameControllerSurfels, KeepsTheSizeUntilAFrameIsMeasured) {
  FrameController c(options(300), 1.5);
  EXPECT_EQ(c.plan([](double s) { return work_of(View{}, s); }), 1.5);
  EXPECT_EQ(c.predicted_ms(), 0);
}

TEST(FrameControllerSurfels, ConvergesOnAStaticViewWithoutOscillating) {
  // Start far off on both sides: at 1 px the frame takes ~1000 ms, at 8 px ~90 ms.
  for (const double start : {1.0, 8.0}) {
    SCOPED_TRACE("start " + std::to_string(start));
    FrameController c(options(300), start);
    Machine m;
    const Trace t = play(&c, &m, std::vector<View>(30, View{}));
    // The first frame only measures; the plans after it scale from the recent mean costs, whose
    // fixed parts the model partly misses, so a step falls short (from 8 px: 93, 141, 220, 274
    // ms). Within +-10 % from the sixth frame on, every frame.
    EXPECT_EQ(within(t.frame_ms, 5, 300, 0.10), 25);
    EXPECT_LE(reversals(t.sizes, 0), 1);
    // Settled: the deadband holds the size over the last 20 frames.
    for (size_t i = 11; i < t.sizes.size(); ++i) EXPECT_EQ(t.sizes[i], t.sizes[10]) << i;
  }
}

// The factory's walk in miniature: the near meshes switch between 6k and 15k triangles every few
// poses (a cost the point size does not govern) while the surfel load drifts.
std::vector<View> walk() {
  std::vector<View> views;
  for (int i = 0; i < 40; ++i) {
    View v;
    v.near_triangles = (i / 3) % 2 == 0 ? 6000 : 15000;
    v.k = 3e5 * (1 + 0.3 * std::sin(i * 0.4));
    views.push_back(v);
  }
  return views;
}

TEST(FrameControllerSurfels, HoldsTheTargetWhileTheNearMeshesSwitch) {
  FrameController c(options(300), 1.5);
  Machine m;
  const Trace t = play(&c, &m, walk());
  // After the model has seen both kinds of view (poses 0-5), every pose within +-10 %.
  EXPECT_EQ(within(t.frame_ms, 6, 300, 0.10), 34);
  for (size_t i = 6; i < t.frame_ms.size(); ++i) {
    EXPECT_NEAR(t.frame_ms[i], 300, 30) << "pose " << i << " at " << t.sizes[i] << " px";
  }
}

TEST(FrameControllerSurfels, ThePapersReactiveRuleMissesTheSameWalk) {
  // The scenario is one a controller must model: the paper's rule (Sec. 4.3: s = (3 s + s t /
  // target) / 4 outside [0.9, 1.1]) on the same walk and machine misses many poses.
  Machine m;
  double s = 1.5;
  int ok = 0;
  const std::vector<View> views = walk();
  for (size_t i = 0; i < views.size(); ++i) {
    const FrameTimes t = m.run(work_of(views[i], s), s);
    if (i >= 6) ok += std::abs(t.frame_ms / 300 - 1) <= 0.10;
    const double r = t.frame_ms / 300;
    if (r < 0.9 || r > 1.1) s = std::clamp((3 * s + s * r) / 4, 1.0, 16.0);
  }
  EXPECT_LT(ok, 25) << "of 34";
}

TEST(FrameControllerSurfels, FollowsAChangeOfLoad) {
  // The machine gets 40 % slower at frame 15 (another job starts): the fits' weighted means
  // forget the old costs and the size follows within a few frames.
  FrameController c(options(300), 2);
  Machine m;
  std::vector<View> views(15, View{});
  Trace before = play(&c, &m, views);
  m.load = 1.4;
  Trace after = play(&c, &m, std::vector<View>(25, View{}));
  EXPECT_GT(after.sizes.back(), before.sizes.back());
  EXPECT_EQ(within(after.frame_ms, 6, 300, 0.10), 19);
  EXPECT_LE(reversals(after.sizes, 0), 1);
}

TEST(FrameControllerSurfels, UnreachableTargetsClampWithoutHunting) {
  {
    // 50 ms: the mesh pass alone takes more; the controller goes to the largest size and stays.
    FrameController c(options(50), 2);
    Machine m;
    const Trace t = play(&c, &m, std::vector<View>(12, View{}));
    for (size_t i = 2; i < t.sizes.size(); ++i) EXPECT_EQ(t.sizes[i], 16.0) << i;
  }
  {
    // 5 s: even 1 px is fast enough; the smallest size, the best image.
    FrameController c(options(5000), 4);
    Machine m;
    const Trace t = play(&c, &m, std::vector<View>(12, View{}));
    for (size_t i = 1; i < t.sizes.size(); ++i) EXPECT_EQ(t.sizes[i], 1.0) << i;
  }
}

TEST(FrameControllerSurfels, SameReportsGiveTheSameSizes) {
  FrameController a(options(300), 1.5), b(options(300), 1.5);
  Machine ma, mb;
  const Trace ta = play(&a, &ma, walk()), tb = play(&b, &mb, walk());
  EXPECT_EQ(ta.sizes, tb.sizes);
}

// The light field's configuration (view_selection.cc with the default FrameBudgetOptions): the
// active-view count in [1, 16], an integer, work growing with it; one pass; memory 0.75; shrink
// above +5 %, grow to a count predicted 10 % under the target, one view after 30 frames with room.
FrameControllerOptions lightfield(double target) {
  FrameControllerOptions o;
  o.target_ms = target;
  o.min = 1;
  o.max = 16;
  o.integer = true;
  o.work_grows = true;
  o.memory = 0.75;
  o.shrink_above = 0.05;
  o.grow_below = o.grow_margin = 0.10;
  o.grow_step = 1;
  o.grow_after_frames = 30;
  o.max_growth_backoff = 32;
  return o;
}

// A light-field frame: 2 ms + 0.9 ms per active view, times the load, +-3 % jitter.
struct ViewMachine {
  Machine jitter;  // its jitter only
  double load = 1;
  FrameTimes run(double views) {
    FrameTimes t;
    t.frame_ms = load * (2 + 0.9 * views) * jitter.jitter();
    t.pass_ms[0] = t.frame_ms;  // fixed_cost_ms 0: the whole frame is the views' pass
    return t;
  }
};

TEST(FrameControllerLightfield, HoldsNinetyHertzAndFollowsAChangeOfLoad) {
  const double target = 1000.0 / 90;
  FrameController c(lightfield(target), 16);
  ViewMachine m;
  std::vector<double> ms, views;
  for (int frame = 0; frame < 240; ++frame) {
    if (frame == 120) m.load = 1.4;  // another job starts: every view costs 40 % more
    const double k = c.plan([](double n) {
      FrameWork w;
      w.pass[0] = n;  // every view survives the other cullings
      return w;
    });
    ASSERT_EQ(k, std::floor(k));
    ASSERT_GE(k, 1);
    ASSERT_LE(k, 16);
    FrameWork w;
    w.pass[0] = k;
    const FrameTimes t = m.run(k);
    c.report(w, t);
    ms.push_back(t.frame_ms);
    views.push_back(k);
  }
  // At load 1, 10 views take 11 ms (11 would take 11.9): within +-10 % from the sixth frame on.
  EXPECT_EQ(within(std::vector<double>(ms.begin(), ms.begin() + 120), 6, target, 0.10), 114);
  // At load 1.4, 7 views take 11.6 ms: within +-10 % again six frames after the change.
  EXPECT_EQ(within(ms, 126, target, 0.10), 114);
  EXPECT_LT(views.back(), views[119]);
  EXPECT_LE(reversals(views, 6), 2);
}

}  // namespace
}  // namespace calf::player
