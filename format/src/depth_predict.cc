#include "calf/format/depth_predict.h"

#include <cstddef>
#include <utility>
#include <vector>

namespace calf::lf {

void predict_depth_rect(const uint16_t* codes, uint32_t w, uint32_t h, size_t stride,
                        uint16_t* residuals) {
  for (uint32_t y = 0; y < h; ++y) {
    const uint16_t* row = codes + y * stride;
    const uint16_t* up = y > 0 ? row - stride : nullptr;
    uint16_t* e = residuals + size_t{y} * w;
    for (uint32_t x = 0; x < w; ++x) {
      uint16_t pred;
      if (up == nullptr) {
        pred = x > 0 ? row[x - 1] : 0;
      } else if (x == 0) {
        pred = up[0];
      } else {
        pred = depth_predict_inner(row[x - 1], up[x], up[x - 1]);
      }
      e[x] = zigzag16(row[x], pred);
    }
  }
}

void reconstruct_depth_rect(const uint8_t* hi, const uint8_t* lo, uint32_t w, uint32_t h,
                            uint8_t* out) {
  // Two rows of codes are all the predictor reads; the output is written as bytes, so keep the
  // previous row's codes apart rather than reading the little-endian output back.
  std::vector<uint16_t> rows(size_t{w} * 2);
  uint16_t* prev = rows.data();
  uint16_t* cur = rows.data() + w;
  for (uint32_t y = 0; y < h; ++y) {
    const size_t base = size_t{y} * w;
    for (uint32_t x = 0; x < w; ++x) {
      const auto e = static_cast<uint16_t>(hi[base + x] << 8 | lo[base + x]);
      uint16_t pred;
      if (y == 0) {
        pred = x > 0 ? cur[x - 1] : 0;
      } else if (x == 0) {
        pred = prev[0];
      } else {
        pred = depth_predict_inner(cur[x - 1], prev[x], prev[x - 1]);
      }
      const uint16_t code = unzigzag16(e, pred);
      cur[x] = code;
      out[2 * (base + x)] = static_cast<uint8_t>(code);
      out[2 * (base + x) + 1] = static_cast<uint8_t>(code >> 8);
    }
    std::swap(prev, cur);
  }
}

}  // namespace calf::lf
