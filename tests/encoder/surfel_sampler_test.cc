// Tests of the surfel orderings (encoder/include/calf/encoder/surfel_sampler.h): orders are
// permutations whose prefixes nest, the exact greedy permutation meets its definition (brute
// force), the greedy permutation through a tree is the exact one element for element, the
// progressive sampler spreads prefixes far better than random, results do not depend on the
// thread count, r_m on hand-computed values, and every error id.
#include "calf/encoder/surfel_sampler.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <set>

namespace calf {
namespace {

constexpr encoder::SurfelOrderMethod kMethods[] = {
    encoder::SurfelOrderMethod::kGreedyTree, encoder::SurfelOrderMethod::kProgressive,
    encoder::SurfelOrderMethod::kExactGreedy, encoder::SurfelOrderMethod::kRandom};

// side x side grid on the unit square (z = 0): a flat surface whose ideal spacing is known.
std::vector<Vec3> plane_grid(int side) {
  std::vector<Vec3> p;
  for (int j = 0; j < side; ++j)
    for (int i = 0; i < side; ++i) p.push_back({(i + 0.5) / side, (j + 0.5) / side, 0.0});
  return p;
}

// Points evenly spread on the unit sphere (Fibonacci lattice): a closed surface.
std::vector<Vec3> sphere(int count) {
  std::vector<Vec3> p;
  const double golden = M_PI * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < count; ++i) {
    const double z = 1.0 - 2.0 * (i + 0.5) / count, s = std::sqrt(1.0 - z * z);
    p.push_back({s * std::cos(golden * i), s * std::sin(golden * i), z});
  }
  return p;
}

encoder::SurfelOrder order(std::span<const Vec3> c, uint32_t n, encoder::SurfelSamplerOptions o) {
  auto r = encoder::order_surfels(c, n, o);
  EXPECT_TRUE(r.ok()) << r.status().to_string();
  return r.ok() ? *r : encoder::SurfelOrder{};
}

encoder::SurfelSamplerOptions with(encoder::SurfelOrderMethod m, uint32_t threads = 1,
                                   uint64_t seed = 7) {
  encoder::SurfelSamplerOptions o;
  o.method = m;
  o.threads = threads;
  o.seed = seed;
  return o;
}

// Distance between the float-rounded positions (the sampler's points), in double.
double dist(const Vec3& a, const Vec3& b) {
  const double dx = double(float(a.x)) - double(float(b.x));
  const double dy = double(float(a.y)) - double(float(b.y));
  const double dz = double(float(a.z)) - double(float(b.z));
  return std::sqrt(dx * dx + dy * dy + dz * dz);
}

// Every method: n distinct indices below the candidate count, and the order for a smaller n is
// the start of the order for a larger one (prefixes nest: the LOD of a prefix never depends on
// how many surfels were built). n = the candidate count exercises the progressive sampler's
// reserve (samples set aside come back when the input set runs dry).
TEST(SurfelSamplerTest, OrdersArePermutationsAndPrefixesNest) {
  const std::vector<Vec3> c = sphere(1500);
  for (encoder::SurfelOrderMethod m : kMethods) {
    SCOPED_TRACE(encoder::surfel_order_method_name(m));
    const encoder::SurfelOrder all = order(c, 1500, with(m));
    ASSERT_EQ(all.order.size(), 1500u);
    std::set<uint32_t> seen(all.order.begin(), all.order.end());
    EXPECT_EQ(seen.size(), 1500u);
    EXPECT_LT(*seen.rbegin(), 1500u);
    for (uint32_t n : {1u, 2u, 300u, 1200u}) {
      const encoder::SurfelOrder part = order(c, n, with(m));
      ASSERT_EQ(part.order.size(), n);
      EXPECT_TRUE(std::equal(part.order.begin(), part.order.end(), all.order.begin())) << n;
    }
  }
}

// The exact greedy permutation, checked by brute force: each next point's distance to the
// chosen set is >= every remaining point's (up to float rounding of the sampler's distances).
TEST(SurfelSamplerTest, ExactGreedySatisfiesItsDefinition) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Vec3> c;
  for (int i = 0; i < 250; ++i) c.push_back({u(rng), u(rng), u(rng)});      // a volume
  for (int i = 0; i < 150; ++i) c.push_back({u(rng), 0.25 * u(rng), 2.0});  // a far slab
  const encoder::SurfelOrder o = order(c, 400, with(encoder::SurfelOrderMethod::kExactGreedy));
  ASSERT_EQ(o.order.size(), 400u);
  std::vector<double> d(c.size(), std::numeric_limits<double>::infinity());
  std::vector<bool> chosen(c.size(), false);
  for (size_t step = 0; step < o.order.size(); ++step) {
    const uint32_t next = o.order[step];
    if (step > 0) {
      for (size_t j = 0; j < c.size(); ++j) {
        if (!chosen[j]) {
          EXPECT_GE(d[next], d[j] * (1 - 1e-6)) << "step " << step << " j " << j;
        }
      }
    }
    chosen[next] = true;
    for (size_t j = 0; j < c.size(); ++j) d[j] = std::min(d[j], dist(c[j], c[next]));
  }
  // The greedy permutation's insertion radii never increase (a consequence of the definition,
  // checked independently of the loop above).
  std::vector<double> radius;
  for (size_t step = 1; step < o.order.size(); ++step) {
    double r = std::numeric_limits<double>::infinity();
    for (size_t i = 0; i < step; ++i) r = std::min(r, dist(c[o.order[i]], c[o.order[step]]));
    radius.push_back(r);
  }
  for (size_t i = 1; i < radius.size(); ++i) EXPECT_LE(radius[i], radius[i - 1] * (1 + 1e-6));
}

// The tree (kGreedyTree) against the plain reference (kExactGreedy): the same order, element for
// element, to the last candidate, on inputs that stress its pruning and its ties: a closed
// surface; a volume with a far slab; a grid (many exactly equal distances, ties to the smallest
// index); coincident points (distance 0 among the remaining, a leaf whose candidates are all
// covered); a line; far outliers (boxes of very different sizes); more candidates than a leaf
// holds by one; and one or two candidates.
TEST(SurfelSamplerTest, GreedyTreeIsTheExactGreedyPermutation) {
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<std::pair<const char*, std::vector<Vec3>>> inputs;
  inputs.emplace_back("sphere", sphere(2000));
  std::vector<Vec3> slab;
  for (int i = 0; i < 700; ++i) slab.push_back({u(rng), u(rng), u(rng)});
  for (int i = 0; i < 300; ++i) slab.push_back({u(rng), 0.25 * u(rng), 2.0});
  inputs.emplace_back("volume and slab", slab);
  inputs.emplace_back("grid", plane_grid(37));
  std::vector<Vec3> dup;
  for (int i = 0; i < 300; ++i) dup.push_back({double(i % 7), 0.0, double(i % 3)});
  for (int i = 0; i < 90; ++i) dup.push_back({0.5, 0.5, 0.5});
  inputs.emplace_back("coincident", dup);
  std::vector<Vec3> line;
  for (int i = 0; i < 500; ++i) line.push_back({0.001 * ((i * 37) % 500), 0.0, 0.0});
  inputs.emplace_back("line", line);
  std::vector<Vec3> outliers = sphere(600);
  outliers.push_back({1e4, -3e3, 7});
  outliers.push_back({-2e3, 5e3, 1e-3});
  for (Vec3& p : outliers) p.x *= 1e-3;  // a very flat sphere beside far points
  inputs.emplace_back("outliers", outliers);
  inputs.emplace_back("33 points", sphere(33));
  inputs.emplace_back("one", std::vector<Vec3>{{1, 2, 3}});
  inputs.emplace_back("two", std::vector<Vec3>{{1, 2, 3}, {1, 2, 3.5}});
  for (const auto& [name, c] : inputs) {
    SCOPED_TRACE(name);
    const auto n = static_cast<uint32_t>(c.size());
    for (uint64_t seed : {7u, 8u}) {
      const encoder::SurfelOrder tree =
          order(c, n, with(encoder::SurfelOrderMethod::kGreedyTree, 1, seed));
      const encoder::SurfelOrder exact =
          order(c, n, with(encoder::SurfelOrderMethod::kExactGreedy, 2, seed));
      EXPECT_EQ(tree.order, exact.order) << "seed " << seed;
      EXPECT_EQ(tree.r_m, exact.r_m);
    }
  }
}

// Spreading on a known surface: 40,000 candidates drawn uniformly on the unit square (not a grid,
// whose spacing would put a floor under random's r_min). rho = r_min / r_max of a prefix.
// Thresholds, not taken from the code's output:
// - an r-net on a dense connected surface has r_min >= r and r_max <= ~2r (a point's nearest
//   neighbour is at most twice the covering radius away), so the exact permutation's rho is about
//   1/2 or more: require >= 0.45 (grid discreteness);
// - points drawn uniformly at random: the smallest of m nearest-neighbour distances shrinks like
//   1/sqrt(m) times the typical one while the largest grows, rho ~ 0.05 at m = 500 (Poisson
//   process): require <= 0.2, so the metric can tell the two apart;
// - the progressive sampler: rho >= 0.35 (most of the exact one's) and >= 3x random's.
TEST(SurfelSamplerTest, ProgressiveSpreadsFarBetterThanRandom) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Vec3> c(40000);
  for (Vec3& p : c) p = {u(rng), u(rng), 0.0};
  const encoder::SurfelOrder prog = order(c, 2000, with(encoder::SurfelOrderMethod::kProgressive));
  const encoder::SurfelOrder exact = order(c, 2000, with(encoder::SurfelOrderMethod::kExactGreedy));
  const encoder::SurfelOrder rand = order(c, 2000, with(encoder::SurfelOrderMethod::kRandom));
  for (uint32_t p : {500u, 2000u}) {
    SCOPED_TRACE(p);
    auto sp = encoder::prefix_spacing(c, prog.order, p),
         se = encoder::prefix_spacing(c, exact.order, p),
         sr = encoder::prefix_spacing(c, rand.order, p);
    ASSERT_TRUE(sp.ok() && se.ok() && sr.ok());
    const double rho_p = sp->r_min / sp->r_max, rho_e = se->r_min / se->r_max,
                 rho_r = sr->r_min / sr->r_max;
    EXPECT_GE(rho_e, 0.45);
    EXPECT_LE(rho_r, 0.2);
    EXPECT_GE(rho_p, 0.35);
    EXPECT_GE(rho_p, 3 * rho_r);
    // The densest spacing of p points on the unit square (hexagonal packing) is
    // sqrt(2 / (sqrt(3) p)), an upper bound for the median; an r-net's points are at least r
    // apart with r at least half of it (discs of radius 2r cover the square), so the exact
    // median is above half of it; the progressive median must stay above 0.4 of it.
    const double ideal = std::sqrt(2.0 / (std::sqrt(3.0) * p));
    EXPECT_GT(se->r_median, ideal / 2);
    EXPECT_LE(se->r_median, ideal * 1.01);
    EXPECT_GT(sp->r_median, ideal * 0.4);
    EXPECT_LE(sp->r_median, ideal * 1.01);
  }
}

// The same input, options and seed give the same order and r_m for any thread count; another
// seed gives another order.
TEST(SurfelSamplerTest, DeterministicOverThreadsAndSeeds) {
  const std::vector<Vec3> c = sphere(3000);
  for (encoder::SurfelOrderMethod m : kMethods) {
    SCOPED_TRACE(encoder::surfel_order_method_name(m));
    const encoder::SurfelOrder one = order(c, 300, with(m, 1));
    for (uint32_t threads : {2u, 4u, 0u}) {
      const encoder::SurfelOrder other = order(c, 300, with(m, threads));
      EXPECT_EQ(one.order, other.order) << threads;
      EXPECT_EQ(one.r_m, other.r_m) << threads;
      EXPECT_EQ(one.p_m, other.p_m);
    }
    const encoder::SurfelOrder again = order(c, 300, with(m, 1));
    EXPECT_EQ(one.order, again.order);
    const encoder::SurfelOrder seeded = order(c, 300, with(m, 1, 8));
    EXPECT_NE(one.order, seeded.order);
  }
}

// r_m is the lower median of the nearest-neighbour distances of the first p_m surfels; p_m is
// capped at n. Points at 0, 1, 3, 7 on a line: nearest-neighbour distances 1, 1, 2, 4 whatever
// the order.
TEST(SurfelSamplerTest, RmAndPrefixSpacingOnHandComputedValues) {
  const std::vector<Vec3> c = {{0, 0, 0}, {1, 0, 0}, {3, 0, 0}, {7, 0, 0}};
  for (encoder::SurfelOrderMethod m : kMethods) {
    const encoder::SurfelOrder o = order(c, 4, with(m));
    EXPECT_EQ(o.p_m, 4u);
    EXPECT_EQ(o.r_m, 1.0f);
    auto s = encoder::prefix_spacing(c, o.order, 4);
    ASSERT_TRUE(s.ok());
    EXPECT_EQ(s->r_min, 1.0);
    EXPECT_EQ(s->r_median, 1.0);
    EXPECT_EQ(s->r_max, 4.0);
  }
  // Exact greedy from any start: the order's first two points are the two ends of the farthest
  // pair reachable from the start; r_m over p_m = 2 is their distance.
  encoder::SurfelSamplerOptions o = with(encoder::SurfelOrderMethod::kExactGreedy);
  o.p_m = 2;
  const encoder::SurfelOrder two = order(c, 4, o);
  EXPECT_EQ(two.p_m, 2u);
  const double d01 = std::fabs(c[two.order[0]].x - c[two.order[1]].x);
  EXPECT_EQ(two.r_m, static_cast<float>(d01));
  EXPECT_GE(d01, 4.0);  // from any start the farthest point is at least 4 away
  // One surfel: no neighbour, r_m = 0.
  const encoder::SurfelOrder single = order(c, 1, with(encoder::SurfelOrderMethod::kProgressive));
  EXPECT_EQ(single.p_m, 1u);
  EXPECT_EQ(single.r_m, 0.0f);
  // Coincident candidates: any order, r_m = 0.
  const std::vector<Vec3> same(50, Vec3{1, 2, 3});
  const encoder::SurfelOrder dup = order(same, 50, with(encoder::SurfelOrderMethod::kProgressive));
  EXPECT_EQ(dup.order.size(), 50u);
  EXPECT_EQ(dup.r_m, 0.0f);
}

// encoder::prefix_spacing (a hashed grid) against brute force, on points clustered at three scales
// (a dense blob, a sparse slab, two far outliers) so that queries cross many empty cells.
TEST(SurfelSamplerTest, PrefixSpacingMatchesBruteForce) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Vec3> c;
  for (int i = 0; i < 400; ++i) c.push_back({0.01 * u(rng), 0.01 * u(rng), 0.01 * u(rng)});
  for (int i = 0; i < 300; ++i) c.push_back({5 * u(rng), 2.0, 5 * u(rng)});
  c.push_back({-30, 7, 2});
  c.push_back({40, -3, 9});
  std::vector<uint32_t> ord(c.size());
  for (uint32_t i = 0; i < ord.size(); ++i) ord[i] = (i * 389u) % static_cast<uint32_t>(c.size());
  for (uint32_t prefix : {2u, 3u, 250u, 702u}) {
    std::vector<double> nn(prefix, std::numeric_limits<double>::infinity());
    for (uint32_t i = 0; i < prefix; ++i)
      for (uint32_t j = 0; j < prefix; ++j)
        if (i != j) nn[i] = std::min(nn[i], dist(c[ord[i]], c[ord[j]]));
    std::sort(nn.begin(), nn.end());
    auto s = encoder::prefix_spacing(c, ord, prefix, 2);
    ASSERT_TRUE(s.ok()) << s.status().to_string();
    EXPECT_NEAR(s->r_min, nn.front(), 1e-6 * nn.front()) << prefix;
    EXPECT_NEAR(s->r_median, nn[(prefix - 1) / 2], 1e-6 * nn[(prefix - 1) / 2]) << prefix;
    EXPECT_NEAR(s->r_max, nn.back(), 1e-6 * nn.back()) << prefix;
  }
}

ErrorId error_of(std::span<const Vec3> c, uint32_t n, const encoder::SurfelSamplerOptions& o) {
  auto r = encoder::order_surfels(c, n, o);
  return r.ok() ? ErrorId::kOk : r.status().id();
}

TEST(SurfelSamplerTest, Errors) {
  const std::vector<Vec3> c = plane_grid(10);
  EXPECT_EQ(error_of({}, 1, {}), ErrorId::kSurfelNoCandidates);
  EXPECT_EQ(error_of(c, 0, {}), ErrorId::kSurfelCount);
  EXPECT_EQ(error_of(c, 101, {}), ErrorId::kSurfelCount);
  EXPECT_EQ(error_of(c, 100, {}), ErrorId::kOk);

  std::vector<Vec3> bad = c;
  bad[3].y = std::nan("");
  auto r = encoder::order_surfels(bad, 10, {});
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().id(), ErrorId::kSurfelPosition);
  EXPECT_NE(r.status().to_string().find("candidate 3 coordinate y"), std::string::npos)
      << r.status().to_string();
  bad[3].y = 0;
  bad[7].z = 1e13;  // beyond the coordinate bound
  EXPECT_EQ(error_of(bad, 10, {}), ErrorId::kSurfelPosition);
  bad[7].z = std::numeric_limits<double>::infinity();
  EXPECT_EQ(error_of(bad, 10, {}), ErrorId::kSurfelPosition);

  auto option = [&](auto change) {
    encoder::SurfelSamplerOptions o;
    change(o);
    return error_of(c, 10, o);
  };
  EXPECT_EQ(option([](auto& o) { o.round_samples = 0; }), ErrorId::kSurfelSamplerOption);
  EXPECT_EQ(option([](auto& o) { o.round_samples = encoder::kSurfelMaxRoundSamples + 1; }),
            ErrorId::kSurfelSamplerOption);
  EXPECT_EQ(option([](auto& o) { o.growth_period = 0; }), ErrorId::kSurfelSamplerOption);
  EXPECT_EQ(option([](auto& o) { o.max_accept = 201; }), ErrorId::kSurfelSamplerOption);
  EXPECT_EQ(option([](auto& o) { o.vicinity = 1.0; }), ErrorId::kSurfelSamplerOption);
  EXPECT_EQ(option([](auto& o) { o.vicinity = -0.1; }), ErrorId::kSurfelSamplerOption);
  EXPECT_EQ(option([](auto& o) { o.vicinity = std::nan(""); }), ErrorId::kSurfelSamplerOption);
  EXPECT_EQ(option([](auto& o) { o.extend_below = 1.0; }), ErrorId::kSurfelSamplerOption);
  EXPECT_EQ(option([](auto& o) { o.extend_below = -0.5; }), ErrorId::kSurfelSamplerOption);
  EXPECT_EQ(option([](auto& o) { o.p_m = 0; }), ErrorId::kSurfelSamplerOption);
  EXPECT_EQ(option([](auto& o) { o.threads = encoder::kSurfelMaxThreads + 1; }),
            ErrorId::kSurfelSamplerOption);
  EXPECT_EQ(option([](auto& o) { o.method = static_cast<encoder::SurfelOrderMethod>(7); }),
            ErrorId::kSurfelSamplerOption);
  // Edges of the ranges are accepted.
  EXPECT_EQ(option([](auto& o) { o.round_samples = 1; }), ErrorId::kOk);
  EXPECT_EQ(option([](auto& o) { o.max_accept = 200; }), ErrorId::kOk);
  EXPECT_EQ(option([](auto& o) { o.vicinity = 0.0; }), ErrorId::kOk);

  const std::vector<uint32_t> ord = {0, 1, 2};
  EXPECT_EQ(encoder::prefix_spacing(c, ord, 0).status().id(), ErrorId::kSurfelCount);
  EXPECT_EQ(encoder::prefix_spacing(c, ord, 4).status().id(), ErrorId::kSurfelCount);
  const std::vector<uint32_t> outside = {0, 100};
  EXPECT_EQ(encoder::prefix_spacing(c, outside, 2).status().id(), ErrorId::kSurfelCount);
  EXPECT_EQ(encoder::prefix_spacing(c, ord, 2, encoder::kSurfelMaxThreads + 1).status().id(),
            ErrorId::kSurfelSamplerOption);
}

}  // namespace
}  // namespace calf
