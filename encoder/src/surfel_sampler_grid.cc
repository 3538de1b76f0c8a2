// The hashed uniform grid of the surfel orderings (surfel_sampler_internal.h): nearest-point
// queries over points inserted one at a time, O(points) memory whatever the object's extent.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>

#include "surfel_sampler_internal.h"

namespace calf::encoder::surfel_internal {
namespace {

constexpr uint64_t kEmpty = ~uint64_t{0};
constexpr int32_t kMaxCells = 1 << 20;

}  // namespace

void bounding_box(std::span<const P3> points, P3* origin, float* extent) {
  P3 lo{std::numeric_limits<float>::max(), std::numeric_limits<float>::max(),
        std::numeric_limits<float>::max()};
  P3 hi{-lo.x, -lo.y, -lo.z};
  for (const P3& p : points) {
    lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
    hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
  }
  if (points.empty()) lo = hi = {0, 0, 0};
  *origin = lo;
  *extent = std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
}

void PointGrid::reset(const P3& origin, float extent, float cell, size_t expected_points) {
  origin_ = origin;
  // A cell never smaller than extent / 2^20 (coordinates fit 21 bits) nor zero (coincident
  // points); the small margin keeps a point on the box's far face inside the last cell.
  const float floor_cell = extent * 1.0001f / static_cast<float>(kMaxCells - 1);
  cell_ = std::max({cell, floor_cell, std::numeric_limits<float>::min() * 1e6f});
  if (!(cell_ < std::numeric_limits<float>::infinity())) cell_ = std::numeric_limits<float>::max();
  inv_cell_ = 1.0 / static_cast<double>(cell_);
  max_index_ = std::min<int32_t>(
      kMaxCells - 1, static_cast<int32_t>(std::floor(static_cast<double>(extent) / cell_)) + 1);
  points_.clear();
  ids_.clear();
  next_.clear();
  points_.reserve(expected_points);
  ids_.reserve(expected_points);
  next_.reserve(expected_points);
  uint32_t capacity = 64;
  while (capacity < 2 * expected_points && capacity < (1u << 30)) capacity *= 2;
  keys_.assign(capacity, kEmpty);
  heads_.assign(capacity, 0);
  mask_ = capacity - 1;
  used_ = 0;
}

PointGrid::Key PointGrid::key_of(const P3& p) const {
  // (p - origin) / cell, truncated (the operand is >= 0 for points inside the box; anything
  // below 0 or past the last cell is clamped), the same arithmetic for points and queries so
  // both agree on a cell.
  // In double: exact enough that a point is never more than ~1e-9 cell outside its cell, which
  // the pruning margins of nearest2 rely on. Truncation, not std::floor (a libm call on baseline
  // x86-64).
  auto axis = [&](float v, float o) {
    const double c = (static_cast<double>(v) - o) * inv_cell_;
    if (!(c > 0.0)) return int32_t{0};
    if (c >= static_cast<double>(max_index_)) return max_index_;
    return static_cast<int32_t>(c);
  };
  return {axis(p.x, origin_.x), axis(p.y, origin_.y), axis(p.z, origin_.z)};
}

size_t PointGrid::slot_of(uint64_t key) const {
  size_t slot = static_cast<size_t>((key * 0x9e3779b97f4a7c15ull) >> 34) & mask_;
  while (keys_[slot] != kEmpty && keys_[slot] != key) slot = (slot + 1) & mask_;
  return slot;
}

uint32_t PointGrid::head(int32_t x, int32_t y, int32_t z) const {
  const uint64_t key = pack(x, y, z);
  const size_t slot = slot_of(key);
  return keys_[slot] == key ? heads_[slot] : UINT32_MAX;
}

void PointGrid::grow() {
  std::vector<uint64_t> keys = std::move(keys_);
  std::vector<uint32_t> heads = std::move(heads_);
  keys_.assign(keys.size() * 2, kEmpty);
  heads_.assign(keys.size() * 2, 0);
  mask_ = static_cast<uint32_t>(keys_.size() - 1);
  for (size_t i = 0; i < keys.size(); ++i) {
    if (keys[i] == kEmpty) continue;
    const size_t slot = slot_of(keys[i]);
    keys_[slot] = keys[i];
    heads_[slot] = heads[i];
  }
}

void PointGrid::insert(uint32_t id, const P3& p) {
  if (2 * (used_ + 1) > keys_.size()) grow();
  const Key k = key_of(p);
  const uint64_t key = pack(k.x, k.y, k.z);
  const size_t slot = slot_of(key);
  const auto index = static_cast<uint32_t>(points_.size());
  points_.push_back(p);
  ids_.push_back(id);
  if (keys_[slot] == key) {
    next_.push_back(heads_[slot]);
  } else {
    keys_[slot] = key;
    next_.push_back(UINT32_MAX);
    ++used_;
  }
  heads_[slot] = index;
}

float PointGrid::nearest2(const P3& q, uint32_t skip, float stop2, bool* exact) const {
  float best = std::numeric_limits<float>::infinity();
  if (exact != nullptr) *exact = true;
  if (points_.empty()) return best;
  const Key c = key_of(q);
  // q relative to the corner of its own cell, in cells' units times cell: a cell dx cells away
  // along x is at least (dx - 1) cell + (cell - qx) (dx > 0) or (-dx - 1) cell + qx (dx < 0)
  // from q along that axis.
  const double cell = cell_;
  const double qx = (static_cast<double>(q.x) - origin_.x) - c.x * cell;
  const double qy = (static_cast<double>(q.y) - origin_.y) - c.y * cell;
  const double qz = (static_cast<double>(q.z) - origin_.z) - c.z * cell;
  auto gap = [&](int32_t d, double local) {
    if (d == 0) return 0.0;
    const double g = d > 0 ? (d - 1) * cell + (cell - local) : (-d - 1) * cell + local;
    return std::max(0.0, g);
  };
  // Visits one cell; true when the search may stop early (a point within sqrt(stop2) found).
  auto visit = [&](int32_t dx, int32_t dy, int32_t dz) {
    const int32_t x = c.x + dx, y = c.y + dy, z = c.z + dz;
    if (x < 0 || y < 0 || z < 0 || x > max_index_ || y > max_index_ || z > max_index_) return false;
    // Skip a cell that cannot hold a nearer point (cheaper than its hash lookup). The 0.9999
    // leaves room for rounding of the cell coordinates.
    const double gx = gap(dx, qx), gy = gap(dy, qy), gz = gap(dz, qz);
    if ((gx * gx + gy * gy + gz * gz) * 0.9999 > best) return false;
    for (uint32_t i = head(x, y, z); i != UINT32_MAX; i = next_[i]) {
      if (ids_[i] == skip) continue;
      best = std::min(best, dist2(q, points_[i]));
    }
    return best <= stop2;
  };
  // The ring R holds the cells whose largest coordinate difference from q's cell is R. A point in
  // ring R + 1 or beyond is at least R cells away from q along some axis; the factor below leaves
  // room for rounding of the cell coordinates.
  const int32_t last_ring =
      std::max({c.x, c.y, c.z, max_index_ - c.x, max_index_ - c.y, max_index_ - c.z});
  for (int32_t r = 0; r <= last_ring; ++r) {
    for (int32_t dz = -r; dz <= r; ++dz) {
      for (int32_t dy = -r; dy <= r; ++dy) {
        bool stop = false;
        if (std::abs(dz) == r || std::abs(dy) == r) {
          for (int32_t dx = -r; dx <= r && !stop; ++dx) stop = visit(dx, dy, dz);
        } else {
          stop = visit(-r, dy, dz) || (r != 0 && visit(r, dy, dz));
        }
        if (stop) {
          if (exact != nullptr) *exact = false;
          return best;
        }
      }
    }
    const float reach = static_cast<float>(r) * cell_ * 0.9999f;
    if (best <= reach * reach) break;
  }
  return best;
}

}  // namespace calf::encoder::surfel_internal
