// Shared pieces of the surfel orderings (calf/encoder/surfel_sampler.h): float points, the
// seeded generator, and the hashed uniform grid that answers nearest-point queries.
#pragma once

#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include "calf/encoder/surfel_sampler.h"

namespace calf::encoder::surfel_internal {

struct P3 {
  float x, y, z;
};

inline float dist2(const P3& a, const P3& b) {
  const float dx = a.x - b.x, dy = a.y - b.y, dz = a.z - b.z;
  return dx * dx + dy * dy + dz * dz;
}

inline P3 to_float(const Vec3& v) {
  return {static_cast<float>(v.x), static_cast<float>(v.y), static_cast<float>(v.z)};
}

// SplitMix64 (Steele et al. 2014): 64 bits of state, the same stream on every platform.
class Rng {
 public:
  explicit Rng(uint64_t seed) : state_(seed) {}
  uint64_t next() {
    uint64_t z = (state_ += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
  }
  // Uniform in [0, bound), bound >= 1: Lemire's multiply-shift with rejection (unbiased).
  uint32_t below(uint32_t bound) {
    uint64_t m = (next() >> 32) * bound;
    auto low = static_cast<uint32_t>(m);
    if (low < bound) {
      const uint32_t threshold = static_cast<uint32_t>(-bound) % bound;
      while (low < threshold) {
        m = (next() >> 32) * bound;
        low = static_cast<uint32_t>(m);
      }
    }
    return static_cast<uint32_t>(m >> 32);
  }

 private:
  uint64_t state_;
};

// A uniform grid of cubic cells over points inserted one by one, stored sparsely: an
// open-addressing table from cell to the head of that cell's list. Memory is O(points), whatever
// the extent; a nearest query visits rings of cells around the query's cell until no unvisited
// cell can hold a nearer point, so it costs O(1) cells when the cell size is near the spacing of
// the points and the query lies within about a cell of one.
class PointGrid {
 public:
  // Empties the grid and sets its cells: `origin` is a corner of a box holding every point that
  // will be inserted or queried, `cell` > 0 the side. The cell is enlarged so that the box
  // `extent` (its largest side) spans at most 2^20 cells, keeping cell coordinates in 21 bits.
  void reset(const P3& origin, float extent, float cell, size_t expected_points);
  void insert(uint32_t id, const P3& p);
  // The squared distance from q to the nearest inserted point whose id is not `skip`
  // (UINT32_MAX: none skipped); +infinity when there is none. With stop2 >= 0 the search may
  // stop at the first point found within sqrt(stop2): the value is then only an upper bound
  // (<= stop2) and *exact (when given) is set false; otherwise *exact is set true.
  float nearest2(const P3& q, uint32_t skip = UINT32_MAX, float stop2 = -1.0f,
                 bool* exact = nullptr) const;
  float cell() const { return cell_; }
  size_t size() const { return points_.size(); }

 private:
  struct Key {
    int32_t x, y, z;
  };
  Key key_of(const P3& p) const;
  static uint64_t pack(int32_t x, int32_t y, int32_t z) {
    return (static_cast<uint64_t>(static_cast<uint32_t>(x)) << 42) |
           (static_cast<uint64_t>(static_cast<uint32_t>(y)) << 21) | static_cast<uint32_t>(z);
  }
  size_t slot_of(uint64_t key) const;
  uint32_t head(int32_t x, int32_t y, int32_t z) const;
  void grow();

  P3 origin_{0, 0, 0};
  float cell_ = 1;
  double inv_cell_ = 1;
  int32_t max_index_ = 0;  // largest cell coordinate any point can have
  std::vector<uint64_t> keys_;
  std::vector<uint32_t> heads_;
  uint32_t mask_ = 0, used_ = 0;
  std::vector<P3> points_;
  std::vector<uint32_t> ids_, next_;
};

// The box (corner and largest side) of the points.
void bounding_box(std::span<const P3> points, P3* origin, float* extent);

// Nearest-neighbour distance (not squared) of each of `points` among the others, on `threads`.
std::vector<float> nearest_neighbour_distances(std::span<const P3> points, uint32_t threads);

// The ordering algorithms; inputs already validated (n in [1, candidates.size()], positions
// within the coordinate bound, options in range). Each rounds positions to float as it reads
// them.
std::vector<uint32_t> order_progressive(std::span<const Vec3> candidates, uint32_t n,
                                        const SurfelSamplerOptions& options);
std::vector<uint32_t> order_exact_greedy(std::span<const Vec3> candidates, uint32_t n,
                                         const SurfelSamplerOptions& options);
std::vector<uint32_t> order_greedy_tree(std::span<const Vec3> candidates, uint32_t n,
                                        const SurfelSamplerOptions& options);

}  // namespace calf::encoder::surfel_internal
