// Spacing of a prefix of a surfel order (calf/encoder/surfel_sampler.h, "Spacing of a prefix"):
// each point's nearest-neighbour distance within the prefix, and their minimum, lower median and
// maximum. r_m (paper 001 Sec. 4.1) is the median over the first p_m surfels.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "calf/format/coordinates.h"
#include "surfel_sampler_internal.h"

namespace calf::encoder {
namespace surfel_internal {

std::vector<float> nearest_neighbour_distances(std::span<const P3> points, uint32_t threads) {
  std::vector<float> nn(points.size(), 0.0f);
  if (points.size() < 2) return nn;
  P3 origin;
  float extent;
  bounding_box(points, &origin, &extent);
  // Points on a surface: about extent / sqrt(count) apart, so a cell of that size holds O(1) of
  // them and a query finishes within a ring or two. (Points filling a volume would only make the
  // cells fuller: slower, never wrong.)
  PointGrid grid;
  grid.reset(origin, extent, extent / std::sqrt(static_cast<float>(points.size())), points.size());
  for (size_t i = 0; i < points.size(); ++i) grid.insert(static_cast<uint32_t>(i), points[i]);
  tbb::task_arena arena(threads == 0 ? tbb::task_arena::automatic : static_cast<int>(threads));
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, points.size(), 1024),
                      [&](const tbb::blocked_range<size_t>& range) {
                        for (size_t i = range.begin(); i != range.end(); ++i)
                          nn[i] = std::sqrt(grid.nearest2(points[i], static_cast<uint32_t>(i)));
                      });
  });
  return nn;
}

}  // namespace surfel_internal

Expected<PrefixSpacing> prefix_spacing(std::span<const Vec3> candidates,
                                       std::span<const uint32_t> order, uint32_t prefix,
                                       uint32_t threads) {
  if (prefix == 0 || prefix > order.size())
    return Status(ErrorId::kSurfelCount, "prefix_spacing: prefix " + std::to_string(prefix) +
                                             " is not in 1.." + std::to_string(order.size()) +
                                             " (the order's length)");
  if (threads > kSurfelMaxThreads)
    return Status(ErrorId::kSurfelSamplerOption, "prefix_spacing: threads " +
                                                     std::to_string(threads) + " is above " +
                                                     std::to_string(kSurfelMaxThreads));
  std::vector<surfel_internal::P3> points(prefix);
  for (uint32_t i = 0; i < prefix; ++i) {
    if (order[i] >= candidates.size())
      return Status(ErrorId::kSurfelCount, "prefix_spacing: order[" + std::to_string(i) + "] = " +
                                               std::to_string(order[i]) + " is not below the " +
                                               std::to_string(candidates.size()) + " candidates");
    const Vec3& p = candidates[order[i]];
    if (!coordinates_ok(p))
      return Status(ErrorId::kSurfelPosition, "prefix_spacing: candidate " +
                                                  std::to_string(order[i]) +
                                                  " has a coordinate that is not finite or "
                                                  "beyond the coordinate bound");
    points[i] = {static_cast<float>(p.x), static_cast<float>(p.y), static_cast<float>(p.z)};
  }
  PrefixSpacing s;
  if (prefix < 2) return s;
  std::vector<float> nn = surfel_internal::nearest_neighbour_distances(points, threads);
  const auto [lo, hi] = std::minmax_element(nn.begin(), nn.end());
  s.r_min = *lo;
  s.r_max = *hi;
  const auto mid = nn.begin() + static_cast<std::ptrdiff_t>((nn.size() - 1) / 2);
  std::nth_element(nn.begin(), mid, nn.end());
  s.r_median = *mid;
  return s;
}

}  // namespace calf::encoder
