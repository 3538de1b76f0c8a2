#include "calf/encoder/depth_aabb.h"

#include <algorithm>
#include <cstdlib>
#include <string>

namespace calf::encoder {
namespace {

// A half-open box on the (possibly coarsened) mask grid.
struct Box {
  uint32_t x0, y0, x1, y1;
  uint64_t area() const { return static_cast<uint64_t>(x1 - x0) * (y1 - y0); }
};

constexpr uint32_t kNone = UINT32_MAX;

// The tight bounding box of the set texels inside `b`, or an empty box (x0 == x1) when none.
Box tighten(const ChangeMask& m, const Box& b) {
  Box t{kNone, kNone, 0, 0};
  for (uint32_t y = b.y0; y < b.y1; ++y) {
    for (uint32_t x = b.x0; x < b.x1; ++x) {
      if (!m.at(x, y)) continue;
      t.x0 = std::min(t.x0, x);
      t.y0 = std::min(t.y0, y);
      t.x1 = std::max(t.x1, x + 1);
      t.y1 = std::max(t.y1, y + 1);
    }
  }
  if (t.x0 == kNone) return Box{0, 0, 0, 0};
  return t;
}

struct Split {
  uint64_t gain = 0;
  Box first{}, second{};
};

// The best split of tight box `b` along x (vertical cut lines) — or along y when `along_y` — by
// area removed once both halves are tight. Per line of the cut axis we keep the extent of set
// texels across the other axis; prefix / suffix sweeps then give both halves' boxes for every cut
// in one pass.
Split best_split(const ChangeMask& m, const Box& b, bool along_y) {
  const uint32_t lo = along_y ? b.y0 : b.x0, hi = along_y ? b.y1 : b.x1;
  const uint32_t n = hi - lo;
  std::vector<uint32_t> ext_min(n, kNone), ext_max(n, 0);  // across-axis extent per line
  for (uint32_t y = b.y0; y < b.y1; ++y) {
    for (uint32_t x = b.x0; x < b.x1; ++x) {
      if (!m.at(x, y)) continue;
      const uint32_t line = (along_y ? y : x) - lo, across = along_y ? x : y;
      ext_min[line] = std::min(ext_min[line], across);
      ext_max[line] = std::max(ext_max[line], across + 1);
    }
  }
  // prefix: for lines [0, i), the last non-empty line and the across extent
  std::vector<uint32_t> pre_last(n + 1, kNone), pre_min(n + 1, kNone), pre_max(n + 1, 0);
  for (uint32_t i = 0; i < n; ++i) {
    const bool set = ext_min[i] != kNone;
    pre_last[i + 1] = set ? i : pre_last[i];
    pre_min[i + 1] = std::min(pre_min[i], ext_min[i]);
    pre_max[i + 1] = std::max(pre_max[i], ext_max[i]);
  }
  std::vector<uint32_t> suf_first(n + 1, kNone), suf_min(n + 1, kNone), suf_max(n + 1, 0);
  for (uint32_t i = n; i-- > 0;) {
    const bool set = ext_min[i] != kNone;
    suf_first[i] = set ? i : suf_first[i + 1];
    suf_min[i] = std::min(suf_min[i + 1], ext_min[i]);
    suf_max[i] = std::max(suf_max[i + 1], ext_max[i]);
  }
  Split best;
  const uint64_t area = b.area();
  for (uint32_t cut = 1; cut < n; ++cut) {
    if (pre_last[cut] == kNone || suf_first[cut] == kNone) continue;
    // first half: lines [0, pre_last + 1), across [pre_min, pre_max); second: [suf_first, n)
    const uint64_t a1 = static_cast<uint64_t>(pre_last[cut] + 1) * (pre_max[cut] - pre_min[cut]);
    const uint64_t a2 = static_cast<uint64_t>(n - suf_first[cut]) * (suf_max[cut] - suf_min[cut]);
    if (a1 + a2 >= area || area - a1 - a2 <= best.gain) continue;
    best.gain = area - a1 - a2;
    if (along_y) {
      best.first = {pre_min[cut], lo, pre_max[cut], lo + pre_last[cut] + 1};
      best.second = {suf_min[cut], lo + suf_first[cut], suf_max[cut], hi};
    } else {
      best.first = {lo, pre_min[cut], lo + pre_last[cut] + 1, pre_max[cut]};
      best.second = {lo + suf_first[cut], suf_min[cut], hi, suf_max[cut]};
    }
  }
  return best;
}

// The mask at 1/k resolution: a coarse texel is set when any texel of its k x k block is.
ChangeMask coarsen(const ChangeMask& m, uint32_t k) {
  ChangeMask c;
  c.width = (m.width + k - 1) / k;
  c.height = (m.height + k - 1) / k;
  c.bits.assign(static_cast<size_t>(c.width) * c.height, 0);
  for (uint32_t y = 0; y < m.height; ++y) {
    for (uint32_t x = 0; x < m.width; ++x) {
      if (m.at(x, y)) c.bits[static_cast<size_t>(y / k) * c.width + x / k] = 1;
    }
  }
  return c;
}

}  // namespace

Expected<ChangeMask> depth_change_mask(std::span<const std::span<const uint16_t>> frames,
                                       uint32_t width, uint32_t height, uint32_t current,
                                       uint32_t window, uint16_t epsilon) {
  if (current == 0 || current >= frames.size() || window == 0) {
    return Status(ErrorId::kInvalidArgument, "depth change mask: frame " + std::to_string(current) +
                                                 " of " + std::to_string(frames.size()) +
                                                 " with window " + std::to_string(window) +
                                                 " (need 1 <= frame < count and window >= 1)");
  }
  const size_t texels = static_cast<size_t>(width) * height;
  for (const auto& f : frames) {
    if (f.size() != texels) {
      return Status(ErrorId::kInvalidArgument, "depth change mask: a frame holds " +
                                                   std::to_string(f.size()) + " values, expected " +
                                                   std::to_string(texels));
    }
  }
  ChangeMask mask{width, height, std::vector<uint8_t>(texels, 0)};
  const uint32_t first = current > window ? current - window : 0;
  const auto& now = frames[current];
  for (uint32_t j = first; j < current; ++j) {
    const auto& before = frames[j];
    for (size_t i = 0; i < texels; ++i) {
      if (std::abs(static_cast<int>(now[i]) - static_cast<int>(before[i])) > epsilon) {
        mask.bits[i] = 1;
      }
    }
  }
  return mask;
}

Expected<std::vector<PixelRect>> fit_change_boxes(const ChangeMask& mask,
                                                  const AabbOptions& options) {
  if (options.max_boxes == 0 || options.alignment == 0) {
    return Status(ErrorId::kInvalidArgument,
                  "AABB fitting: max boxes " + std::to_string(options.max_boxes) +
                      " and alignment " + std::to_string(options.alignment) +
                      " must be at least 1");
  }
  const uint32_t k = options.alignment;
  const ChangeMask grid = k == 1 ? mask : coarsen(mask, k);
  std::vector<Box> boxes;
  const Box whole = tighten(grid, Box{0, 0, grid.width, grid.height});
  if (whole.area() == 0) return std::vector<PixelRect>{};
  boxes.push_back(whole);
  while (boxes.size() < options.max_boxes) {
    Split best;
    size_t best_box = 0;
    for (size_t i = 0; i < boxes.size(); ++i) {
      for (bool along_y : {false, true}) {
        const Split s = best_split(grid, boxes[i], along_y);
        if (s.gain > best.gain) {
          best = s;
          best_box = i;
        }
      }
    }
    if (best.gain == 0) break;  // no split removes an uncovered texel
    boxes[best_box] = best.first;
    boxes.push_back(best.second);
  }
  std::sort(boxes.begin(), boxes.end(),
            [](const Box& a, const Box& b) { return a.y0 != b.y0 ? a.y0 < b.y0 : a.x0 < b.x0; });
  std::vector<PixelRect> rects;
  rects.reserve(boxes.size());
  for (const Box& b : boxes) {
    const uint32_t x0 = b.x0 * k, y0 = b.y0 * k;
    const uint32_t x1 = std::min(b.x1 * k, mask.width), y1 = std::min(b.y1 * k, mask.height);
    rects.push_back({x0, y0, x1 - x0, y1 - y0});
  }
  return rects;
}

uint64_t covered_texels(std::span<const PixelRect> boxes) {
  uint64_t total = 0;
  for (const auto& b : boxes) total += static_cast<uint64_t>(b.width) * b.height;
  return total;
}

}  // namespace calf::encoder
