// A pixel's interval list in blocks (the storage behind Alg. 1's per-pixel lists).
//
// Why blocks: on a field of grass a pixel's list holds ~1,000 intervals (every blade the pixel's
// ray sweeps over while the eye crosses a 3 m segment), and a plain vector moved half of them on
// every change and was walked whole to bound its depth: the builder spent most of its time in
// memmove and that walk and never finished the `blades` scene. Here a change rewrites only the
// blocks it touches (kListBlock intervals each, usually one) and refreshes their summaries (last
// end, largest depth, gap), finding the first interval that ends after a time is a binary search
// over the blocks then within one, and the depth bound reads one summary per block. The order of
// intervals, and so every result, is the same as a flat sorted vector's.
#include <algorithm>
#include <limits>

#include "visible_set_internal.h"

namespace calf::encoder::visibility {

uint32_t IntervalPool::allocate() {
  if (!free_.empty()) {
    const uint32_t b = free_.back();
    free_.pop_back();
    return b;
  }
  if (used_ * size_t{kListBlock} >= storage_.size())
    storage_.resize(std::max<size_t>(size_t{64} * kListBlock, 2 * storage_.size()));
  return used_++;
}

void IntervalPool::release(uint32_t block) {
  free_.push_back(block);
}

void IntervalPool::reset() {
  free_.clear();
  used_ = 0;
}

void IntervalList::clear() {
  blocks_.clear();
  size_ = 0;
}

IntervalList::Pos IntervalList::first_ending_after(const IntervalPool& pool, double s) const {
  // Blocks are sorted and disjoint: the first block whose last interval ends after s holds the
  // first interval that does.
  const auto it = std::upper_bound(blocks_.begin(), blocks_.end(), s,
                                   [](double v, const Block& b) { return v < b.end; });
  if (it == blocks_.end()) return end();
  const Interval* e = pool.block(it->id);
  const Interval* first =
      std::upper_bound(e, e + it->count, s, [](double v, const Interval& i) { return v < i.s1; });
  return {static_cast<uint32_t>(it - blocks_.begin()), static_cast<uint32_t>(first - e)};
}

namespace {

// Fills a block's summary from its intervals.
template <typename B>
void summarise(const Interval* e, uint32_t count, std::span<const SphereDepth> spheres, B* b) {
  b->count = static_cast<uint16_t>(count);
  b->end = e[count - 1].s1;
  b->far = 0;
  b->gap = false;
  for (uint32_t i = 0; i < count; ++i) {
    b->far = std::max({b->far, depth_at(e[i], spheres, e[i].s0), depth_at(e[i], spheres, e[i].s1)});
    if (i > 0 && e[i].s0 != e[i - 1].s1) b->gap = true;
  }
}

}  // namespace

void IntervalList::replace(IntervalPool* pool, Pos first, Pos last, std::span<const Interval> with,
                           std::span<const SphereDepth> spheres, std::vector<Interval>* tmp) {
  const uint32_t nb = static_cast<uint32_t>(blocks_.size());
  // The blocks [bf, bl] are rewritten: their intervals before `first`, then `with`, then their
  // intervals from `last` on. An end position stands for "after the last block's intervals".
  uint32_t bf = first.block, fi = first.index, bl = last.block, li = last.index;
  if (nb == 0) {
    bf = bl = 0, fi = li = 0;
  } else {
    if (bf == nb) bf = nb - 1, fi = blocks_[nb - 1].count;
    if (bl == nb) bl = nb - 1, li = blocks_[nb - 1].count;
  }
  if (nb > 0 && bf == bl) {
    const uint32_t count = blocks_[bf].count;
    const uint32_t m = count - (li - fi) + static_cast<uint32_t>(with.size());
    if (m >= 1 && m <= kListBlock) {
      // The usual change: one block, rewritten in place (its tail shifted, `with` copied in).
      Interval* e = pool->block(blocks_[bf].id);
      const uint32_t at = fi + static_cast<uint32_t>(with.size());
      if (at > li) {
        std::copy_backward(e + li, e + count, e + at + (count - li));
      } else if (at < li) {
        std::copy(e + li, e + count, e + at);
      }
      std::copy(with.begin(), with.end(), e + fi);
      size_ = size_ - count + m;
      summarise(e, m, spheres, &blocks_[bf]);
      return;
    }
  }
  tmp->clear();
  if (nb > 0) {
    const Interval* f = pool->block(blocks_[bf].id);
    tmp->insert(tmp->end(), f, f + fi);
  }
  tmp->insert(tmp->end(), with.begin(), with.end());
  if (nb > 0) {
    const Interval* l = pool->block(blocks_[bl].id);
    tmp->insert(tmp->end(), l + li, l + blocks_[bl].count);
  }
  const uint32_t old_blocks = nb == 0 ? 0 : bl - bf + 1;
  size_t old_size = 0;
  for (uint32_t b = bf; b < bf + old_blocks; ++b) old_size += blocks_[b].count;
  const uint32_t m = static_cast<uint32_t>(tmp->size());
  size_ = size_ - old_size + m;
  // Keep the block ids already there, release or take the difference; the new blocks share the
  // intervals evenly (a full block that gains one becomes two half-full ones, as in a B-tree).
  const uint32_t new_blocks = (m + kListBlock - 1) / kListBlock;
  std::vector<Block> blocks(new_blocks);
  for (uint32_t k = 0; k < new_blocks; ++k)
    blocks[k].id = k < old_blocks ? blocks_[bf + k].id : pool->allocate();
  for (uint32_t k = new_blocks; k < old_blocks; ++k) pool->release(blocks_[bf + k].id);
  uint32_t at = 0;
  for (uint32_t k = 0; k < new_blocks; ++k) {
    const uint32_t c = (m - at) / (new_blocks - k);
    Interval* e = pool->block(blocks[k].id);
    std::copy_n(tmp->begin() + at, c, e);
    summarise(e, c, spheres, &blocks[k]);
    at += c;
  }
  blocks_.erase(blocks_.begin() + bf, blocks_.begin() + bf + old_blocks);
  blocks_.insert(blocks_.begin() + bf, blocks.begin(), blocks.end());
}

double IntervalList::far_bound(const IntervalPool& pool, double* gap) const {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  if (blocks_.empty()) {
    *gap = 0.5;
    return kInf;
  }
  const double first = pool.block(blocks_.front().id)[0].s0;
  if (first > 0) {
    *gap = 0.5 * first;
    return kInf;
  }
  if (blocks_.back().end < 1) {
    *gap = 0.5 * (blocks_.back().end + 1);
    return kInf;
  }
  double far = 0;
  for (size_t b = 0; b < blocks_.size(); ++b) {
    const Interval* e = pool.block(blocks_[b].id);
    if (b > 0 && e[0].s0 != blocks_[b - 1].end) {
      *gap = 0.5 * (blocks_[b - 1].end + e[0].s0);
      return kInf;
    }
    if (blocks_[b].gap) {
      for (uint32_t i = 1; i < blocks_[b].count; ++i)
        if (e[i].s0 != e[i - 1].s1) {
          *gap = 0.5 * (e[i - 1].s1 + e[i].s0);
          break;
        }
      return kInf;
    }
    far = std::max(far, blocks_[b].far);
  }
  return far;
}

}  // namespace calf::encoder::visibility
