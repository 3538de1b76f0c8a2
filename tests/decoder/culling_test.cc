// Tests of view-dependent culling (decoder/include/calf/decoder/culling.h). Frusta themselves
// and their intersection test are tested in tests/format/geometry_test.cc.
#include "calf/decoder/culling.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <set>

namespace calf {
namespace {

constexpr double kPi = 3.14159265358979323846;

Vec3 v(double x, double y, double z) {
  return {x, y, z};
}

// Point-in-frustum by its face planes, oriented with the centroid inside: an independent check.
bool contains(const Frustum& f, const Vec3& p, double tolerance = 1e-9) {
  Vec3 c{};
  for (const Vec3& q : f.corners()) c = {c.x + q.x / 8, c.y + q.y / 8, c.z + q.z / 8};
  const int face_corner[6] = {0, 1, 2, 3, 0, 4};  // a corner on each face (see Frustum ctor)
  for (int i = 0; i < 6; ++i) {
    const Vec3& n = f.face_normals()[i];
    const Vec3& q = f.corners()[face_corner[i]];
    const double side_c = dot(n, {c.x - q.x, c.y - q.y, c.z - q.z});
    const double side_p = dot(n, {p.x - q.x, p.y - q.y, p.z - q.z});
    const double scale = std::sqrt(dot(n, n));
    if (side_c * side_p < 0 && std::fabs(side_p) > tolerance * scale) return false;
  }
  return true;
}

// Every point a cell's texels can stand for (a direction through the cell, a radial depth in the
// range) lies inside the cell frustum.
TEST(CullingTest, CellFrustumContainsItsTexels) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u01(0, 1);
  const FaceGrid grid = *FaceGrid::with_cell_size(64, 16);
  const Vec3 vp = v(1, -2, 3);
  for (int f = 0; f < kCubeFaceCount; ++f) {
    for (uint32_t c = 0; c < grid.cell_count(); ++c) {
      const PixelRect r = *grid.cell_rect(c);
      const Frustum fr = cell_frustum(vp, cube_face_from_index(f), 64, r, 0.5, 20);
      for (int k = 0; k < 20; ++k) {
        const Vec3 d = direction_from_texel_coord(
            {cube_face_from_index(f), r.x + u01(rng) * r.width, r.y + u01(rng) * r.height}, 64);
        const double depth = 0.5 * std::pow(40.0, u01(rng));
        ASSERT_TRUE(contains(fr, v(vp.x + d.x * depth, vp.y + d.y * depth, vp.z + d.z * depth)))
            << "face " << f << " cell " << c;
      }
    }
  }
}

TEST(CullingTest, EyeAtViewpointSeesTheFaceItLooksAt) {
  const FaceGrid grid = *FaceGrid::with_cell_size(64, 16);
  EyeView eye;
  eye.position = v(0, 0, 0);
  eye.forward = v(1, 0, 0);
  eye.fov_y = kPi / 4;  // tan 22.5 deg = 0.41: inside the 4 middle cells' tangent range
  const Frustum e = eye_frustum(eye);
  const auto px = visible_cells_brute_force(v(0, 0, 0), CubeFace::kPosX, grid, 0.1, 10,
                                            std::span(&e, 1), nullptr);
  const auto nx = visible_cells_brute_force(v(0, 0, 0), CubeFace::kNegX, grid, 0.1, 10,
                                            std::span(&e, 1), nullptr);
  EXPECT_TRUE(nx.empty());
  // 4 x 4 cells each span 0.5 in tangent; a 45 degree square eye reaches tangent 0.41 on both
  // axes, so exactly the 4 middle cells.
  EXPECT_EQ(px, (std::vector<uint32_t>{grid.cell_index(1, 1), grid.cell_index(2, 1),
                                       grid.cell_index(1, 2), grid.cell_index(2, 2)}));
}

struct RandomScene {
  Vec3 viewpoint;
  std::vector<Frustum> eyes;
};

// A random eye: position in [-3, 3]^3, any direction, field of view, aspect and far plane.
EyeView random_eye_view(std::mt19937& rng) {
  std::uniform_real_distribution<double> pos(-3, 3), u01(0, 1);
  EyeView e;
  e.position = v(pos(rng), pos(rng), pos(rng));
  const double th = u01(rng) * 2 * kPi, ph = std::acos(2 * u01(rng) - 1);
  e.forward = v(std::sin(ph) * std::cos(th), std::sin(ph) * std::sin(th), std::cos(ph));
  e.up = std::fabs(e.forward.y) < 0.9 ? v(0, 1, 0) : v(1, 0, 0);
  e.fov_y = 0.3 + u01(rng) * 1.5;
  e.aspect = 0.5 + u01(rng) * 1.5;
  e.near = 0.05;
  e.far = 1 + u01(rng) * 8;
  return e;
}

RandomScene random_scene(std::mt19937& rng, int eye_count) {
  std::uniform_real_distribution<double> pos(-3, 3);
  RandomScene s;
  s.viewpoint = v(pos(rng), pos(rng), pos(rng));
  for (int i = 0; i < eye_count; ++i) s.eyes.push_back(eye_frustum(random_eye_view(rng)));
  return s;
}

// The property the decoder relies on: for every level count the quadtree search returns exactly
// the brute-force set, for one or several viewers; and the set for several viewers is the union
// of each viewer's set.
TEST(CullingTest, HierarchicalEqualsBruteForceAndUnionOverViewers) {
  std::mt19937 rng(2);
  int nonempty = 0, partial = 0;
  for (int trial = 0; trial < 60; ++trial) {
    const uint32_t face_size = 32 + 16 * (trial % 5);
    const FaceGrid grid = *FaceGrid::with_cell_size(face_size, 8 + 4 * (trial % 3));
    const RandomScene s = random_scene(rng, 1 + trial % 3);
    for (int f = 0; f < kCubeFaceCount; ++f) {
      const CubeFace face = cube_face_from_index(f);
      const auto brute =
          visible_cells_brute_force(s.viewpoint, face, grid, 0.2, 6, s.eyes, nullptr);
      for (uint32_t levels = 1; levels <= grid.quadtree_levels(); ++levels) {
        ASSERT_EQ(
            visible_cells_hierarchical(s.viewpoint, face, grid, 0.2, 6, s.eyes, levels, nullptr),
            brute)
            << "trial " << trial << " face " << f << " levels " << levels;
      }
      std::set<uint32_t> united;
      for (const Frustum& e : s.eyes) {
        for (uint32_t c : visible_cells_hierarchical(s.viewpoint, face, grid, 0.2, 6,
                                                     std::span(&e, 1), 0, nullptr)) {
          united.insert(c);
        }
      }
      ASSERT_EQ(std::vector<uint32_t>(united.begin(), united.end()), brute);
      nonempty += !brute.empty();
      partial += !brute.empty() && brute.size() < grid.cell_count();
    }
  }
  // The random scenes exercise the interesting case: some but not all cells visible.
  EXPECT_GT(partial, 50);
  EXPECT_GT(nonempty, partial);
}

// Conservative: a cell with any sampled texel point inside the eye frustum is never culled.
TEST(CullingTest, NeverCullsACellWithAVisiblePoint) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u01(0, 1);
  const FaceGrid grid = *FaceGrid::with_cell_size(32, 8);
  for (int trial = 0; trial < 30; ++trial) {
    const RandomScene s = random_scene(rng, 1);
    for (int f = 0; f < kCubeFaceCount; ++f) {
      const CubeFace face = cube_face_from_index(f);
      const auto visible =
          visible_cells_hierarchical(s.viewpoint, face, grid, 0.2, 6, s.eyes, 0, nullptr);
      for (uint32_t c = 0; c < grid.cell_count(); ++c) {
        const PixelRect r = *grid.cell_rect(c);
        bool seen = false;
        for (int k = 0; k < 200 && !seen; ++k) {
          const Vec3 d = direction_from_texel_coord(
              {face, r.x + u01(rng) * r.width, r.y + u01(rng) * r.height}, 32);
          const double depth = 0.2 * std::pow(30.0, u01(rng));
          const Vec3& o = s.viewpoint;
          seen = contains(s.eyes[0], v(o.x + d.x * depth, o.y + d.y * depth, o.z + d.z * depth), 0);
        }
        if (seen) {
          EXPECT_TRUE(std::binary_search(visible.begin(), visible.end(), c))
              << "trial " << trial << " face " << f << " cell " << c;
        }
      }
    }
  }
}

TEST(CullingTest, HierarchyMakesFewerTestsForANarrowEye) {
  const FaceGrid grid = *FaceGrid::with_cell_size(1024, 64);  // 16 x 16 cells, 5 levels
  EyeView eye;
  eye.forward = v(1, 0.1, 0.05);
  eye.fov_y = 0.3;
  const Frustum e = eye_frustum(eye);
  CullStats flat, tree;
  const auto a = visible_cells_hierarchical(v(0, 0, 0), CubeFace::kPosX, grid, 0.1, 50,
                                            std::span(&e, 1), 1, &flat);
  const auto b = visible_cells_hierarchical(v(0, 0, 0), CubeFace::kPosX, grid, 0.1, 50,
                                            std::span(&e, 1), 5, &tree);
  EXPECT_EQ(a, b);
  EXPECT_EQ(flat.tests, 256u);
  EXPECT_LT(tree.tests, flat.tests / 2);
  EXPECT_EQ(tree.visible_cells, a.size());
}

// GridCuller (the decoder's culling) returns exactly the brute-force set: its plane test rejects
// nothing the exact test accepts and its inside / corner-inside acceptances are never wrong, at
// every level count, for one or several viewers. One culler per grid serves every trial, so a
// changed viewpoint, depth range or eye needs nothing recomputed or invalidated (the culler holds
// directions only).
TEST(CullingTest, GridCullerEqualsBruteForce) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u01(0, 1);
  std::vector<GridCuller> cullers;
  for (int g = 0; g < 5; ++g) {
    cullers.emplace_back(*FaceGrid::with_cell_size(32 + 16 * g, 8 + 4 * (g % 3)));
  }
  CullStats stats;
  int partial = 0;
  std::vector<uint32_t> got;
  for (int trial = 0; trial < 300; ++trial) {
    const GridCuller& culler = cullers[trial % cullers.size()];
    const FaceGrid& grid = culler.grid();
    const RandomScene s = random_scene(rng, 1 + trial % 3);
    std::vector<PreparedEye> eyes;
    for (const Frustum& e : s.eyes) eyes.push_back(prepare_eye(e));
    // Depth ranges from a sliver to the decoder's far caps (eye far plus distance).
    const double z_near = 0.05 + u01(rng), z_far = z_near * (1.01 + 100 * u01(rng) * u01(rng));
    for (int f = 0; f < kCubeFaceCount; ++f) {
      const CubeFace face = cube_face_from_index(f);
      const auto brute =
          visible_cells_brute_force(s.viewpoint, face, grid, z_near, z_far, s.eyes, nullptr);
      for (uint32_t levels = 0; levels <= grid.quadtree_levels(); ++levels) {
        culler.visible(s.viewpoint, face, z_near, z_far, eyes, levels, &stats, &got);
        ASSERT_EQ(got, brute) << "trial " << trial << " face " << f << " levels " << levels;
      }
      partial += !brute.empty() && brute.size() < grid.cell_count();
    }
  }
  EXPECT_GT(partial, 200);
  // The planes settle most tests; the exact test is the exception.
  EXPECT_LT(stats.exact_tests * 4, stats.tests);
}

// The eye at the apex (the decoder's sky pass) and eyes just touching a cell: the acceptances near
// the tolerance still agree with the exact test.
TEST(CullingTest, GridCullerEqualsBruteForceForEyesAtTheApexAndGrazing) {
  std::mt19937 rng(6);
  std::uniform_real_distribution<double> u01(0, 1);
  const GridCuller culler(*FaceGrid::with_cell_size(64, 8));
  std::vector<uint32_t> got;
  for (int trial = 0; trial < 200; ++trial) {
    EyeView e;
    const double th = u01(rng) * 2 * kPi, ph = std::acos(2 * u01(rng) - 1);
    e.forward = v(std::sin(ph) * std::cos(th), std::sin(ph) * std::sin(th), std::cos(ph));
    // Axis-aligned views put eye planes on cell boundaries (touching counts as meeting).
    if (trial % 4 == 0) e.forward = v(trial % 8 == 0 ? 1 : 0, 0, trial % 8 == 0 ? 0 : -1);
    e.up = std::fabs(e.forward.y) < 0.9 ? v(0, 1, 0) : v(1, 0, 0);
    e.fov_y = trial % 4 == 0 ? kPi / 2 : 0.3 + u01(rng) * 1.5;
    e.aspect = trial % 4 == 0 ? 1 : 0.5 + u01(rng) * 1.5;
    e.near = 0.05;
    e.far = 5 + 50 * u01(rng);
    e.position = trial % 2 ? v(0.5, -0.25, 2) : v(0.5 + 0.1 * u01(rng), -0.25, 2);
    const Frustum fr = eye_frustum(e);
    const PreparedEye pe = prepare_eye(fr);
    for (int f = 0; f < kCubeFaceCount; ++f) {
      const CubeFace face = cube_face_from_index(f);
      const Vec3 apex = v(0.5, -0.25, 2);
      const auto brute = visible_cells_brute_force(apex, face, culler.grid(), e.near, 2 * e.far,
                                                   std::span(&fr, 1), nullptr);
      culler.visible(apex, face, e.near, 2 * e.far, std::span(&pe, 1), 0, nullptr, &got);
      ASSERT_EQ(got, brute) << "trial " << trial << " face " << f;
    }
  }
}

// Cached directions give the very frustum cell_frustum() builds from scratch.
TEST(CullingTest, CellFrustumFromCachedDirectionsIsBitIdentical) {
  const FaceGrid grid = *FaceGrid::with_cell_size(96, 16);
  for (int f = 0; f < kCubeFaceCount; ++f) {
    const CubeFace face = cube_face_from_index(f);
    for (uint32_t c = 0; c < grid.cell_count(); ++c) {
      const PixelRect r = *grid.cell_rect(c);
      const Frustum a = cell_frustum(v(1, 2, -3), face, 96, r, 0.3, 17);
      const std::array<Vec3, 8> b =
          cell_frustum_corners(cell_directions(face, 96, r), v(1, 2, -3), 0.3, 17);
      for (int i = 0; i < 8; ++i) ASSERT_EQ(a.corners()[i], b[i]) << "face " << f << " cell " << c;
    }
  }
}

// More eyes than one 64-bit group: the groups' sets are united without duplicates.
TEST(CullingTest, GridCullerTakesMoreThan64Eyes) {
  std::mt19937 rng(7);
  const GridCuller culler(*FaceGrid::with_cell_size(64, 8));
  const RandomScene s = random_scene(rng, 70);
  std::vector<PreparedEye> eyes;
  for (const Frustum& e : s.eyes) eyes.push_back(prepare_eye(e));
  std::vector<uint32_t> got;
  for (int f = 0; f < kCubeFaceCount; ++f) {
    const CubeFace face = cube_face_from_index(f);
    culler.visible(s.viewpoint, face, 0.2, 6, eyes, 0, nullptr, &got);
    EXPECT_EQ(got,
              visible_cells_brute_force(s.viewpoint, face, culler.grid(), 0.2, 6, s.eyes, nullptr))
        << "face " << f;
  }
}

// `a` turned by `angle` radians about the unit axis `k` (Rodrigues).
Vec3 turned(const Vec3& a, const Vec3& k, double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  return a * c + cross(k, a) * s + k * (dot(k, a) * (1 - c));
}

// A steady motion: a step, a turn about an axis and a zoom every frame (a walking, turning
// head). Summed over frames, the memory's bound on the motion is tight for it, so decisions are
// kept up to the limit of their slack.
struct Drift {
  Vec3 step, axis{0, 1, 0};
  double turn = 0, zoom = 0, far = 0;
};

Drift random_drift(std::mt19937& rng) {
  std::uniform_real_distribution<double> u01(0, 1), sym(-1, 1);
  auto magnitude = [&](double most) {
    return u01(rng) < 0.3 ? 0 : most * std::pow(10.0, -3 * u01(rng));
  };
  Drift d;
  d.step = normalize(v(sym(rng), sym(rng), sym(rng))) * magnitude(0.05);
  d.axis = normalize(v(sym(rng), sym(rng), sym(rng)));
  d.turn = magnitude(0.02) * (u01(rng) < 0.5 ? -1 : 1);  // 0.02 rad = 1.1 degrees a frame
  d.zoom = u01(rng) < 0.7 ? 0 : magnitude(0.01) * sym(rng);
  d.far = u01(rng) < 0.6 ? 0 : magnitude(0.03) * sym(rng);
  return d;
}

// The next pose of a moving eye: the drift, and now and then a jolt — a small turn, step, zoom,
// change of near, far or aspect — a large turn, a jump, or a frame where nothing moves.
EyeView moved(const EyeView& e, const Drift& drift, std::mt19937& rng) {
  std::uniform_real_distribution<double> u01(0, 1), sym(-1, 1);
  EyeView n = e;
  const double kind = u01(rng);
  if (kind < 0.7) {  // the drift
    n.position = e.position + drift.step;
    n.forward = turned(e.forward, drift.axis, drift.turn);
    n.up = turned(e.up, drift.axis, drift.turn);
    n.fov_y = std::clamp(e.fov_y * (1 + drift.zoom), 0.1, 2.5);
    n.far = std::clamp(e.far * (1 + drift.far), 1.0, 20.0);
    if (!view_axes_usable(n.forward, n.up)) n = e;
    return n;
  }
  const double small = std::pow(10.0, -4 + 3 * u01(rng));  // 1e-4 .. 0.1
  const Vec3 axis = normalize(v(sym(rng), sym(rng), sym(rng)));
  if (kind < 0.76) {  // turn
    n.forward = turned(e.forward, axis, small * sym(rng));
    n.up = turned(e.up, axis, small * sym(rng));
  } else if (kind < 0.8) {  // step
    n.position = e.position + axis * small;
  } else if (kind < 0.84) {  // zoom
    n.fov_y = std::clamp(e.fov_y * (1 + small * sym(rng)), 0.1, 2.5);
  } else if (kind < 0.87) {
    n.aspect = std::clamp(e.aspect * (1 + small * sym(rng)), 0.3, 3.0);
  } else if (kind < 0.9) {
    n.near = std::clamp(e.near * (1 + small * sym(rng)), 0.01, 0.5);
    n.far = std::clamp(e.far * (1 + small * sym(rng)), 1.0, 20.0);
  } else if (kind < 0.93) {  // a large turn
    n.forward = turned(e.forward, axis, 0.2 + 3 * u01(rng));
  } else if (kind < 0.95) {  // a jump
    n = random_eye_view(rng);
  }  // else: nothing moves
  if (!view_axes_usable(n.forward, n.up)) n = e;
  return n;
}

// GridCuller's memory (visible_reusing) on random pose sequences of a moving eye: at every frame
// and face, exactly the set of a fresh visible(), for node frusta at a fixed viewpoint (the
// decoder's views, their far cap following the eye), at the eye itself (the sky pass), and at a
// viewpoint and depth range drifting on their own (short frusta whose far caps cut through the
// eye), at every level count. Most decisions come from the memory. The sequences keep many
// decisions near the limit of their slack: a memory that kept one a little too long fails here
// (checked: halving the turn's or the travel's part of the bound, letting the budget pass by
// half, or leaving out the turn of the normals, the travel of the offsets, of the eye's origin,
// of the viewpoint or of the depth range each fails it).
TEST(CullingTest, GridCullerReusingEqualsFreshForMovingEyes) {
  std::mt19937 rng(8);
  std::uniform_real_distribution<double> u01(0, 1), sym(-1, 1);
  std::vector<GridCuller> cullers;
  for (int g = 0; g < 4; ++g) {
    cullers.emplace_back(*FaceGrid::with_cell_size(32 + 32 * g, g == 3 ? 64 : 8 + 4 * (g % 2)));
  }
  CullStats fresh_stats, reusing_stats;
  std::vector<uint32_t> fresh, got;
  int partial = 0;
  for (int sequence = 0; sequence < 72; ++sequence) {
    const GridCuller& culler = cullers[sequence % cullers.size()];
    const int mode = sequence % 3;  // 0: a view, 1: the sky pass, 2: drifting on its own
    Vec3 viewpoint = v(3 * u01(rng) - 1.5, 3 * u01(rng) - 1.5, 3 * u01(rng) - 1.5);
    double z_near = 0.05 + 0.5 * u01(rng), z_far = mode == 2 ? 1 + 3 * u01(rng) : 2 + 10 * u01(rng);
    const Vec3 viewpoint_step = v(sym(rng), sym(rng), sym(rng)) * (0.02 * u01(rng));
    const double near_rate = 0.02 * sym(rng) * u01(rng), far_rate = 0.02 * sym(rng) * u01(rng);
    const uint32_t levels = sequence % 4 == 1 ? 1 + sequence % culler.grid().quadtree_levels() : 0;
    std::array<CullMemory, 6> memory;
    const Drift drift = random_drift(rng);
    EyeView eye = random_eye_view(rng);
    // Point the eye at the viewpoint's neighbourhood, so that its planes cut through the faces.
    eye.forward = viewpoint + v(u01(rng), u01(rng), u01(rng)) - eye.position;
    for (int frame = 0; frame < 80; ++frame) {
      if (frame > 0) {
        eye = moved(eye, drift, rng);
        if (mode == 2) {
          viewpoint = viewpoint + viewpoint_step;
          z_near = std::clamp(z_near * (1 + near_rate), 0.02, 0.6);
          z_far = std::clamp(z_far * (1 + far_rate), 0.8, 8.0);
        }
      }
      const Frustum frustum = eye_frustum(eye);
      const PreparedEye prepared = prepare_eye(frustum);
      const Vec3 apex = mode == 1 ? eye.position : viewpoint;
      const double near = mode == 1 ? eye.near : z_near;
      const double far = mode == 1   ? 2 * eye.far
                         : mode == 0 ? std::max(z_far, length(eye.position - viewpoint) + eye.far)
                                     : z_far;
      for (int f = 0; f < kCubeFaceCount; ++f) {
        const CubeFace face = cube_face_from_index(f);
        culler.visible(apex, face, near, far, std::span(&prepared, 1), levels, &fresh_stats,
                       &fresh);
        culler.visible_reusing(apex, face, near, far, prepared, levels, &memory[f], &reusing_stats,
                               &got);
        ASSERT_EQ(got, fresh) << "sequence " << sequence << " frame " << frame << " face " << f;
        partial += !fresh.empty() && fresh.size() < culler.grid().cell_count();
      }
    }
  }
  EXPECT_GT(partial, 1000);
  // The memory settles most decisions; fresh tests are the exception.
  EXPECT_GT(reusing_stats.reused, 2 * reusing_stats.tests);
  EXPECT_LT(reusing_stats.tests * 3, fresh_stats.tests);
}

// A memory handed to another face or culler starts afresh, and clear() forgets: still the fresh
// sets.
TEST(CullingTest, GridCullerMemoryFollowsItsFaceAndCuller) {
  std::mt19937 rng(9);
  const GridCuller a(*FaceGrid::with_cell_size(64, 8)), b(*FaceGrid::with_cell_size(64, 16));
  CullMemory memory;
  std::vector<uint32_t> fresh, got;
  const Drift drift = random_drift(rng);
  EyeView eye = random_eye_view(rng);
  eye.forward = v(1, 0.2, 0.1);
  eye.position = v(0, 0, 0);
  for (int step = 0; step < 24; ++step) {
    const GridCuller& culler = step % 3 == 0 ? a : b;
    const CubeFace face = cube_face_from_index(step % 2 == 0 ? 0 : (step / 2) % 6);
    if (step == 12) memory.clear();
    eye = moved(eye, drift, rng);
    const Frustum frustum = eye_frustum(eye);
    const PreparedEye prepared = prepare_eye(frustum);
    culler.visible(v(0.1, 0, 0), face, 0.1, 20, std::span(&prepared, 1), 0, nullptr, &fresh);
    culler.visible_reusing(v(0.1, 0, 0), face, 0.1, 20, prepared, 0, &memory, nullptr, &got);
    ASSERT_EQ(got, fresh) << "step " << step;
  }
}

}  // namespace
}  // namespace calf
