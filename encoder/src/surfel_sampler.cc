// The entry points of the surfel orderings (calf/encoder/surfel_sampler.h): input checks, the
// random baseline and r_m (paper 001 Sec. 4.1). The greedy permutation through a tree, the
// progressive sampler and the plain exact greedy permutation have a file each.
#include "calf/encoder/surfel_sampler.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>

#include "calf/format/coordinates.h"
#include "surfel_sampler_internal.h"

namespace calf::encoder {
namespace {

using surfel_internal::P3;

Status option_error(const std::string& what) {
  return Status(ErrorId::kSurfelSamplerOption, "surfel sampler: " + what);
}

Status check_options(const SurfelSamplerOptions& o) {
  if (o.method != SurfelOrderMethod::kProgressive && o.method != SurfelOrderMethod::kExactGreedy &&
      o.method != SurfelOrderMethod::kRandom && o.method != SurfelOrderMethod::kGreedyTree)
    return option_error("method " + std::to_string(static_cast<int>(o.method)) +
                        " is not progressive (0), exact (1), random (2) or greedy-tree (3)");
  if (o.round_samples < 1 || o.round_samples > kSurfelMaxRoundSamples)
    return option_error("round_samples " + std::to_string(o.round_samples) + " is not in 1.." +
                        std::to_string(kSurfelMaxRoundSamples));
  if (o.growth_period < 1) return option_error("growth_period is 0 (must be >= 1 round)");
  if (o.max_accept > o.round_samples)
    return option_error("max_accept " + std::to_string(o.max_accept) + " is above round_samples " +
                        std::to_string(o.round_samples));
  if (!(o.vicinity >= 0.0 && o.vicinity < 1.0))
    return option_error("vicinity " + std::to_string(o.vicinity) + " is not in [0, 1)");
  if (!(o.extend_below >= 0.0 && o.extend_below < 1.0))
    return option_error("extend_below " + std::to_string(o.extend_below) + " is not in [0, 1)");
  if (o.p_m < 1) return option_error("p_m is 0 (must be >= 1)");
  if (o.threads > kSurfelMaxThreads)
    return option_error("threads " + std::to_string(o.threads) + " is above " +
                        std::to_string(kSurfelMaxThreads));
  return Status::Ok();
}

// Fisher-Yates on the index list, stopped after n draws.
std::vector<uint32_t> order_random(size_t count, uint32_t n, uint64_t seed) {
  std::vector<uint32_t> all(count);
  std::iota(all.begin(), all.end(), 0u);
  surfel_internal::Rng rng(seed);
  for (uint32_t i = 0; i < n; ++i) {
    const uint32_t j = i + rng.below(static_cast<uint32_t>(count - i));
    std::swap(all[i], all[j]);
  }
  all.resize(n);
  return all;
}

}  // namespace

const char* surfel_order_method_name(SurfelOrderMethod method) {
  switch (method) {
    case SurfelOrderMethod::kProgressive:
      return "progressive";
    case SurfelOrderMethod::kExactGreedy:
      return "exact";
    case SurfelOrderMethod::kRandom:
      return "random";
    case SurfelOrderMethod::kGreedyTree:
      return "greedy-tree";
  }
  return "unknown";
}

Expected<SurfelOrder> order_surfels(std::span<const Vec3> candidates, uint32_t n,
                                    const SurfelSamplerOptions& options) {
  if (candidates.empty())
    return Status(ErrorId::kSurfelNoCandidates, "surfel sampler: no candidate position to order");
  if (candidates.size() > UINT32_MAX)
    return Status(ErrorId::kSurfelCount, "surfel sampler: " + std::to_string(candidates.size()) +
                                             " candidates, above 2^32 - 1");
  if (n == 0 || n > candidates.size())
    return Status(ErrorId::kSurfelCount, "surfel sampler: surfel count " + std::to_string(n) +
                                             " is not in 1.." + std::to_string(candidates.size()) +
                                             " (the candidate count)");
  for (size_t i = 0; i < candidates.size(); ++i) {
    const Vec3& p = candidates[i];
    const double c[3] = {p.x, p.y, p.z};
    for (int a = 0; a < 3; ++a) {
      if (!coordinate_ok(c[a]))
        return Status(ErrorId::kSurfelPosition,
                      "surfel sampler: candidate " + std::to_string(i) + " coordinate " + "xyz"[a] +
                          " = " + std::to_string(c[a]) +
                          " is not finite or beyond the coordinate bound 1e12");
    }
  }
  CALF_RETURN_IF_ERROR(check_options(options));

  SurfelOrder result;
  switch (options.method) {
    case SurfelOrderMethod::kProgressive:
      result.order = surfel_internal::order_progressive(candidates, n, options);
      break;
    case SurfelOrderMethod::kExactGreedy:
      result.order = surfel_internal::order_exact_greedy(candidates, n, options);
      break;
    case SurfelOrderMethod::kRandom:
      result.order = order_random(candidates.size(), n, options.seed);
      break;
    case SurfelOrderMethod::kGreedyTree:
      result.order = surfel_internal::order_greedy_tree(candidates, n, options);
      break;
  }
  if (result.order.size() != n)
    return Status(ErrorId::kInternal, "surfel sampler: " + std::to_string(result.order.size()) +
                                          " surfels ordered instead of " + std::to_string(n));

  result.p_m = std::min(options.p_m, n);
  std::vector<P3> head(result.p_m);
  for (uint32_t i = 0; i < result.p_m; ++i)
    head[i] = surfel_internal::to_float(candidates[result.order[i]]);
  std::vector<float> nn = surfel_internal::nearest_neighbour_distances(head, options.threads);
  const auto mid = nn.begin() + static_cast<std::ptrdiff_t>((nn.size() - 1) / 2);
  std::nth_element(nn.begin(), mid, nn.end());
  result.r_m = *mid;
  return result;
}

}  // namespace calf::encoder
