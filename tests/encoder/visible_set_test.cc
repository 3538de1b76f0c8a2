// Tests of the from-segment visibility builder and its from-point baseline
// (encoder/include/calf/encoder/visible_set.h).
//
// The acceptance property: on a segment, every primitive seen in a from-point ID buffer
// at >= 1000 random points of the segment is in the set, and every primitive of the set is seen
// at some point of its interval. The first half uses the from-point baseline, itself checked
// against an independent brute-force ray caster written here (Moller-Trumbore through
// calf/format/cube.h's pixel directions). The second half casts, with that ray caster, the ray of
// each member's witness pixel from the middle of its witness interval and requires the member to
// be the nearest hit. Float tolerance of that check: a hit within 1e-7 (relative) of the
// nearest depth counts as a tie, and witness intervals shorter than 1e-9 of the segment are not
// checkable at a point (none occurs on these scenes; the test counts them and allows none).
#include "calf/encoder/visible_set.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <set>
#include <utility>
#include <vector>

#include "calf/encoder/sphere_mesh.h"
#include "calf/format/cube.h"
#include "visible_set_internal.h"  // encoder/src: the block interval list, tested directly below

namespace calf::encoder {
namespace {

using capture::SceneFile;
using Prim = std::pair<uint32_t, uint32_t>;  // (object, primitive)

SceneFile base_scene(uint32_t frames = 1) {
  SceneFile s;
  s.name = "test";
  s.fps = 10;
  s.frame_count = frames;
  s.materials.push_back({});
  return s;
}

// One mesh from triangles given as 9 floats each, one object placing it.
uint32_t add_triangles(SceneFile& s, const std::vector<std::array<float, 9>>& tris,
                       std::vector<capture::SceneTransform> transforms = {}) {
  capture::SceneMesh mesh;
  mesh.name = "m" + std::to_string(s.meshes.size());
  for (const auto& t : tris) {
    for (int k = 0; k < 3; ++k) {
      mesh.positions.insert(mesh.positions.end(), {t[3 * k], t[3 * k + 1], t[3 * k + 2]});
      mesh.indices.push_back(static_cast<uint32_t>(mesh.indices.size()));
    }
  }
  s.meshes.push_back(std::move(mesh));
  capture::SceneObject o;
  o.name = "o" + std::to_string(s.objects.size());
  o.mesh = static_cast<uint32_t>(s.meshes.size() - 1);
  o.transforms = std::move(transforms);
  s.objects.push_back(o);
  return static_cast<uint32_t>(s.objects.size() - 1);
}

// A quad (two triangles sharing the diagonal) with corners a, b, c, d in order.
std::vector<std::array<float, 9>> quad(Vec3 a, Vec3 b, Vec3 c, Vec3 d) {
  auto f = [](Vec3 p, Vec3 q, Vec3 r) {
    return std::array<float, 9>{float(p.x), float(p.y), float(p.z), float(q.x), float(q.y),
                                float(q.z), float(r.x), float(r.y), float(r.z)};
  };
  return {f(a, b, c), f(a, c, d)};
}

// ---- the independent reference: brute-force ray casting ----

struct World {
  struct Tri {
    Vec3 a, b, c;
    Prim id;
  };
  struct Ball {
    Vec3 c;
    double r;
    Prim id;
  };
  std::vector<Tri> tris;
  std::vector<Ball> balls;
};

World world_at(const SceneFile& s, uint32_t frame) {
  World w;
  for (uint32_t o = 0; o < s.objects.size(); ++o) {
    const capture::SceneMesh& mesh = s.meshes[s.objects[o].mesh];
    std::vector<float> p;
    capture::positions_at(mesh, frame / s.fps, &p);
    const capture::SceneTransform& m = capture::transform_at(s.objects[o], frame);
    auto tf = [&](double x, double y, double z) {
      return Vec3{m[0] * x + m[1] * y + m[2] * z + m[3], m[4] * x + m[5] * y + m[6] * z + m[7],
                  m[8] * x + m[9] * y + m[10] * z + m[11]};
    };
    auto vtx = [&](uint32_t i) { return tf(p[3 * i], p[3 * i + 1], p[3 * i + 2]); };
    const uint32_t t_count = static_cast<uint32_t>(mesh.triangle_count());
    for (uint32_t t = 0; t < t_count; ++t)
      w.tris.push_back({vtx(mesh.indices[3 * t]),
                        vtx(mesh.indices[3 * t + 1]),
                        vtx(mesh.indices[3 * t + 2]),
                        {o, t}});
    for (uint32_t k = 0; k < mesh.spheres.size(); ++k) {
      const auto& sp = mesh.spheres[k];
      w.balls.push_back(
          {tf(sp.center[0], sp.center[1], sp.center[2]), sp.radius, {o, t_count + k}});
    }
  }
  return w;
}

struct Hit {
  double t;
  Prim id;
  double margin;  // barycentric (triangles) or relative radial (spheres) distance to the rim
};

std::vector<Hit> cast(const World& w, const Vec3& o, const Vec3& d) {
  std::vector<Hit> hits;
  for (const World::Tri& tr : w.tris) {
    const Vec3 e1 = tr.b - tr.a, e2 = tr.c - tr.a;
    const Vec3 p = cross(d, e2);
    const double det = dot(e1, p);
    if (det == 0) continue;
    const Vec3 tv = o - tr.a;
    const double u = dot(tv, p) / det;
    const Vec3 q = cross(tv, e1);
    const double v = dot(d, q) / det;
    const double t = dot(e2, q) / det;
    const double margin = std::min({u, v, 1 - u - v});
    if (t > 0 && margin > -1e-9) hits.push_back({t, tr.id, margin});
  }
  for (const World::Ball& b : w.balls) {
    const Vec3 e = b.c - o;
    const double along = dot(e, d);
    const double dist2 = dot(e, e) - along * along;
    if (dist2 > b.r * b.r || dot(e, e) <= b.r * b.r) continue;
    const double t = along - std::sqrt(b.r * b.r - dist2);
    if (t > 0) hits.push_back({t, b.id, (b.r - std::sqrt(dist2)) / b.r});
  }
  std::sort(hits.begin(), hits.end(), [](const Hit& a, const Hit& b) { return a.t < b.t; });
  return hits;
}

// The brute-force from-point sets at `eye`: `must` holds primitives nearest with margins (not on
// a rim, not tied), `may` every primitive that rounding could make nearest.
void reference_sets(const World& w, const Vec3& eye, uint32_t n, std::set<Prim>* must,
                    std::set<Prim>* may) {
  for (int f = 0; f < kCubeFaceCount; ++f)
    for (uint32_t y = 0; y < n; ++y)
      for (uint32_t x = 0; x < n; ++x) {
        const Vec3 d = direction_from_texel(cube_face_from_index(f), x, y, n);
        const std::vector<Hit> hits = cast(w, eye, d);
        if (hits.empty()) continue;
        const double tie = 1e-7 * hits[0].t;
        if (hits[0].margin > 1e-7 && (hits.size() == 1 || hits[1].t > hits[0].t + tie))
          must->insert(hits[0].id);
        for (const Hit& h : hits) {
          may->insert(h.id);
          if (h.margin > 1e-7 && h.t > hits[0].t + tie) break;
        }
      }
}

std::set<Prim> members(const VisibleSet& v) {
  std::set<Prim> out;
  for (const VisibilityWitness& w : v.witnesses) out.insert({w.object, w.primitive});
  return out;
}

std::string name(const Prim& p) {
  return "object " + std::to_string(p.first) + " primitive " + std::to_string(p.second);
}

// The acceptance property on one segment and frame range: from-point at `points` random points
// within the set, and every member's witness confirmed by the ray caster.
void check_property(const SceneFile& scene, const ViewSegment& seg, uint32_t n, int points,
                    uint32_t seed, VisibleSetOptions options = {}) {
  options.face_size = n;
  options.witnesses = true;
  options.threads = 2;
  const ViewSegment segs[1] = {seg};
  Expected<VisibleSet> set = compute_visible_set(scene, segs, options);
  ASSERT_TRUE(set.ok()) << set.status().to_string();
  const std::set<Prim> found = members(*set);
  ASSERT_FALSE(found.empty());

  // First half: from-point ID buffers at random points of the segment.
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<Vec3> eyes;
  for (int i = 0; i < points; ++i) eyes.push_back(seg.a + (seg.b - seg.a) * u(rng));
  const uint32_t frame_end =
      options.frames == 0 ? scene.frame_count : options.first_frame + options.frames;
  Expected<VisibleSet> sampled = compute_visible_set_at_points(scene, eyes, options);
  ASSERT_TRUE(sampled.ok()) << sampled.status().to_string();
  for (const Prim& p : members(*sampled))
    EXPECT_TRUE(found.count(p)) << name(p) << " is seen from a point of the segment but is not "
                                << "in the from-segment set";

  // Second half: each member is the nearest hit at the middle of its witness interval.
  int short_intervals = 0;
  for (const VisibilityWitness& w : set->witnesses) {
    ASSERT_LT(w.face, 6u) << name({w.object, w.primitive}) << ": the eye passes through it";
    ASSERT_GE(w.frame, options.first_frame);
    ASSERT_LT(w.frame, frame_end);
    if (w.s1 - w.s0 < 1e-9) {
      ++short_intervals;
      continue;
    }
    const double s = 0.5 * (w.s0 + w.s1);
    const Vec3 eye = seg.a + (seg.b - seg.a) * s;
    const Vec3 d =
        direction_from_texel(cube_face_from_index(static_cast<int>(w.face)), w.x, w.y, n);
    const std::vector<Hit> hits = cast(world_at(scene, w.frame), eye, d);
    const Prim id{w.object, w.primitive};
    ASSERT_FALSE(hits.empty()) << name(id) << ": the witness ray hits nothing";
    bool ok = false;
    for (const Hit& h : hits)
      if (h.t <= hits[0].t * (1 + 1e-7) && h.id == id) ok = true;
    EXPECT_TRUE(ok) << name(id) << " is in the set but at s = " << s << " (interval [" << w.s0
                    << ", " << w.s1 << "]), face " << w.face << " pixel (" << w.x << ", " << w.y
                    << ") the nearest hit is " << name(hits[0].id);
  }
  EXPECT_EQ(short_intervals, 0);
}

// Random triangles in a box around the segment (some large, some slivers).
SceneFile random_scene(uint32_t seed, int count) {
  SceneFile s = base_scene();
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> pos(-4, 4), small(-0.6, 0.6);
  std::vector<std::array<float, 9>> tris;
  for (int i = 0; i < count; ++i) {
    const Vec3 c{pos(rng), pos(rng) * 0.5 + 1.5, pos(rng)};
    std::array<float, 9> t;
    for (int k = 0; k < 3; ++k) {
      t[3 * k] = float(c.x + small(rng));
      t[3 * k + 1] = float(c.y + small(rng));
      t[3 * k + 2] = float(c.z + small(rng));
    }
    if (i % 7 == 0) {  // a sliver: the third corner nearly on the first edge
      for (int a = 0; a < 3; ++a) t[6 + a] = 0.5f * (t[a] + t[3 + a]) + 0.002f * float(small(rng));
    }
    tris.push_back(t);
  }
  add_triangles(s, tris);
  return s;
}

const ViewSegment kSegment{{-1.03, 1.61, 0.37}, {1.21, 1.57, -0.29}};

TEST(VisibleSetTest, PerimeterSegmentsRunCounterClockwiseFromMinCorner) {
  const Box3 region{{0, 0, 0}, {4, 3, 2}};
  const std::vector<ViewSegment> s = perimeter_segments(region, 1.6, 2);
  ASSERT_EQ(s.size(), 8u);
  EXPECT_EQ(s[0].a, (Vec3{0, 1.6, 0}));
  EXPECT_EQ(s[1].b, (Vec3{0, 1.6, 2}));
  EXPECT_EQ(s[3].b, (Vec3{4, 1.6, 2}));
  EXPECT_EQ(s[5].b, (Vec3{4, 1.6, 0}));
  EXPECT_EQ(s[7].b, (Vec3{0, 1.6, 0}));
  for (size_t i = 0; i < s.size(); ++i) EXPECT_EQ(s[i].b, s[(i + 1) % s.size()].a);
  // A positive turn about +Y: the first edge's direction crossed with the second's points up.
  const Vec3 turn = cross(s[1].b - s[0].a, s[3].b - s[2].a);
  EXPECT_GT(turn.y, 0);
  EXPECT_EQ(perimeter_segments({{1, 0, 0}, {1, 2, 5}}, 1, 1).size(), 1u);
  EXPECT_TRUE(perimeter_segments({{1, 0, 2}, {1, 2, 2}}, 1, 3).empty());
}

TEST(VisibleSetTest, FromPointMatchesBruteForceRayCasting) {
  const SceneFile scene = random_scene(7, 60);
  const World world = world_at(scene, 0);
  VisibleSetOptions o;
  o.face_size = 16;
  o.witnesses = true;
  for (double s : {0.0, 0.37, 1.0}) {
    const Vec3 eye = kSegment.a + (kSegment.b - kSegment.a) * s;
    Expected<VisibleSet> got = compute_visible_set_at_points(scene, {&eye, 1}, o);
    ASSERT_TRUE(got.ok()) << got.status().to_string();
    std::set<Prim> must, may;
    reference_sets(world, eye, 16, &must, &may);
    const std::set<Prim> m = members(*got);
    EXPECT_GT(must.size(), 10u);
    for (const Prim& p : must) EXPECT_TRUE(m.count(p)) << name(p) << " missed at s = " << s;
    for (const Prim& p : m) EXPECT_TRUE(may.count(p)) << name(p) << " invented at s = " << s;
  }
}

TEST(VisibleSetTest, RandomTrianglesHavePropertyOfAcceptance) {
  for (uint32_t seed : {1u, 2u}) {
    SCOPED_TRACE(seed);
    check_property(random_scene(seed, 80), kSegment, 16, 1000, seed);
  }
  // A finer face on one scene (fewer points: the cost grows with the square of the face).
  check_property(random_scene(3, 80), kSegment, 40, 200, 3);
}

TEST(VisibleSetTest, OccludersWithGapsKeepOnlyWhatShowsThrough) {
  SceneFile s = base_scene();
  // A wall at z = -2 with a window, a far wall at z = -6 behind it (split in 8 x 4 quads), and a
  // triangle wholly hidden behind the near wall's solid part.
  std::vector<std::array<float, 9>> near;
  for (auto q : {quad({-5, 0, -2}, {-0.5, 0, -2}, {-0.5, 4, -2}, {-5, 4, -2}),
                 quad({0.5, 0, -2}, {5, 0, -2}, {5, 4, -2}, {0.5, 4, -2}),
                 quad({-0.5, 0, -2}, {0.5, 0, -2}, {0.5, 1.2, -2}, {-0.5, 1.2, -2}),
                 quad({-0.5, 2.1, -2}, {0.5, 2.1, -2}, {0.5, 4, -2}, {-0.5, 4, -2})})
    near.insert(near.end(), q.begin(), q.end());
  add_triangles(s, near);
  std::vector<std::array<float, 9>> far;
  for (int i = 0; i < 8; ++i)
    for (int j = 0; j < 4; ++j) {
      const double x = -8 + 2 * i, y = j;
      const auto q = quad({x, y, -6}, {x + 2, y, -6}, {x + 2, y + 1, -6}, {x, y + 1, -6});
      far.insert(far.end(), q.begin(), q.end());
    }
  add_triangles(s, far);
  const uint32_t hidden = add_triangles(s, {{-3.f, 1.f, -3.f, -2.f, 1.f, -3.f, -2.5f, 2.f, -3.f}});
  const ViewSegment seg{{-0.3, 1.6, 0.013}, {0.3, 1.6, 0.011}};
  check_property(s, seg, 24, 1000, 11);
  VisibleSetOptions o;
  o.face_size = 24;
  const ViewSegment segs[1] = {seg};
  Expected<VisibleSet> v = compute_visible_set(s, segs, o);
  ASSERT_TRUE(v.ok());
  EXPECT_TRUE(v->triangles[hidden].empty());
  // Some, not all, of the far wall shows through the window.
  EXPECT_GT(v->triangles[1].size(), 0u);
  EXPECT_LT(v->triangles[1].size(), 64u);
  // The near wall faces the segment: all 8 of its triangles are seen.
  EXPECT_EQ(v->triangles[0].size(), 8u);
}

TEST(VisibleSetTest, AdversarialTrianglesCrossBehindAndTouchTheSegment) {
  SceneFile s = base_scene();
  const Vec3 a = kSegment.a, b = kSegment.b;
  const Vec3 mid = (a + b) * 0.5;
  auto tri = [](Vec3 p, Vec3 q, Vec3 r) {
    return std::array<float, 9>{float(p.x), float(p.y), float(p.z), float(q.x), float(q.y),
                                float(q.z), float(r.x), float(r.y), float(r.z)};
  };
  std::vector<std::array<float, 9>> t;
  // Crossing the horizontal plane of the segment, in front and behind.
  t.push_back(tri({-2, 0.5, -3}, {2, 2.7, -3.2}, {0.3, 0.9, -2.7}));
  t.push_back(tri({-2, 2.5, 3}, {2, 0.7, 3.2}, {0.3, 2.9, 2.7}));
  // A large triangle around the eye, crossing every face's plane.
  t.push_back(tri({-6, 0.2, -6}, {6, 0.3, -5}, {0.2, 0.1, 7}));
  // Touching the segment: a vertex on it, and one pierced by it.
  const Vec3 on = a + (b - a) * 0.3;
  t.push_back(tri(on, on + Vec3{0.3, 1.1, -1.7}, on + Vec3{-0.9, 0.4, -1.3}));
  const Vec3 pierce = a + (b - a) * 0.7;
  t.push_back(tri(pierce + Vec3{0.01, 0.9, -0.3}, pierce + Vec3{0.02, -0.8, -0.6},
                  pierce + Vec3{-0.03, 0.1, 1.1}));
  // Slivers near the eye, and one in the segment's vertical plane.
  t.push_back(tri(mid + Vec3{-1, 0.3, -1}, mid + Vec3{1, 0.3001, -1.1}, mid + Vec3{0, 0.3, -1.05}));
  t.push_back(tri(a + Vec3{0, 0.5, 0}, b + Vec3{0, 0.5, 0}, mid + Vec3{0, 0.9, 0}));
  // Intersecting pair.
  t.push_back(tri({-1, 0.5, -4}, {1, 0.5, -4}, {0, 2.5, -5}));
  t.push_back(tri({-1, 2.3, -4.1}, {1, 1.9, -4.2}, {0, 0.6, -5.2}));
  add_triangles(s, t);
  // Enough random filler to occlude some of it.
  const SceneFile filler = random_scene(5, 40);
  s.meshes.push_back(filler.meshes[0]);
  s.objects.push_back({"filler", 1, 0, {}});
  check_property(s, kSegment, 16, 1000, 21);
}

TEST(VisibleSetTest, SameResultForOneAndFourThreads) {
  const SceneFile scene = random_scene(9, 150);
  const std::vector<ViewSegment> segs = perimeter_segments({{-1, 0, -1}, {1, 3, 0.5}}, 1.6, 1);
  VisibleSetOptions o;
  o.face_size = 40;
  o.witnesses = true;
  o.threads = 1;
  Expected<VisibleSet> one = compute_visible_set(scene, segs, o);
  o.threads = 4;
  Expected<VisibleSet> four = compute_visible_set(scene, segs, o);
  ASSERT_TRUE(one.ok() && four.ok());
  EXPECT_EQ(one->triangles, four->triangles);
  EXPECT_EQ(one->stats.triangle_pixel_pairs, four->stats.triangle_pixel_pairs);
  ASSERT_EQ(one->witnesses.size(), four->witnesses.size());
  for (size_t i = 0; i < one->witnesses.size(); ++i) {
    const VisibilityWitness &x = one->witnesses[i], &y = four->witnesses[i];
    EXPECT_TRUE(x.object == y.object && x.primitive == y.primitive && x.segment == y.segment &&
                x.face == y.face && x.x == y.x && x.y == y.y && x.s0 == y.s0 && x.s1 == y.s1);
  }
  // The perimeter sees more than any one of its segments.
  Expected<VisibleSet> first = compute_visible_set(scene, {segs.data(), 1}, o);
  ASSERT_TRUE(first.ok());
  EXPECT_LT(first->stats.visible_triangles, one->stats.visible_triangles);
}

// A wall that moves away at frame 2 (a rigid transform per frame) reveals a triangle.
TEST(VisibleSetTest, TriangleRevealedInALaterFrameIsFound) {
  SceneFile s = base_scene(3);
  capture::SceneTransform moved = capture::kSceneIdentity;
  moved[3] = 30;  // x + 30
  add_triangles(s, quad({-4, -1, -2}, {4, -1, -2}, {4, 4, -2}, {-4, 4, -2}),
                {capture::kSceneIdentity, capture::kSceneIdentity, moved});
  const uint32_t behind = add_triangles(s, {{-0.5f, 1.f, -4.f, 0.5f, 1.f, -4.f, 0.f, 2.f, -4.f}});
  const ViewSegment segs[1] = {{{-0.4, 1.6, 0.1}, {0.4, 1.6, -0.1}}};
  VisibleSetOptions o;
  o.face_size = 24;
  o.frames = 2;
  Expected<VisibleSet> early = compute_visible_set(s, segs, o);
  ASSERT_TRUE(early.ok()) << early.status().to_string();
  EXPECT_TRUE(early->triangles[behind].empty());
  EXPECT_EQ(early->stats.frames_solved, 1u);  // frames 0 and 1 hold the same geometry
  o.frames = 0;
  Expected<VisibleSet> all = compute_visible_set(s, segs, o);
  ASSERT_TRUE(all.ok());
  EXPECT_EQ(all->triangles[behind], (std::vector<uint32_t>{0}));
  EXPECT_EQ(all->stats.frames_solved, 2u);
  o.first_frame = 2;
  check_property(s, segs[0], 24, 1000, 5, o);
}

// Piecewise-linear vertex states: a triangle rises from behind a low wall over time.
TEST(VisibleSetTest, VertexStatesRevealATriangleAtTheirLaterFrames) {
  SceneFile s = base_scene(5);  // frames at t = 0, 0.1, .. 0.4 s
  add_triangles(s, quad({-4, -1, -2}, {4, -1, -2}, {4, 1.2, -2}, {-4, 1.2, -2}));
  capture::SceneMesh rising;
  rising.name = "rising";
  rising.positions = {-0.5f, -0.5f, -4.f, 0.5f, -0.5f, -4.f, 0.f, 0.5f, -4.f};
  rising.indices = {0, 1, 2};
  rising.state_times = {0.0f, 0.2f, 0.4f};
  // Hidden at states 0 and 1 (top below the wall's shadow), up high at state 2.
  rising.state_positions = {-0.5f, -0.5f, -4.f, 0.5f, -0.5f, -4.f, 0.f, 0.5f, -4.f,
                            -0.5f, -0.4f, -4.f, 0.5f, -0.4f, -4.f, 0.f, 0.6f, -4.f,
                            -0.5f, 2.5f,  -4.f, 0.5f, 2.5f,  -4.f, 0.f, 3.5f, -4.f};
  s.meshes.push_back(rising);
  s.objects.push_back({"rising", 1, 0, {}});
  const ViewSegment segs[1] = {{{-0.4, 1.6, 0.1}, {0.4, 1.6, -0.1}}};
  VisibleSetOptions o;
  o.face_size = 24;
  o.frames = 2;  // t = 0, 0.1: still hidden
  Expected<VisibleSet> early = compute_visible_set(s, segs, o);
  ASSERT_TRUE(early.ok()) << early.status().to_string();
  EXPECT_TRUE(early->triangles[1].empty());
  EXPECT_EQ(early->stats.frames_solved, 2u);
  o.frames = 0;
  Expected<VisibleSet> all = compute_visible_set(s, segs, o);
  ASSERT_TRUE(all.ok());
  EXPECT_EQ(all->triangles[1], (std::vector<uint32_t>{0}));
  EXPECT_EQ(all->stats.frames_solved, 5u);
  for (uint32_t f : {3u, 4u}) {
    o.first_frame = f;
    o.frames = 1;
    check_property(s, segs[0], 24, 1000, 40 + f, o);
  }
}

TEST(VisibleSetTest, SpheresAreKeptWholeAndOcclude) {
  SceneFile s = base_scene();
  capture::SceneMesh balls;
  balls.name = "balls";
  balls.positions = {-0.3f, 0.4f, -3.f, 0.3f, 0.4f, -3.f, 0.f, 0.9f, -3.f};
  balls.indices = {0, 1, 2};  // a small triangle in front of the far sphere
  balls.spheres = {{{0, 1.6f, -3}, 0.7f}, {{0, 1.6f, -8}, 0.5f}, {{2.2f, 1.3f, -5}, 0.9f}};
  s.meshes.push_back(balls);
  s.objects.push_back({"balls", 0, 0, {}});
  // A wall behind everything, partly hidden by the spheres.
  add_triangles(s, quad({-6, -1, -10}, {6, -1, -10}, {6, 4, -10}, {-6, 4, -10}));
  const ViewSegment seg{{-0.05, 1.6, 0.02}, {0.05, 1.6, -0.01}};
  check_property(s, seg, 24, 1000, 77);
  VisibleSetOptions o;
  o.face_size = 24;
  Expected<VisibleSet> v = compute_visible_set(s, {&seg, 1}, o);
  ASSERT_TRUE(v.ok());
  // Sphere 1 is right behind sphere 0 along the segment: hidden. Spheres 0 and 2 are kept whole.
  std::vector<uint32_t> expect = {0};
  for (uint32_t sph : {0u, 2u})
    for (uint32_t k = 0; k < kSphereTriangles; ++k)
      expect.push_back(1 + sph * kSphereTriangles + k);
  EXPECT_EQ(v->triangles[0], expect);
  EXPECT_EQ(v->stats.scene_triangles, 1 + 3 * kSphereTriangles + 2);
}

TEST(VisibleSetTest, ObjectGranularityKeepsWholeObjects) {
  SceneFile s = base_scene();
  add_triangles(s, quad({-4, -1, -2}, {4, -1, -2}, {4, 4, -2}, {-4, 4, -2}));
  // Object 1: one triangle in view, one hidden behind the wall; object 2: hidden entirely.
  add_triangles(s, {{-0.5f, 1.f, 1.f, 0.5f, 1.f, 1.f, 0.f, 2.f, 1.f},
                    {-0.5f, 1.f, -4.f, 0.5f, 1.f, -4.f, 0.f, 2.f, -4.f}});
  add_triangles(s, {{-1.5f, 1.f, -5.f, 0.5f, 1.f, -5.f, 0.f, 2.f, -5.f}});
  const ViewSegment seg{{-0.4, 1.6, 0.1}, {0.4, 1.6, -0.1}};
  VisibleSetOptions o;
  o.face_size = 24;
  Expected<VisibleSet> tri = compute_visible_set(s, {&seg, 1}, o);
  o.object_granularity = true;
  Expected<VisibleSet> obj = compute_visible_set(s, {&seg, 1}, o);
  ASSERT_TRUE(tri.ok() && obj.ok());
  EXPECT_EQ(tri->triangles[1], (std::vector<uint32_t>{0}));
  EXPECT_EQ(obj->triangles[1], (std::vector<uint32_t>{0, 1}));
  EXPECT_TRUE(obj->triangles[2].empty());
  EXPECT_EQ(obj->stats.visible_triangles, 4u);
}

TEST(VisibleSetTest, FromPointsFindsNoMoreThanFromSegment) {
  const SceneFile scene = random_scene(4, 120);
  const ViewSegment segs[1] = {kSegment};
  VisibleSetOptions o;
  o.face_size = 32;
  Expected<VisibleSet> seg = compute_visible_set(scene, segs, o);
  Expected<VisibleSet> pts = compute_visible_set_from_points(scene, segs, 8, o);
  ASSERT_TRUE(seg.ok() && pts.ok());
  EXPECT_LE(pts->stats.visible_triangles, seg->stats.visible_triangles);
  for (size_t i = 0; i < scene.objects.size(); ++i)
    EXPECT_TRUE(std::includes(seg->triangles[i].begin(), seg->triangles[i].end(),
                              pts->triangles[i].begin(), pts->triangles[i].end()));
  EXPECT_GT(pts->stats.triangle_pixel_pairs, 0u);
  EXPECT_GT(seg->stats.triangle_pixel_pairs, 0u);
}

TEST(VisibleSetTest, BadInputIsOneLineWithItsId) {
  const SceneFile scene = random_scene(1, 10);
  VisibleSetOptions o;
  o.face_size = 8;
  auto id = [](const auto& r) { return r.status().id(); };
  EXPECT_EQ(id(compute_visible_set(scene, {}, o)), ErrorId::kVisibleSetNoSegment);
  const ViewSegment zero[1] = {{{0, 1.5, 0}, {0, 1.5, 0}}};
  Expected<VisibleSet> r = compute_visible_set(scene, zero, o);
  EXPECT_EQ(id(r), ErrorId::kVisibleSetSegment);
  EXPECT_NE(r.status().message().find("segment 0"), std::string::npos);
  const ViewSegment nan[2] = {kSegment, {{0, NAN, 0}, {1, 1, 1}}};
  r = compute_visible_set(scene, nan, o);
  EXPECT_EQ(id(r), ErrorId::kVisibleSetSegment);
  EXPECT_NE(r.status().message().find("segment 1"), std::string::npos);
  const ViewSegment far[2] = {kSegment, {{0, 1.5, 0}, {500, 1.5, 0}}};
  r = compute_visible_set(scene, far, o);
  EXPECT_EQ(id(r), ErrorId::kVisibleSetOutside);
  EXPECT_NE(r.status().message().find("segment 1 end"), std::string::npos);
  const SceneFile empty = base_scene();
  EXPECT_EQ(id(compute_visible_set(empty, {&kSegment, 1}, o)), ErrorId::kVisibleSetScene);
  o.face_size = 0;
  EXPECT_EQ(id(compute_visible_set(scene, {&kSegment, 1}, o)), ErrorId::kVisibleSetOption);
  o.face_size = 8;
  o.first_frame = 3;
  EXPECT_EQ(id(compute_visible_set(scene, {&kSegment, 1}, o)), ErrorId::kVisibleSetOption);
  o.first_frame = 0;
  EXPECT_EQ(id(compute_visible_set_from_points(scene, {&kSegment, 1}, 0, o)),
            ErrorId::kVisibleSetOption);
  EXPECT_EQ(id(compute_visible_set_from_points(scene, far, 4, o)), ErrorId::kVisibleSetOutside);
  const Vec3 outside{0, 1e6, 0};
  EXPECT_EQ(id(compute_visible_set_at_points(scene, {&outside, 1}, o)),
            ErrorId::kVisibleSetOutside);
  EXPECT_EQ(id(compute_visible_set_at_points(scene, {}, o)), ErrorId::kVisibleSetNoSegment);
  // Every message is one line.
  EXPECT_EQ(r.status().to_string().find('\n'), std::string::npos);
}

// The per-pixel interval list (blocks of kListBlock intervals, split and rewritten in place) and
// the compositor on it, against a brute-force lower envelope: thousands of random depth lines
// make lists far longer than a block, as on grass. At random times the list must hold the
// nearest line covering that time (none where no line covers it), in sorted disjoint order, and
// its depth bound must be +inf with an uncovered time while it has a gap, then the largest depth
// at its intervals' ends once a far background line covers [0, 1].
TEST(VisibleSetTest, IntervalListMatchesBruteForceLowerEnvelope) {
  using visibility::Interval;
  std::mt19937_64 rng(19);
  std::uniform_real_distribution<double> u(0, 1);
  visibility::IntervalPool pool;
  visibility::IntervalList list;
  visibility::CompositeScratch scratch;
  std::vector<Interval> inserted;
  auto check = [&](bool complete) {
    std::vector<Interval> flat;
    list.for_each(pool, [&](const Interval& i) {
      flat.push_back(i);
      return true;
    });
    ASSERT_EQ(flat.size(), list.size());
    for (size_t i = 0; i < flat.size(); ++i) {
      ASSERT_LT(flat[i].s0, flat[i].s1);
      if (i > 0) {
        ASSERT_LE(flat[i - 1].s1, flat[i].s0);
      }
    }
    for (int k = 0; k < 400; ++k) {
      const double s = u(rng);
      double best = std::numeric_limits<double>::infinity();
      int64_t want = -1;
      for (const Interval& i : inserted)
        if (i.s0 < s && s < i.s1 && i.p + i.q * s < best) best = i.p + i.q * s, want = i.primitive;
      int64_t got = -1;
      for (const Interval& i : flat)
        if (i.s0 <= s && s < i.s1) got = i.primitive;
      ASSERT_EQ(got, want) << "at s = " << s << " after " << inserted.size() << " intervals";
    }
    double gap = -1;
    const double far = list.far_bound(pool, &gap);
    if (!complete) {
      ASSERT_EQ(far, std::numeric_limits<double>::infinity());
      ASSERT_GE(gap, 0);
      ASSERT_LE(gap, 1);
      for (const Interval& i : flat) ASSERT_FALSE(i.s0 <= gap && gap < i.s1) << "gap " << gap;
    } else {
      double want_far = 0;
      for (const Interval& i : flat)
        want_far = std::max({want_far, i.p + i.q * i.s0, i.p + i.q * i.s1});
      ASSERT_EQ(far, want_far);
    }
  };
  auto insert = [&](double s0, double s1, double p, double q) {
    Interval in{s0, s1, p, q, static_cast<uint32_t>(inserted.size()), -1};
    inserted.push_back(in);
    visibility::composite(&list, &pool, in, {}, &scratch);
  };
  for (int n = 0; n < 3000; ++n) {
    const double s0 = u(rng), len = 0.002 + 0.03 * u(rng) * u(rng);
    insert(s0, std::min(1.0, s0 + len), 1 + 50 * u(rng), 4 * u(rng) - 2);
    if (n % 500 == 499) check(false);
  }
  EXPECT_GT(list.size(), 4 * visibility::kListBlock);  // many blocks, split many times
  insert(0, 1, 200, 0);                                // a far background: no gap left
  check(true);
  // A near line over the middle replaces hundreds of intervals at once (blocks merged away).
  insert(0.25, 0.75, 0.5, 0);
  check(true);
}

}  // namespace
}  // namespace calf::encoder
