// The exact greedy permutation (farthest-first traversal; calf/encoder/surfel_sampler.h,
// kExactGreedy): the reference the progressive sampler is measured against.
//
// Plain and obviously right rather than fast: one squared distance per candidate to the chosen
// set, all updated after each accepted surfel, O(n N). The candidates are split into fixed
// chunks (independent of the thread count); each chunk updates its distances and keeps its
// largest; the winner is the largest over chunks and, among equal values, the smallest candidate
// index, found by scanning the winning chunk: the same answer for any split.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <limits>

#include "surfel_sampler_internal.h"

namespace calf::encoder::surfel_internal {
namespace {

constexpr size_t kChunk = 1 << 14;

}  // namespace

std::vector<uint32_t> order_exact_greedy(std::span<const Vec3> candidates, uint32_t n,
                                         const SurfelSamplerOptions& options) {
  const size_t count = candidates.size();
  // Structure of arrays so the update loop vectorises.
  std::vector<float> xs(count), ys(count), zs(count);
  for (size_t i = 0; i < count; ++i) {
    xs[i] = static_cast<float>(candidates[i].x);
    ys[i] = static_cast<float>(candidates[i].y);
    zs[i] = static_cast<float>(candidates[i].z);
  }
  // Squared distance to the chosen set; chosen candidates hold -1 so that neither the update
  // (a minimum) nor the choice (a maximum) ever touches them again.
  std::vector<float> dist(count, std::numeric_limits<float>::infinity());
  const size_t chunks = (count + kChunk - 1) / kChunk;
  std::vector<float> chunk_max(chunks);

  std::vector<uint32_t> order;
  order.reserve(n);
  Rng rng(options.seed);
  uint32_t next = rng.below(static_cast<uint32_t>(count));
  tbb::task_arena arena(options.threads == 0 ? tbb::task_arena::automatic
                                             : static_cast<int>(options.threads));
  while (true) {
    order.push_back(next);
    dist[next] = -1.0f;
    if (order.size() == n) break;
    const float px = xs[next], py = ys[next], pz = zs[next];
    auto update = [&](size_t c) {
      const size_t begin = c * kChunk, end = std::min(count, begin + kChunk);
      float best = -2.0f;
      for (size_t i = begin; i < end; ++i) {
        const float dx = xs[i] - px, dy = ys[i] - py, dz = zs[i] - pz;
        const float d = dx * dx + dy * dy + dz * dz;
        const float cur = dist[i];
        const float upd = d < cur ? d : cur;
        dist[i] = upd;
        best = upd > best ? upd : best;
      }
      chunk_max[c] = best;
    };
    if (chunks == 1) {
      update(0);
    } else {
      arena.execute([&] {
        tbb::parallel_for(tbb::blocked_range<size_t>(0, chunks, 1),
                          [&](const tbb::blocked_range<size_t>& r) {
                            for (size_t c = r.begin(); c != r.end(); ++c) update(c);
                          });
      });
    }
    size_t win = 0;
    for (size_t c = 1; c < chunks; ++c)
      if (chunk_max[c] > chunk_max[win]) win = c;
    const size_t begin = win * kChunk, end = std::min(count, begin + kChunk);
    for (size_t i = begin; i < end; ++i) {
      if (dist[i] == chunk_max[win]) {
        next = static_cast<uint32_t>(i);
        break;
      }
    }
  }
  return order;
}

}  // namespace calf::encoder::surfel_internal
