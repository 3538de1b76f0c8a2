// Surfel orderings (paper 001, Brandt et al., "Progressive Blue Surfels", Sec. 3.2-3.3 and 4.1):
// which of an object's candidate surfels become its surfels, and in which order, so that every
// prefix of the order is a level of detail whose points are spread evenly over the surface (an
// approximate greedy permutation: blue noise in every prefix).
//
// This header is the contract between the orderings (encoder/src/surfel_sampler*.cc, one
// algorithm per file) and their callers (the surfels builder); docs/SURFELS.md ("Sampler") has
// the figures, the commands that measured them, and the reasons for the defaults.
//
// Input. The candidates are the object-space positions of the covered G-buffer pixels of one
// object (paper Sec. 3.1: orthographic views from 8 or 16 directions); only positions matter
// here, the caller keeps normals and colours and permutes them with SurfelOrder::order.
// Positions are rounded to float once on entry (the precision of G-buffer samples and of the
// surfels track) and every distance below is the Euclidean distance between those float points,
// computed in float (squared distances compared; no square root decides anything).
//
// The four methods (SurfelOrderMethod):
//
// - kGreedyTree (default): the greedy permutation below (kExactGreedy's order, element for
//   element, proven so in encoder/src/surfel_sampler_tree.cc and tested against it), computed in
//   about O(N log n) instead of O(n N). The candidates sit in the leaves of a binary tree of
//   boxes (Morton order, 32 a leaf) whose nodes keep the largest distance to the chosen set below
//   them; choosing a surfel updates only the nodes whose box is nearer to it than their largest
//   distance (in effect the new surfel's Voronoi cell, about N / i candidates at step i), and the
//   next surfel is the root's farthest. Single-threaded; `threads` does not change it. O(N)
//   memory (about 36 bytes a candidate while the tree is built, 22 after). The options below
//   marked "Progressive" do not apply; `seed` picks the first surfel.
//
// - kProgressive, the paper's sampler (Sec. 3.2), kept to compare with the paper (its prefixes'
//   r_min / r_max is 4-20 % below the greedy permutation's, docs/SURFELS.md). The first surfel is
//   drawn with `seed` from the input set (all candidates; the same draw as kExactGreedy's first).
//   Then rounds:
//   1. Draw `round_samples` candidates uniformly without replacement from the input set (fewer
//      when fewer remain) and find each one's distance to the chosen set with a hashed uniform
//      grid over the chosen surfels (cell size following the current spacing, rebuilt whenever
//      a round's best distance falls below half a cell).
//   2. Extension (calf's addition, `extend_below`; 0 turns it off): while the farthest sample is
//      nearer than extend_below x the previous round's first accepted distance, draw another
//      round_samples into the same round, at most kSurfelMaxExtensions times. Rounds whose
//      sample happened to miss the uncovered parts pay for more draws; the others cost nothing.
//   3. Accept the `accept` samples farthest from the chosen set one by one, each time updating
//      the other samples' distances by the surfel just accepted (so two surfels accepted in the
//      same round are not placed side by side: within a round this is the exact greedy step
//      over the sample; ties go to the smaller candidate index).
//   4. The samples not accepted go back to the input set, except those nearer to the chosen set
//      than `vicinity` times the distance of the last surfel accepted this round: the paper's
//      "samples that are at close vicinity to the chosen samples can also be removed from the
//      input set". Such a sample could only be chosen once the spacing has shrunk below
//      `vicinity` times its current value; setting it aside keeps later rounds from wasting
//      draws on covered parts. Set-aside samples are not lost: when the input set holds fewer
//      than round_samples, they join it again (appended in the order set aside), so rounds stay
//      full and any n <= N is reached.
//   Growth heuristic (paper: "after each k iterations, the number of candidates chosen from the
//   random sample set is increased by one (e.g., k = 500)"): an iteration is read as one round
//   (draw a sample, accept from it), as in the authors' MinSG code, which counts rounds;
//   `accept` starts at 1 and grows by one after every `growth_period` rounds, up to
//   `max_accept`. Reading "iterations" as accepted surfels instead would make `accept` reach the
//   whole sample (200) at 100k surfels, i.e. a random order. Rounds to reach n surfels: about
//   sqrt(2 n k) (n = 10k: ~3,200 rounds, accept 6; 100k: ~10,000 rounds, accept 20), so the
//   cost is O(rounds x round_samples) grid queries plus an O(N) set-up, nearly independent of N.
//   Speed without changing the result: the input set stores each candidate's position (a draw
//   is one cache miss), the slots of a round's draws are chosen and prefetched before any is
//   read, and a query stops at the first chosen surfel within half the previous round's best
//   distance, keeping that upper bound; a bound is replaced by the exact distance only when it
//   comes out on top (lazy evaluation), so the surfels accepted are those exact queries would
//   give. (A bound also decides the vicinity rule: a bound below the threshold proves the
//   sample close; a bound above it sends the sample back to the input set.)
//   Single-threaded (each round depends on the last); `threads` does not change it.
//
// - kRandom: a uniformly random permutation of the candidates (Fisher-Yates with `seed`), cut at
//   n. The baseline the paper's Fig. 3 compares against.
//
// Determinism. The same candidates, n and options give the same order on every machine and for
// every thread count: random numbers come from a fixed 64-bit generator (SplitMix64) seeded by
// `seed`, bounded draws use rejection (no std:: distribution, whose output is
// implementation-defined), and every tie is broken by the smaller candidate index.
//
// Spacing of a prefix (used for r_m and by tests and benchmarks, prefix_spacing below). For a
// prefix P of the order with |P| >= 2, each point's nearest-neighbour distance is
// nn(i) = min over j in P, j != i of |x_i - x_j|. r_min, r_max and r_median are the minimum,
// maximum and lower median (element floor((|P| - 1) / 2) of the sorted values) of nn over P.
// r_min is the smallest pairwise distance of P; r_min / r_max near 1 means evenly spread points.
//
// Prefix from a radius (paper Sec. 4.1). r_m is r_median of the first p_m surfels (p_m =
// min(options.p_m, n)); a surfel disc of radius r covers about 4 surfels of half that radius on
// a surface, which gives the prefix p(r) = p_m (r_m / r)^2 (surfels::prefix_for_radius,
// calf/format/surfels_layout.h).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "calf/format/geometry.h"
#include "calf/format/status.h"

namespace calf::encoder {

enum class SurfelOrderMethod : uint8_t {
  kProgressive = 0,  // the paper's randomized rounds
  kExactGreedy = 1,  // the greedy permutation, plain O(n N) (reference)
  kRandom = 2,       // a uniformly random permutation (baseline)
  kGreedyTree = 3,   // the greedy permutation through a tree of boxes (default)
};

// "progressive", "exact", "random", "greedy-tree".
const char* surfel_order_method_name(SurfelOrderMethod method);

// Limits of the options (checked by order_surfels: CALF-E243).
inline constexpr uint32_t kSurfelMaxRoundSamples = 65536;
inline constexpr uint32_t kSurfelMaxThreads = 256;
inline constexpr uint32_t kSurfelMaxExtensions = 4;

struct SurfelSamplerOptions {
  SurfelOrderMethod method = SurfelOrderMethod::kGreedyTree;
  // Seeds the first surfel (all methods) and the random draws (progressive, random).
  uint64_t seed = 0x243f6a8885a308d3ull;
  // Progressive: samples drawn per round, 1 .. kSurfelMaxRoundSamples (paper: ~200 "yield a
  // reasonably good quality result").
  uint32_t round_samples = 200;
  // Progressive: rounds after which the number accepted per round grows by one (paper: k = 500),
  // >= 1.
  uint32_t growth_period = 500;
  // Progressive: the most samples accepted per round, 1 .. round_samples (the growth stops
  // there; accepting the whole sample would be random order). 0 means round_samples / 4.
  uint32_t max_accept = 0;
  // Progressive: samples of a round nearer to the chosen set than vicinity x (the distance of the
  // round's last accepted surfel) are set aside (see above), in [0, 1); 0 sets none aside.
  double vicinity = 0.5;
  // Progressive: a round whose farthest sample is nearer to the chosen set than extend_below x
  // the previous round's first accepted distance draws another round_samples samples into the
  // same round, up to kSurfelMaxExtensions times, in [0, 1); 0 never extends (the paper's plain
  // rounds). This cuts the low tail of accepted distances (r_min) at the cost of more draws in
  // the rounds that need them (docs/SURFELS.md has the measured trade).
  double extend_below = 0.9;
  // The prefix length whose median nearest-neighbour distance is r_m (paper: p_m = 1000), >= 1.
  uint32_t p_m = 1000;
  // Worker threads for kExactGreedy and for r_m (0: hardware concurrency), at most
  // kSurfelMaxThreads. The order never depends on it.
  uint32_t threads = 0;
};

struct SurfelOrder {
  // Indices into the candidates, each at most once, in the accepted sequence; every prefix is a
  // level of detail (prefixes are nested by construction). order.size() == n.
  std::vector<uint32_t> order;
  // r_median (see "Spacing of a prefix") of the first p_m surfels of `order`, in the candidates'
  // units; 0 when p_m == 1 (a single surfel has no neighbour) or when the prefix holds
  // coincident points.
  float r_m = 0;
  // The prefix length r_m was measured on: min(options.p_m, n).
  uint32_t p_m = 0;
};

// Orders `n` of `candidates` with options.method. Errors (one line each, naming the value at
// fault): no candidate (CALF-E240); n = 0, n above the candidate count, or more than 2^32 - 1
// candidates (E241); a candidate coordinate not finite or beyond the coordinate bound
// (calf/format/coordinates.h; E242, naming the candidate and coordinate); an option out of range
// (E243, naming the option and its range).
Expected<SurfelOrder> order_surfels(std::span<const Vec3> candidates, uint32_t n,
                                    const SurfelSamplerOptions& options = {});

// The spacing of a prefix: see "Spacing of a prefix" above. For prefix == 1 all three are 0.
struct PrefixSpacing {
  double r_min = 0;
  double r_median = 0;
  double r_max = 0;
};

// The spacing of the first `prefix` entries of `order` (indices into `candidates`), with a hashed
// grid (O(prefix) expected for points on a surface), on `threads` workers (0: hardware
// concurrency; the result does not depend on it). Errors: prefix 0 or above order.size(), an
// index of `order` out of range (E241); a candidate not finite (E242); threads above the limit
// (E243). Duplicate indices in the order count as coincident points (distance 0).
Expected<PrefixSpacing> prefix_spacing(std::span<const Vec3> candidates,
                                       std::span<const uint32_t> order, uint32_t prefix,
                                       uint32_t threads = 0);

}  // namespace calf::encoder
