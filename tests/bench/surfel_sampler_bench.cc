// bench-surfel_sampler_bench: the surfel orderings of paper 001 (calf/encoder/surfel_sampler.h)
// on about a million candidates from a real surface, as many as the covered pixels of a
// 512^2 x 8 G-buffer: sampler time for 10k / 50k / 100k surfels for the progressive sampler, the
// exact greedy permutation and a random order, and the spacing of prefixes (r_min, median,
// r_max of each point's nearest-neighbour distance within the prefix; docs/SURFELS.md).
//
// Surfaces (--surface):
//   bumpy  a closed bumpy sphere: a Fibonacci lattice of --candidates points on the unit sphere
//          (evenly spread), each pushed along its radius by 0.15 sin(5 theta) sin(4 phi) + 0.05
//          sin(17 theta) (folds at two scales, so the spacing the sampler must keep varies)
//   plane  a --candidates grid on the unit square (flat; spacing known: 1 / sqrt(n) for n
//          surfels ideally)
//
// Limits beside the figures: the sampler >= 50x faster than the exact permutation at
// 10k surfels; its r_min / r_max within 10 % of the exact one's.
// Times: the median of --repeats runs (exact: one run, it takes seconds), wall clock and process
// CPU time with --threads workers (the exact permutation is the only parallel part).
#include <fmt/core.h>
#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <string>
#include <vector>

#include "calf/encoder/surfel_sampler.h"

namespace {

using calf::Vec3;

std::vector<Vec3> bumpy_sphere(uint32_t count) {
  std::vector<Vec3> p(count);
  const double golden = M_PI * (3.0 - std::sqrt(5.0));
  for (uint32_t i = 0; i < count; ++i) {
    const double z = 1.0 - 2.0 * (i + 0.5) / count;
    const double theta = std::acos(z), phi = golden * i;
    const double r =
        1.0 + 0.15 * std::sin(5 * theta) * std::sin(4 * phi) + 0.05 * std::sin(17 * theta);
    const double s = std::sin(theta);
    p[i] = {r * s * std::cos(phi), r * s * std::sin(phi), r * z};
  }
  return p;
}

std::vector<Vec3> plane_grid(uint32_t count) {
  const auto side = static_cast<uint32_t>(std::sqrt(static_cast<double>(count)));
  std::vector<Vec3> p;
  p.reserve(static_cast<size_t>(side) * side);
  for (uint32_t j = 0; j < side; ++j)
    for (uint32_t i = 0; i < side; ++i) p.push_back({(i + 0.5) / side, (j + 0.5) / side, 0.0});
  return p;
}

// Process CPU time: on a shared machine it tracks the work done where wall time also counts the
// waits for a core (both are printed; single-threaded runs compare fairly on CPU time).
double cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"bench-surfel_sampler_bench: surfel orderings (paper 001), time and spacing"};
  std::string surface = "bumpy";
  uint32_t candidates = 1000000;
  std::vector<uint32_t> sizes = {10000, 50000, 100000};
  uint32_t exact_max = 100000;
  uint32_t threads = 1;
  int repeats = 3;
  calf::encoder::SurfelSamplerOptions base;
  app.add_option("--surface", surface, "bumpy | plane")->capture_default_str();
  app.add_option("--candidates", candidates, "candidate count")->capture_default_str();
  app.add_option("--sizes", sizes, "surfel counts")->capture_default_str();
  app.add_option("--exact-max", exact_max, "largest count the exact permutation runs at")
      ->capture_default_str();
  app.add_option("--threads", threads, "workers (0: all)")->capture_default_str();
  app.add_option("--repeats", repeats, "timed runs (median)")->capture_default_str();
  app.add_option("--round-samples", base.round_samples, "progressive: samples per round")
      ->capture_default_str();
  app.add_option("--growth-period", base.growth_period, "progressive: k (rounds)")
      ->capture_default_str();
  app.add_option("--max-accept", base.max_accept, "progressive: accepted per round at most")
      ->capture_default_str();
  app.add_option("--vicinity", base.vicinity, "progressive: set-aside factor")
      ->capture_default_str();
  app.add_option("--extend-below", base.extend_below, "progressive: extend a poor round")
      ->capture_default_str();
  bool skip_progressive = false;
  app.add_flag("--skip-progressive", skip_progressive, "leave the paper's sampler out");
  CLI11_PARSE(app, argc, argv);
  base.threads = threads;

  const std::vector<Vec3> points =
      surface == "plane" ? plane_grid(candidates) : bumpy_sphere(candidates);
  fmt::print(
      "surface {}: {} candidates; threads {}; progressive: {} samples/round, k = {} rounds, "
      "max accept {}, vicinity {}\n\n",
      surface, points.size(), threads, base.round_samples, base.growth_period, base.max_accept,
      base.vicinity);

  const calf::encoder::SurfelOrderMethod methods[] = {
      calf::encoder::SurfelOrderMethod::kGreedyTree, calf::encoder::SurfelOrderMethod::kProgressive,
      calf::encoder::SurfelOrderMethod::kExactGreedy, calf::encoder::SurfelOrderMethod::kRandom};
  constexpr int kMethods = 4, kExact = 2;
  fmt::print(
      "milliseconds, wall / CPU (median of runs); limit: exact / sampler >= 50 at 10k (CPU)\n");
  fmt::print("{:>8} {:>20} {:>20} {:>20} {:>20} {:>12} {:>12}\n", "surfels", "greedy-tree",
             "progressive", "exact", "random", "exact/tree", "exact/progr");
  std::vector<std::vector<uint32_t>> longest(kMethods);
  for (uint32_t n : sizes) {
    if (n > points.size()) continue;
    double ms[kMethods] = {NAN, NAN, NAN, NAN}, cpu[kMethods] = {NAN, NAN, NAN, NAN};
    for (int m = 0; m < kMethods; ++m) {
      if (methods[m] == calf::encoder::SurfelOrderMethod::kProgressive && skip_progressive)
        continue;
      if (methods[m] == calf::encoder::SurfelOrderMethod::kExactGreedy && n > exact_max) continue;
      calf::encoder::SurfelSamplerOptions o = base;
      o.method = methods[m];
      std::vector<double> runs, cpus;
      const int reps = methods[m] == calf::encoder::SurfelOrderMethod::kExactGreedy ? 1 : repeats;
      for (int r = 0; r < reps; ++r) {
        const auto t0 = std::chrono::steady_clock::now();
        const double c0 = cpu_seconds();
        auto order = calf::encoder::order_surfels(points, n, o);
        cpus.push_back((cpu_seconds() - c0) * 1e3);
        runs.push_back(
            std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() * 1e3);
        if (!order.ok()) {
          fmt::print(stderr, "{}\n", order.status().to_string());
          return 1;
        }
        if (order->order.size() > longest[m].size()) longest[m] = order->order;
      }
      std::sort(runs.begin(), runs.end());
      std::sort(cpus.begin(), cpus.end());
      ms[m] = runs[runs.size() / 2];
      cpu[m] = cpus[cpus.size() / 2];
    }
    auto cell = [](double w, double c) { return fmt::format("{:.1f} / {:.1f}", w, c); };
    fmt::print("{:>8} {:>20} {:>20} {:>20} {:>20} {:>12.1f} {:>12.1f}\n", n, cell(ms[0], cpu[0]),
               cell(ms[1], cpu[1]), cell(ms[2], cpu[2]), cell(ms[3], cpu[3]), cpu[kExact] / cpu[0],
               cpu[kExact] / cpu[1]);
  }
  {
    const size_t common = std::min(longest[0].size(), longest[kExact].size());
    if (common > 0)
      fmt::print(
          "greedy-tree order {} the exact permutation's on its first {} surfels\n",
          std::equal(longest[0].begin(), longest[0].begin() + common, longest[kExact].begin())
              ? "equals"
              : "DIFFERS FROM",
          common);
  }
  std::fflush(stdout);

  fmt::print(
      "\nspacing of prefixes (nearest-neighbour distance within the prefix; limit: "
      "the sampler's r_min/r_max within 10 % of exact's)\n");
  fmt::print("{:>8} {:>12} {:>10} {:>10} {:>10} {:>10} {:>12}\n", "prefix", "method", "r_min",
             "r_median", "r_max", "min/max", "vs exact");
  std::vector<uint32_t> prefixes = {1000, 5000};
  for (uint32_t n : sizes) prefixes.push_back(n);
  std::sort(prefixes.begin(), prefixes.end());
  prefixes.erase(std::unique(prefixes.begin(), prefixes.end()), prefixes.end());
  for (uint32_t p : prefixes) {
    double exact_rho = NAN;
    for (int m : {kExact, 0, 1, 3}) {
      if (longest[m].size() < p) continue;
      auto s = calf::encoder::prefix_spacing(points, longest[m], p, threads);
      if (!s.ok()) {
        fmt::print(stderr, "{}\n", s.status().to_string());
        return 1;
      }
      const double rho = s->r_min / s->r_max;
      if (m == kExact) exact_rho = rho;
      fmt::print("{:>8} {:>12} {:>10.5f} {:>10.5f} {:>10.5f} {:>10.3f} {:>11.1f}%\n", p,
                 calf::encoder::surfel_order_method_name(methods[m]), s->r_min, s->r_median,
                 s->r_max, rho, 100.0 * (rho / exact_rho - 1.0));
    }
  }
  return 0;
}
