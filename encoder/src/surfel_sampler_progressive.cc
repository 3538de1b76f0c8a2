// The progressive sampler of paper 001 Sec. 3.2 (calf/encoder/surfel_sampler.h, kProgressive):
// rounds of a random sample of the input set, the samples farthest from the chosen surfels
// accepted, the ones close to them set aside.
#include <algorithm>
#include <cmath>

#include "surfel_sampler_internal.h"

namespace calf::encoder::surfel_internal {

std::vector<uint32_t> order_progressive(std::span<const Vec3> candidates, uint32_t n,
                                        const SurfelSamplerOptions& options) {
  const auto count = static_cast<uint32_t>(candidates.size());
  const uint32_t max_accept =
      options.max_accept != 0 ? options.max_accept : std::max(1u, options.round_samples / 4);
  Rng rng(options.seed);

  // The input set: candidates neither chosen nor set aside, each with its position, so that a
  // draw costs one cache miss, not two (the draws are what the sampler's time goes to on a
  // million candidates). Draws swap the drawn entry with the last one, so the set's order (and
  // hence the draws) depends only on the seed and the input.
  struct Entry {
    P3 p;
    uint32_t id;
  };
  std::vector<Entry> pool(count);
  for (uint32_t i = 0; i < count; ++i) {
    const Vec3& c = candidates[i];
    pool[i] = {{static_cast<float>(c.x), static_cast<float>(c.y), static_cast<float>(c.z)}, i};
  }
  std::vector<Entry> reserve;  // set aside by the vicinity rule, in the order set aside
  auto draw = [&]() {
    const uint32_t j = rng.below(static_cast<uint32_t>(pool.size()));
    const Entry e = pool[j];
    pool[j] = pool.back();
    pool.pop_back();
    return e;
  };

  std::vector<uint32_t> order;
  std::vector<P3> chosen;  // the positions of `order`, for rebuilding the grid
  order.reserve(n);
  chosen.reserve(n);
  P3 origin;
  float extent;
  {
    // The box of every candidate, from the pool's positions (before any draw).
    P3 lo = pool.front().p, hi = lo;
    for (const Entry& e : pool) {
      lo = {std::min(lo.x, e.p.x), std::min(lo.y, e.p.y), std::min(lo.z, e.p.z)};
      hi = {std::max(hi.x, e.p.x), std::max(hi.y, e.p.y), std::max(hi.z, e.p.z)};
    }
    origin = lo;
    extent = std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
  }
  // The first surfel is the same draw as the exact greedy permutation's first (rng.below(count)
  // on the identity list), so both orders start from one point.
  const Entry first = draw();
  order.push_back(first.id);
  chosen.push_back(first.p);

  // Grid over the chosen surfels. It starts with one cell per object and is rebuilt with the
  // current spacing (the best distance of a round, about the covering radius of the chosen set)
  // whenever that falls below half the cell: queries then stay within one ring of cells, and the
  // O(chosen) rebuilds add up to O(n) over the halvings.
  PointGrid grid;
  grid.reset(origin, extent, extent, n);
  grid.insert(first.id, first.p);
  auto rebuild = [&](float cell) {
    grid.reset(origin, extent, cell, n);
    for (size_t i = 0; i < order.size(); ++i) grid.insert(order[i], chosen[i]);
  };

  std::vector<Entry> sample;
  std::vector<float> d2;
  std::vector<uint8_t> exact;
  std::vector<uint32_t> slots;
  uint32_t accept = 1;
  uint64_t round = 0;
  const float vicinity2 = static_cast<float>(options.vicinity * options.vicinity);
  float previous_best2 = 0.0f;  // the first accepted distance of the last round, squared
  // Appends up to `want` samples drawn from the input set to the round, with their distances.
  auto draw_batch = [&](size_t want, float stop2) {
    const size_t s0 = sample.size();
    const size_t s = std::min(want, pool.size());
    sample.resize(s0 + s);
    d2.resize(s0 + s);
    exact.resize(s0 + s);
    // Draw first, query after. The slots drawn depend only on the generator and the set's size,
    // so they are picked and prefetched before any is read: the cache misses of the draws (the
    // sampler's main cost on a million candidates) overlap instead of following one another.
    slots.resize(s);
    for (size_t k = 0; k < s; ++k) {
      slots[k] = rng.below(static_cast<uint32_t>(pool.size() - k));
      __builtin_prefetch(&pool[slots[k]]);
    }
    for (size_t k = 0; k < s; ++k) {
      sample[s0 + k] = pool[slots[k]];
      pool[slots[k]] = pool.back();
      pool.pop_back();
    }
    for (size_t k = s0; k < s0 + s; ++k) {
      bool is_exact = true;
      d2[k] = grid.nearest2(sample[k].p, UINT32_MAX, stop2, &is_exact);
      exact[k] = is_exact ? 1 : 0;
    }
  };
  // The sample farthest from the chosen set (ties: the smaller candidate index), evaluating
  // upper bounds lazily: while a bound is on top it is replaced by the exact distance (to every
  // surfel chosen so far, this round's included). -1 marks samples accepted this round.
  auto farthest = [&]() {
    const size_t s = sample.size();
    while (true) {
      size_t best = s;
      for (size_t k = 0; k < s; ++k) {
        if (d2[k] < 0.0f) continue;
        if (best == s || d2[k] > d2[best] || (d2[k] == d2[best] && sample[k].id < sample[best].id))
          best = k;
      }
      if (best == s || exact[best] != 0) return best;
      d2[best] = grid.nearest2(sample[best].p);
      exact[best] = 1;
    }
  };
  const float extend2 = static_cast<float>(options.extend_below * options.extend_below);
  while (order.size() < n) {
    // An input set that cannot fill a round takes the samples set aside back (in the order set
    // aside): a round of a few leftovers would accept whatever they are. n <= count, so the two
    // together are never empty here.
    if (pool.size() < options.round_samples && !reserve.empty()) {
      pool.insert(pool.end(), reserve.begin(), reserve.end());
      reserve.clear();
    }
    sample.clear();
    d2.clear();
    exact.clear();
    // Most samples lie well inside the covered part: a query stops at the first chosen surfel
    // within half the last round's best distance and keeps that upper bound. Only a sample whose
    // bound comes out on top is queried in full (lazy evaluation: the surfels accepted are
    // those an exact query of every sample would accept).
    const float stop2 = 0.25f * previous_best2;
    draw_batch(options.round_samples, stop2);
    // A round whose best is well below the last round's best draws more (extend_below).
    for (uint32_t e = 0; e < kSurfelMaxExtensions && extend2 > 0.0f && !pool.empty(); ++e) {
      if (d2[farthest()] >= extend2 * previous_best2) break;
      draw_batch(options.round_samples, stop2);
    }
    const size_t s = sample.size();
    // Within the round: the exact greedy step over the sample, `accept` times.
    const size_t take = std::min<size_t>({accept, n - order.size(), s});
    float round_best2 = -1.0f, last2 = 0.0f;
    for (size_t a = 0; a < take; ++a) {
      const size_t best = farthest();
      const uint32_t id = sample[best].id;
      const P3 at = sample[best].p;
      last2 = d2[best];
      if (a == 0) round_best2 = last2;
      d2[best] = -1.0f;
      order.push_back(id);
      chosen.push_back(at);
      grid.insert(id, at);
      // Exact values stay exact and bounds stay bounds under this minimum.
      if (a + 1 < take)
        for (size_t k = 0; k < s; ++k)
          if (d2[k] >= 0.0f) d2[k] = std::min(d2[k], dist2(sample[k].p, at));
    }
    // The rest go back to the input set, or aside when they are close to the chosen set (a
    // bound below the threshold is enough to know; a bound above it puts the sample back).
    const float aside2 = vicinity2 * last2;
    for (size_t k = 0; k < s; ++k) {
      if (d2[k] < 0.0f) continue;
      if (d2[k] < aside2) {
        reserve.push_back(sample[k]);
      } else {
        pool.push_back(sample[k]);
      }
    }
    if (round_best2 > 0.0f && round_best2 < 0.25f * grid.cell() * grid.cell())
      rebuild(std::sqrt(round_best2));
    if (round_best2 >= 0.0f) previous_best2 = round_best2;
    ++round;
    if (round % options.growth_period == 0 && accept < max_accept) ++accept;
  }
  return order;
}

}  // namespace calf::encoder::surfel_internal
