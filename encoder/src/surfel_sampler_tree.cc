// The greedy permutation through a tree of boxes (calf/encoder/surfel_sampler.h, kGreedyTree):
// the same order as kExactGreedy (surfel_sampler_exact.cc, the plain reference it is tested
// against), computed in about O(N log n) instead of O(n N).
//
// Why it is fast. After surfel p is chosen, a candidate's distance to the chosen set changes only
// if it is nearer to p than to every surfel chosen before, i.e. only inside p's Voronoi cell,
// about N / i candidates at step i. The candidates sit in the leaves of a binary tree of boxes,
// each node keeping the largest distance below it; a node whose box is at least that far from p
// holds no candidate whose distance can drop, so the update skips it whole. The farthest
// candidate is then the root's. Summed over the steps, N (1 + 1/2 + ... + 1/n) ~ N ln n updates.
//
// Why it is exact. Every distance is the float expression of the reference, (dx dx + dy dy) +
// dz dz with dx = x_i - p_x, and the lower bound for a box is the same expression on the box's
// gaps (x_lo - p_x or p_x - x_hi, else 0). Rounding is monotone, so the bound is <= the float
// distance of every point in the box: a skipped candidate has distance >= bound >= node maximum
// >= its current value, and the reference's minimum would have kept that value. The values are
// therefore the reference's, bit for bit, and the choice (largest, then smallest candidate index)
// is the same. The tree's shape only changes the speed, never the order. (This needs both files
// to evaluate the expression alike: calf builds for baseline x86-64, where nothing is contracted
// into a fused multiply-add; tests/encoder/surfel_sampler_test.cc compares the two orders.)
//
// The tree. Candidates are sorted along a Morton curve (24-bit codes, a stable radix sort) so that
// runs of consecutive candidates are small boxes; the leaves are runs of kLeaf candidates, the
// inner nodes a complete binary tree over them (heap order, leaves padded to a power of two).
#include <algorithm>
#include <array>
#include <bit>
#include <limits>

#include "surfel_sampler_internal.h"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace calf::encoder::surfel_internal {
namespace {

// Candidates per leaf: small enough that a leaf's box is tight, large enough that the tree's
// overhead (a box test and a maximum per node) stays below the distance updates.
constexpr uint32_t kLeaf = 32;  // at most 32: a leaf's ties are a 32-bit mask
constexpr float kInf = std::numeric_limits<float>::infinity();

// Spreads the low 10 bits of v to every third bit.
uint32_t spread3(uint32_t v) {
  v &= 0x3ffu;
  v = (v | (v << 16)) & 0x030000ffu;
  v = (v | (v << 8)) & 0x0300f00fu;
  v = (v | (v << 4)) & 0x030c30c3u;
  v = (v | (v << 2)) & 0x09249249u;
  return v;
}

class GreedyTree {
 public:
  explicit GreedyTree(std::span<const Vec3> candidates) {
    const auto count = static_cast<uint32_t>(candidates.size());
    std::vector<Item> items(count), sorted(count);
    for (uint32_t i = 0; i < count; ++i) items[i] = {to_float(candidates[i]), i};
    P3 lo = items[0].p, hi = lo;
    for (const Item& it : items) {
      lo = {std::min(lo.x, it.p.x), std::min(lo.y, it.p.y), std::min(lo.z, it.p.z)};
      hi = {std::max(hi.x, it.p.x), std::max(hi.y, it.p.y), std::max(hi.z, it.p.z)};
    }
    // Morton codes on a 256^3 lattice over the box (about two candidates a cell on a surface of a
    // million); any order would give the same result, this one makes the leaves' boxes small.
    const float extent = std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
    const double scale = extent > 0.0f ? 256.0 / static_cast<double>(extent) : 0.0;
    auto cell = [&](float v, float o) {
      const double c = (static_cast<double>(v) - o) * scale;
      return c <= 0.0 ? 0u : c >= 255.0 ? 255u : static_cast<uint32_t>(c);
    };
    auto code = [&](const P3& q) {
      return spread3(cell(q.x, lo.x)) | (spread3(cell(q.y, lo.y)) << 1) |
             (spread3(cell(q.z, lo.z)) << 2);
    };
    // A stable LSD radix sort of the items by code, two passes of 12 bits; the items carry their
    // positions so that nothing is gathered at random afterwards.
    std::vector<uint32_t> codes(count);
    std::vector<uint32_t> low(4097, 0), high(4097, 0);
    for (uint32_t i = 0; i < count; ++i) {
      codes[i] = code(items[i].p);
      ++low[(codes[i] & 4095u) + 1];
      ++high[(codes[i] >> 12) + 1];
    }
    for (size_t b = 1; b < low.size(); ++b) {
      low[b] += low[b - 1];
      high[b] += high[b - 1];
    }
    for (uint32_t i = 0; i < count; ++i) sorted[low[codes[i] & 4095u]++] = items[i];
    for (uint32_t i = 0; i < count; ++i) items[high[code(sorted[i].p) >> 12]++] = sorted[i];
    sorted = {};
    codes = {};

    // The leaves: kLeaf candidates each, stored as blocks (kLeaf x, y, z, distance); the last
    // block is padded with distance -infinity (never the farthest) and NaN positions (a NaN
    // distance never lowers a minimum), so every leaf loop runs kLeaf times.
    const uint32_t leaves = (count + kLeaf - 1) / kLeaf;
    blocks_.resize(leaves);
    ids_.assign(size_t{leaves} * kLeaf, UINT32_MAX);
    Block& last = blocks_.back();
    std::fill(std::begin(last.x), std::end(last.x), std::numeric_limits<float>::quiet_NaN());
    std::fill(std::begin(last.y), std::end(last.y), std::numeric_limits<float>::quiet_NaN());
    std::fill(std::begin(last.z), std::end(last.z), std::numeric_limits<float>::quiet_NaN());
    std::fill(std::begin(last.d), std::end(last.d), -kInf);
    for (uint32_t k = 0; k < count; ++k) {
      Block& b = blocks_[k / kLeaf];
      const uint32_t j = k % kLeaf;
      b.x[j] = items[k].p.x;
      b.y[j] = items[k].p.y;
      b.z[j] = items[k].p.z;
      b.d[j] = kInf;
      ids_[k] = items[k].id;
    }
    items = {};

    leaves_ = 1;
    while (leaves_ < leaves) leaves_ *= 2;
    nodes_.assign(2 * size_t{leaves_}, Node{});
    for (uint32_t leaf = 0; leaf < leaves; ++leaf) {
      Node& node = nodes_[leaves_ + leaf];
      const Block& b = blocks_[leaf];
      const uint32_t size = std::min(kLeaf, count - leaf * kLeaf);
      for (uint32_t j = 0; j < size; ++j) {
        node.lo = {std::min(node.lo.x, b.x[j]), std::min(node.lo.y, b.y[j]),
                   std::min(node.lo.z, b.z[j])};
        node.hi = {std::max(node.hi.x, b.x[j]), std::max(node.hi.y, b.y[j]),
                   std::max(node.hi.z, b.z[j])};
      }
      this->leaf(leaves_ + leaf, false);
    }
    for (size_t node = leaves_ - 1; node >= 1; --node) {
      Node &n = nodes_[node], &a = nodes_[2 * node], &b = nodes_[2 * node + 1];
      n.lo = {std::min(a.lo.x, b.lo.x), std::min(a.lo.y, b.lo.y), std::min(a.lo.z, b.lo.z)};
      n.hi = {std::max(a.hi.x, b.hi.x), std::max(a.hi.y, b.hi.y), std::max(a.hi.z, b.hi.z)};
      combine(node);
    }
  }

  // The place of candidate `id` in the tree's order (a linear search: once per order).
  uint32_t position_of(uint32_t id) const {
    return static_cast<uint32_t>(std::find(ids_.begin(), ids_.end(), id) - ids_.begin());
  }
  uint32_t id_at(uint32_t k) const { return ids_[k]; }
  // The place of the candidate farthest from the chosen set (ties: the smallest id).
  uint32_t farthest() const { return nodes_[1].at; }

  // Chooses the candidate at place k: it leaves the race (distance -1, as in the reference) and
  // every other candidate's distance becomes its minimum with the distance to it.
  void choose(uint32_t k) {
    Block& b = blocks_[k / kLeaf];
    b.d[k % kLeaf] = -1.0f;
    px_ = b.x[k % kLeaf];
    py_ = b.y[k % kLeaf];
    pz_ = b.z[k % kLeaf];
    // The chosen candidate's leaf and its ancestors even when the update below skips them (a
    // leaf whose other candidates are all at distance 0 from the chosen set).
    size_t node = leaves_ + k / kLeaf;
    leaf(node, false);
    for (node /= 2; node >= 1; node /= 2) combine(node);
    if (visit(nodes_[1])) update(1);
  }

 private:
  struct Item {
    P3 p;
    uint32_t id;
  };
  // One leaf's candidates, by field: positions and squared distance to the chosen set (-1 once
  // chosen).
  struct alignas(64) Block {
    float x[kLeaf], y[kLeaf], z[kLeaf], d[kLeaf];
  };
  // 32 bytes: the two children of a node share a cache line.
  struct alignas(32) Node {
    P3 lo{kInf, kInf, kInf}, hi{-kInf, -kInf, -kInf};  // the box of the candidates below
    float max = -kInf;                                 // their largest distance
    uint32_t at = 0;                                   // whose (its place; ties: the smallest id)
  };

  // The larger child's maximum (ties: the smaller candidate id).
  void combine(size_t node) {
    const Node &a = nodes_[2 * node], &b = nodes_[2 * node + 1];
    const bool take_b = b.max > a.max || (b.max == a.max && ids_[b.at] < ids_[a.at]);
    nodes_[node].max = take_b ? b.max : a.max;
    nodes_[node].at = take_b ? b.at : a.at;
  }

  // The leaf's largest distance and whose it is (ties: the smallest id); with `lower`, first
  // every distance becomes its minimum with the distance to the chosen point.
  void leaf(size_t node, bool lower) {
    Block& b = blocks_[node - leaves_];
    uint32_t mask = 0;  // bit j: candidate j holds the largest distance
    float best;
#if defined(__SSE2__)
    // Four lanes at a time; the same IEEE operations in the same order as the scalar branch
    // and the reference (minps(e, d) is e < d ? e : d).
    const __m128 px = _mm_set1_ps(px_), py = _mm_set1_ps(py_), pz = _mm_set1_ps(pz_);
    __m128 top = _mm_set1_ps(-kInf);
    for (uint32_t j = 0; j < kLeaf; j += 4) {
      __m128 d = _mm_load_ps(b.d + j);
      if (lower) {
        const __m128 dx = _mm_sub_ps(_mm_load_ps(b.x + j), px);
        const __m128 dy = _mm_sub_ps(_mm_load_ps(b.y + j), py);
        const __m128 dz = _mm_sub_ps(_mm_load_ps(b.z + j), pz);
        const __m128 e =
            _mm_add_ps(_mm_add_ps(_mm_mul_ps(dx, dx), _mm_mul_ps(dy, dy)), _mm_mul_ps(dz, dz));
        d = _mm_min_ps(e, d);
        _mm_store_ps(b.d + j, d);
      }
      top = _mm_max_ps(d, top);
    }
    top = _mm_max_ps(top, _mm_shuffle_ps(top, top, _MM_SHUFFLE(2, 3, 0, 1)));
    top = _mm_max_ps(top, _mm_shuffle_ps(top, top, _MM_SHUFFLE(1, 0, 3, 2)));
    best = _mm_cvtss_f32(top);
    for (uint32_t j = 0; j < kLeaf; j += 4)
      mask |= static_cast<uint32_t>(_mm_movemask_ps(_mm_cmpeq_ps(_mm_load_ps(b.d + j), top))) << j;
#else
    best = -kInf;
    for (uint32_t j = 0; j < kLeaf; ++j) {
      if (lower) {
        const float dx = b.x[j] - px_, dy = b.y[j] - py_, dz = b.z[j] - pz_;
        const float e = dx * dx + dy * dy + dz * dz;
        b.d[j] = e < b.d[j] ? e : b.d[j];
      }
      best = b.d[j] > best ? b.d[j] : best;
    }
    for (uint32_t j = 0; j < kLeaf; ++j) mask |= (b.d[j] == best ? 1u : 0u) << j;
#endif
    const size_t first = (node - leaves_) * kLeaf;
    uint32_t at = static_cast<uint32_t>(first + std::countr_zero(mask));
    for (mask &= mask - 1; mask != 0; mask &= mask - 1) {
      const size_t k = first + std::countr_zero(mask);
      if (ids_[k] < ids_[at]) at = static_cast<uint32_t>(k);
    }
    nodes_[node].max = best;
    nodes_[node].at = at;
  }

  // Whether the node may hold a candidate nearer to the chosen point than its distance: the
  // squared distance from the point to the node's box, in the reference's arithmetic (see the
  // top of the file), is a lower bound of every candidate's distance in it.
  bool visit(const Node& n) const {
    const float gx = std::max(0.0f, std::max(n.lo.x - px_, px_ - n.hi.x));
    const float gy = std::max(0.0f, std::max(n.lo.y - py_, py_ - n.hi.y));
    const float gz = std::max(0.0f, std::max(n.lo.z - pz_, pz_ - n.hi.z));
    return n.max > gx * gx + gy * gy + gz * gz;
  }

  void update(size_t node) {
    if (node >= leaves_) {
      leaf(node, true);
      return;
    }
    if (visit(nodes_[2 * node])) update(2 * node);
    if (visit(nodes_[2 * node + 1])) update(2 * node + 1);
    combine(node);
  }

  // The candidates in Morton order, kLeaf a block (a leaf), and their ids in that order.
  std::vector<Block> blocks_;
  std::vector<uint32_t> ids_;
  // The tree in heap order: node 1 the root, node i's children 2i and 2i + 1, leaves from
  // leaves_ (leaf j holds candidates j kLeaf ..; leaves past the last candidate are empty).
  uint32_t leaves_ = 1;
  std::vector<Node> nodes_;
  float px_ = 0, py_ = 0, pz_ = 0;  // the surfel being chosen
};

}  // namespace

std::vector<uint32_t> order_greedy_tree(std::span<const Vec3> candidates, uint32_t n,
                                        const SurfelSamplerOptions& options) {
  GreedyTree tree(candidates);
  std::vector<uint32_t> order;
  order.reserve(n);
  // The first surfel is the reference's: rng.below(count) on the candidates' own indices.
  Rng rng(options.seed);
  uint32_t next = tree.position_of(rng.below(static_cast<uint32_t>(candidates.size())));
  while (true) {
    order.push_back(tree.id_at(next));
    if (order.size() == n) break;
    tree.choose(next);
    next = tree.farthest();
  }
  return order;
}

}  // namespace calf::encoder::surfel_internal
