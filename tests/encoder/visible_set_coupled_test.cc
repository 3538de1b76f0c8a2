// Tests of the visible-set builder's coupled motion (VisibilityMotion::kCoupled in
// encoder/include/calf/encoder/visible_set.h; paper 004 Sec. 3.2, Eqs. 3-4).
//
// The acceptance property in the coupled sense: at >= 1000 random t of a motion step, the eye at
// v(t) and every vertex (and sphere) at its linear in-between state at t, every primitive seen
// robustly nearest at a pixel centre by an independent brute-force ray caster written here
// (Moller-Trumbore in double through calf/format/cube.h's texel directions) is in the set; and
// every member, cast from the middle of its witness interval at its witness pixel, is the
// nearest hit. Float tolerance: "robustly nearest" means a barycentric margin above 1e-7 and the
// next hit farther by more than 1e-7 (relative) - pixels closer to an edge or a tie are counted
// and skipped (a few per thousand); for members, a hit within 1e-7 (relative) of the nearest
// counts as nearest and a barycentric margin down to -1e-9 as a hit.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <set>
#include <utility>
#include <vector>

#include "calf/encoder/visible_set.h"
#include "calf/format/cube.h"

namespace calf::encoder {
namespace {

using capture::SceneFile;
using Prim = std::pair<uint32_t, uint32_t>;  // (object, primitive)
using Tri = std::array<Vec3, 3>;

constexpr double kTie = 1e-7;

SceneFile two_frame_scene() {
  SceneFile s;
  s.name = "coupled";
  s.fps = 10;
  s.frame_count = 2;
  s.materials.push_back({});
  return s;
}

// One object whose mesh moves its triangles from `from` to `to` (vertex states at frames 0, 1).
void add_moving(SceneFile& s, const std::vector<Tri>& from, const std::vector<Tri>& to) {
  capture::SceneMesh mesh;
  mesh.name = "m" + std::to_string(s.meshes.size());
  for (size_t t = 0; t < from.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      const Vec3& p = from[t][k];
      mesh.positions.insert(mesh.positions.end(), {float(p.x), float(p.y), float(p.z)});
      mesh.indices.push_back(static_cast<uint32_t>(mesh.indices.size()));
    }
  if (&from != &to) {
    mesh.state_times = {0.0f, 0.1f};
    mesh.state_positions = mesh.positions;
    for (const Tri& t : to)
      for (const Vec3& p : t)
        mesh.state_positions.insert(mesh.state_positions.end(),
                                    {float(p.x), float(p.y), float(p.z)});
  }
  s.meshes.push_back(std::move(mesh));
  s.objects.push_back(
      {"o" + std::to_string(s.objects.size()), static_cast<uint32_t>(s.meshes.size() - 1), 0, {}});
}

// ---- the independent reference: the scene at t, brute-force ray casting ----

struct World {
  struct T {
    Vec3 a, b, c;
    Prim id;
  };
  struct Ball {
    Vec3 c;
    double r;
    Prim id;
  };
  std::vector<T> tris;
  std::vector<Ball> balls;
};

Vec3 to_world(const capture::SceneTransform& m, const float* p) {
  const double x = p[0], y = p[1], z = p[2];
  return {m[0] * x + m[1] * y + m[2] * z + m[3], m[4] * x + m[5] * y + m[6] * z + m[7],
          m[8] * x + m[9] * y + m[10] * z + m[11]};
}

// The scene between frames f and f + 1 at parameter t (the builder's chord, in double).
World world_at(const SceneFile& s, uint32_t f, double t) {
  World w;
  const uint32_t g = std::min(f + 1, s.frame_count - 1);
  for (uint32_t o = 0; o < s.objects.size(); ++o) {
    const capture::SceneMesh& mesh = s.meshes[s.objects[o].mesh];
    std::vector<float> p0, p1;
    capture::positions_at(mesh, f / s.fps, &p0);
    capture::positions_at(mesh, g / s.fps, &p1);
    const capture::SceneTransform& m0 = capture::transform_at(s.objects[o], f);
    const capture::SceneTransform& m1 = capture::transform_at(s.objects[o], g);
    auto vtx = [&](uint32_t i) {
      return to_world(m0, &p0[3 * i]) * (1 - t) + to_world(m1, &p1[3 * i]) * t;
    };
    const uint32_t nt = static_cast<uint32_t>(mesh.triangle_count());
    for (uint32_t k = 0; k < nt; ++k)
      w.tris.push_back({vtx(mesh.indices[3 * k]),
                        vtx(mesh.indices[3 * k + 1]),
                        vtx(mesh.indices[3 * k + 2]),
                        {o, k}});
    for (uint32_t k = 0; k < mesh.spheres.size(); ++k) {
      const capture::SceneSphere& sp = mesh.spheres[k];
      // Rigid transforms without scale in these tests: the radius is the object's.
      w.balls.push_back(
          {to_world(m0, sp.center.data()) * (1 - t) + to_world(m1, sp.center.data()) * t,
           sp.radius,
           {o, nt + k}});
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
  for (const World::T& tr : w.tris) {
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
    const double dd = dot(d, d), along = dot(e, d) / dd;
    const Vec3 off = e - d * along;
    const double dist2 = dot(off, off);
    if (dist2 > b.r * b.r || dot(e, e) <= b.r * b.r) continue;
    const double t = along - std::sqrt((b.r * b.r - dist2) / dd);
    if (t > 0) hits.push_back({t, b.id, (b.r - std::sqrt(dist2)) / b.r});
  }
  std::sort(hits.begin(), hits.end(), [](const Hit& a, const Hit& b) { return a.t < b.t; });
  return hits;
}

std::string name(const Prim& p) {
  return "object " + std::to_string(p.first) + " primitive " + std::to_string(p.second);
}

VisibleSet coupled(const SceneFile& scene, const ViewSegment& seg, uint32_t n,
                   uint32_t threads = 2) {
  VisibleSetOptions o;
  o.face_size = n;
  o.witnesses = true;
  o.threads = threads;
  o.motion = VisibilityMotion::kCoupled;
  const ViewSegment segs[1] = {seg};
  Expected<VisibleSet> r = compute_visible_set(scene, segs, o);
  EXPECT_TRUE(r.ok()) << r.status().to_string();
  return r.ok() ? std::move(*r) : VisibleSet{};
}

// The coupled acceptance property on one segment and one motion step (frames 0 -> 1).
// `only_face` >= 0: the first half casts through that face only (a scene seen through one face).
void check_property(const SceneFile& scene, const ViewSegment& seg, uint32_t n, int samples,
                    uint32_t seed, int only_face = -1) {
  const VisibleSet set = coupled(scene, seg, n);
  ASSERT_FALSE(set.witnesses.empty());
  std::set<Prim> found;
  for (const VisibilityWitness& w : set.witnesses) found.insert({w.object, w.primitive});

  // First half: every primitive robustly nearest at a pixel centre at a random t is in the set.
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  std::set<Prim> seen;
  int robust = 0, skipped = 0;
  for (int i = 0; i < samples; ++i) {
    const double t = u(rng);
    const World w = world_at(scene, 0, t);
    const Vec3 eye = seg.a + (seg.b - seg.a) * t;
    for (int f = 0; f < kCubeFaceCount; ++f)
      for (uint32_t y = 0; y < n; ++y)
        for (uint32_t x = 0; x < n && (only_face < 0 || f == only_face); ++x) {
          const std::vector<Hit> hits =
              cast(w, eye, direction_from_texel(cube_face_from_index(f), x, y, n));
          if (hits.empty()) continue;
          if (hits[0].margin > kTie && (hits.size() == 1 || hits[1].t > hits[0].t * (1 + kTie))) {
            ++robust;
            if (seen.insert(hits[0].id).second) {
              EXPECT_TRUE(found.count(hits[0].id))
                  << name(hits[0].id) << " is nearest at t " << t << " face " << f << " pixel " << x
                  << "," << y << " but not in the coupled set";
            }
          } else {
            ++skipped;
          }
        }
  }
  EXPECT_GT(robust, 100 * skipped) << "too many pixels within the tolerance of an edge or tie";
  EXPECT_FALSE(seen.empty());

  // Second half: every member is nearest at the middle of its witness interval.
  for (const VisibilityWitness& w : set.witnesses) {
    const Prim id{w.object, w.primitive};
    ASSERT_GT(w.s1 - w.s0, 1e-9) << name(id);
    const double t = 0.5 * (w.s0 + w.s1);
    const Vec3 eye = seg.a + (seg.b - seg.a) * t;
    if (w.face == kCubeFaceCount) continue;  // a sphere the eye enters (none here)
    const std::vector<Hit> hits =
        cast(world_at(scene, w.frame, t), eye,
             direction_from_texel(cube_face_from_index(int(w.face)), w.x, w.y, n));
    bool nearest = false;
    for (const Hit& h : hits) {
      if (h.t > hits[0].t * (1 + kTie)) break;
      nearest |= h.id == id;
    }
    EXPECT_TRUE(nearest) << name(id) << " is a member but is not nearest at its witness (t " << t
                         << ", face " << w.face << " pixel " << w.x << "," << w.y << ")";
  }
}

Vec3 random_point(std::mt19937& rng, double lo, double hi) {
  std::uniform_real_distribution<double> u(lo, hi);
  return {u(rng), u(rng), u(rng)};
}

// Random triangles around a segment, each vertex displaced independently between the frames
// (so edges rotate and deform: quadratic events), plus one moving sphere.
SceneFile random_moving_scene(uint32_t seed, int count, double motion) {
  std::mt19937 rng(seed);
  std::vector<Tri> from, to;
  for (int i = 0; i < count; ++i) {
    const Vec3 c = random_point(rng, -4, 4);
    const double size = i % 7 == 0 ? 0.3 : 1.5;
    Tri a, b;
    for (int k = 0; k < 3; ++k) {
      a[k] = c + random_point(rng, -size, size);
      b[k] = a[k] + random_point(rng, -motion, motion);
    }
    from.push_back(a);
    to.push_back(b);
  }
  SceneFile s = two_frame_scene();
  add_moving(s, from, to);
  if (motion > 0) {
    capture::SceneMesh balls;
    balls.name = "balls";
    balls.spheres.push_back({{0, 0, 0}, 0.6f});
    s.meshes.push_back(balls);
    capture::SceneTransform m0 = capture::kSceneIdentity, m1 = capture::kSceneIdentity;
    m0[3] = 2.5, m0[7] = 0.5, m0[11] = 1;
    m1[3] = -1.5, m1[7] = -0.5, m1[11] = 2;
    s.objects.push_back({"balls", static_cast<uint32_t>(s.meshes.size() - 1), 0, {m0, m1}});
  }
  return s;
}

const ViewSegment kSegment{{-0.7, 0.1, -0.2}, {0.8, -0.1, 0.3}};

TEST(VisibleSetCoupled, ExactOnRandomMovingTriangles) {
  check_property(random_moving_scene(1, 36, 1.0), kSegment, 10, 1000, 101);
  check_property(random_moving_scene(2, 36, 2.0), kSegment, 10, 300, 102);
}

// The slit scene: a wall at z = 2 with a vertical slit whose centre moves from x = +1 to x = -1
// and whose sides tilt one way, then the other (edges rotating: quadratic events), while the eye
// moves from x = -1 to x = +1. A small target at z = 4 near x = 0 lines up with the slit and the
// eye only in the middle of the motion; at either frame, from any point of the segment, it is
// hidden.
SceneFile slit_scene() {
  auto wall = [](double centre, double tilt) {
    const double half = 0.05, h = 3, far = 30;
    const Vec3 lt{centre - half + tilt, h, 2}, lb{centre - half - tilt, -h, 2};
    const Vec3 rt{centre + half + tilt, h, 2}, rb{centre + half - tilt, -h, 2};
    const Vec3 lft{-far, h, 2}, lfb{-far, -h, 2}, rft{far, h, 2}, rfb{far, -h, 2};
    const Vec3 top0{-far, far, 2}, top1{far, far, 2}, bot0{-far, -far, 2}, bot1{far, -far, 2};
    return std::vector<Tri>{{lfb, lb, lt},     {lfb, lt, lft},   {rb, rfb, rft},
                            {rb, rft, rt},     {lft, rft, top1}, {lft, top1, top0},
                            {bot0, bot1, rfb}, {bot0, rfb, lfb}};
  };
  SceneFile s = two_frame_scene();
  const std::vector<Tri> w0 = wall(1, 0.2), w1 = wall(-1, -0.2);
  add_moving(s, w0, w1);
  const std::vector<Tri> target = {{Vec3{-0.08, -0.08, 4}, Vec3{0.08, -0.08, 4}, Vec3{0, 0.1, 4}}};
  add_moving(s, target, target);
  return s;
}

const ViewSegment kSlitSegment{{-1, 0, 0}, {1, 0, 0}};

TEST(VisibleSetCoupled, TriangleSeenOnlyInTheMiddleOfTheMotion) {
  const SceneFile s = slit_scene();
  const VisibleSet c = coupled(s, kSlitSegment, 64);
  bool target = false;
  for (const VisibilityWitness& w : c.witnesses)
    if (w.object == 1) {
      target = true;
      EXPECT_GT(w.s0, 0.3) << "seen too early";
      EXPECT_LT(w.s1, 0.7) << "seen too late";
    }
  EXPECT_TRUE(target) << "the target behind the moving slit is not in the coupled set";
  // The per-frame question: frames 0 and 1 each static, the eye anywhere on the segment.
  VisibleSetOptions o;
  o.face_size = 64;
  const ViewSegment segs[1] = {kSlitSegment};
  Expected<VisibleSet> per_frame = compute_visible_set(s, segs, o);
  ASSERT_TRUE(per_frame.ok()) << per_frame.status().to_string();
  EXPECT_TRUE(per_frame->triangles[1].empty()) << "the target is visible at a frame";
  check_property(s, kSlitSegment, 64, 300, 7, 4);
}

TEST(VisibleSetCoupled, StaticSceneGivesThePerFrameSet) {
  for (uint32_t seed : {3u, 4u, 5u}) {
    SCOPED_TRACE(seed);
    const SceneFile s = random_moving_scene(seed, 60, 0);
    VisibleSetOptions o;
    o.face_size = 24;
    const ViewSegment segs[1] = {kSegment};
    Expected<VisibleSet> per_frame = compute_visible_set(s, segs, o);
    ASSERT_TRUE(per_frame.ok()) << per_frame.status().to_string();
    const VisibleSet c = coupled(s, kSegment, 24);
    EXPECT_EQ(c.triangles, per_frame->triangles);
    EXPECT_GT(per_frame->stats.visible_triangles, 5u);
    EXPECT_LT(per_frame->stats.visible_triangles, 60u);
  }
}

TEST(VisibleSetCoupled, SameResultForOneAndFourThreads) {
  const SceneFile s = random_moving_scene(9, 80, 1.5);
  const VisibleSet a = coupled(s, kSegment, 40, 1), b = coupled(s, kSegment, 40, 4);
  EXPECT_EQ(a.triangles, b.triangles);
  EXPECT_EQ(a.stats.triangle_pixel_pairs, b.stats.triangle_pixel_pairs);
  ASSERT_EQ(a.witnesses.size(), b.witnesses.size());
  for (size_t i = 0; i < a.witnesses.size(); ++i) {
    const VisibilityWitness &x = a.witnesses[i], &y = b.witnesses[i];
    EXPECT_TRUE(x.object == y.object && x.primitive == y.primitive && x.face == y.face &&
                x.x == y.x && x.y == y.y && x.s0 == y.s0 && x.s1 == y.s1)
        << "witness " << i;
  }
  EXPECT_EQ(a.stats.frames_solved, 1u);
}

// Steps are pairs of consecutive frames; a step repeating the previous one's geometry is skipped.
TEST(VisibleSetCoupled, StepsAreConsecutiveFrames) {
  // Three frames: the wall holds still from frame 0 to 1, then moves from 1 to 2.
  SceneFile s = slit_scene();
  s.frame_count = 3;
  capture::SceneMesh& wall = s.meshes[0];
  const size_t n = wall.positions.size();
  std::vector<float> moved(wall.state_positions.begin() + static_cast<std::ptrdiff_t>(n),
                           wall.state_positions.end());
  wall.state_times = {0.0f, 0.1f, 0.2f};
  wall.state_positions.resize(n);
  wall.state_positions.insert(wall.state_positions.end(), wall.positions.begin(),
                              wall.positions.end());
  wall.state_positions.insert(wall.state_positions.end(), moved.begin(), moved.end());
  const VisibleSet c = coupled(s, kSlitSegment, 64);
  EXPECT_EQ(c.stats.frames_solved, 2u);
  bool target = false;
  for (const VisibilityWitness& w : c.witnesses)
    if (w.object == 1) {
      target = true;
      EXPECT_EQ(w.frame, 1u) << "the target lines up only while the wall moves (frames 1 -> 2)";
    }
  EXPECT_TRUE(target);

  // Four identical frames: one step without motion, the per-frame set.
  SceneFile still = random_moving_scene(6, 40, 0);
  still.frame_count = 4;
  const VisibleSet c4 = coupled(still, kSegment, 16);
  EXPECT_EQ(c4.stats.frames_solved, 1u);
  VisibleSetOptions o;
  o.face_size = 16;
  const ViewSegment segs[1] = {kSegment};
  Expected<VisibleSet> per_frame = compute_visible_set(still, segs, o);
  ASSERT_TRUE(per_frame.ok()) << per_frame.status().to_string();
  EXPECT_EQ(c4.triangles, per_frame->triangles);
}

TEST(VisibleSetCoupled, MotionOutOfRangeIsAnError) {
  const SceneFile s = slit_scene();
  VisibleSetOptions o;
  o.face_size = 8;
  o.motion = static_cast<VisibilityMotion>(7);
  const ViewSegment segs[1] = {kSlitSegment};
  Expected<VisibleSet> r = compute_visible_set(s, segs, o);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().to_string().find("CALF-E114"), std::string::npos) << r.status().to_string();
}

}  // namespace
}  // namespace calf::encoder
