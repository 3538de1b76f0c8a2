#include "calf/format/depth_predict.h"

#include <bit>
#include <cstddef>

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
  // The predictor reads the codes already written: the output's little-endian pairs (no scratch
  // buffer, so a small rectangle costs no allocation). The first row and column are apart so the
  // inner loop has no edge test.
  auto code_at = [out](size_t i) {
    return static_cast<uint16_t>(out[2 * i] | out[2 * i + 1] << 8);
  };
  auto put = [out](size_t i, uint16_t code) {
    out[2 * i] = static_cast<uint8_t>(code);
    out[2 * i + 1] = static_cast<uint8_t>(code >> 8);
  };
  auto residual = [hi, lo](size_t i) { return static_cast<uint16_t>(hi[i] << 8 | lo[i]); };
  if (w == 0 || h == 0) return;
  uint16_t left = unzigzag16(residual(0), 0);
  put(0, left);
  for (uint32_t x = 1; x < w; ++x) {
    left = unzigzag16(residual(x), left);
    put(x, left);
  }
  for (uint32_t y = 1; y < h; ++y) {
    const size_t base = size_t{y} * w;
    uint16_t up_left = code_at(base - w);
    left = unzigzag16(residual(base), up_left);
    put(base, left);
    for (uint32_t x = 1; x < w; ++x) {
      const uint16_t up = code_at(base - w + x);
      left = unzigzag16(residual(base + x), depth_predict_inner(left, up, up_left));
      put(base + x, left);
      up_left = up;
    }
  }
}

void predict_depth_rect_masked(const uint16_t* codes, uint32_t w, uint32_t h, size_t stride,
                               const uint8_t* mask, std::vector<uint16_t>& residuals) {
  std::vector<uint16_t> all(size_t{w} * h);
  predict_depth_rect(codes, w, h, stride, all.data());
  residuals.clear();
  for (size_t i = 0; i < all.size(); ++i) {
    if (mask_bit(mask, i)) residuals.push_back(all[i]);
  }
}

void reconstruct_depth_rect_masked(const uint8_t* mask, const uint8_t* hi, const uint8_t* lo,
                                   uint32_t w, uint32_t h, uint8_t* inout) {
  auto code_at = [inout](size_t i) {
    return static_cast<uint16_t>(inout[2 * i] | inout[2 * i + 1] << 8);
  };
  // Visits the set bits only, in increasing order (row-major texel order): P-frame rectangles
  // are mostly unchanged texels, which cost a zero test per 8 here.
  const size_t n = size_t{w} * h;
  size_t k = 0;  // residuals used so far
  for (size_t byte = 0; byte < (n + 7) / 8; ++byte) {
    for (unsigned m = mask[byte]; m != 0; m &= m - 1) {
      const size_t i = byte * 8 + static_cast<size_t>(std::countr_zero(m));
      if (i >= n) return;  // padding bits: the parser refuses them, this only stays in bounds
      const size_t y = i / w, x = i - y * w;
      uint16_t pred;
      if (y == 0) {
        pred = x > 0 ? code_at(i - 1) : 0;
      } else if (x == 0) {
        pred = code_at(i - w);
      } else {
        pred = depth_predict_inner(code_at(i - 1), code_at(i - w), code_at(i - w - 1));
      }
      const uint16_t code = unzigzag16(static_cast<uint16_t>(hi[k] << 8 | lo[k]), pred);
      ++k;
      inout[2 * i] = static_cast<uint8_t>(code);
      inout[2 * i + 1] = static_cast<uint8_t>(code >> 8);
    }
  }
}

}  // namespace calf::lf
