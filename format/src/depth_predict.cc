#include "calf/format/depth_predict.h"

#include <bit>
#include <cstddef>
#include <cstring>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace calf::lf {

static_assert(std::endian::native == std::endian::little,
              "decoded codes are little-endian u16 stored as the host writes them");

namespace {

uint16_t load_code(const uint8_t* p) {
  uint16_t v;
  std::memcpy(&v, p, 2);  // little-endian host: asserted above
  return v;
}
void store_code(uint8_t* p, uint16_t v) {
  std::memcpy(p, &v, 2);
}

// Inversion by prefix sums. Where every prediction of texels x .. x + n - 1 of a row is the plane
// a + b - c, code(x) - up(x) = code(x - 1) - up(x - 1) + d(x) (d: the unzigzagged residual), so
//   code(x + i) = up(x + i) + carry + d(x) + ... + d(x + i),  carry = code(x - 1) - up(x - 1)
// (0 at the row's start, where the prediction is up(x)); on the first row, which predicts from
// the left code whatever it is, the same with up = 0 and carry = code(x - 1). A prefix sum has no
// serial chain through the predictor's branches: SSE2 sums eight residuals in three shifted
// additions. Where sky (65535) takes the median into the prediction, texels go one at a time,
// except a block under sky with sky on its left (or at the row's start) and zero residuals, which
// is sky: with a = b = sky the median is sky whatever c is, and at x = 0 the prediction is b. So
// the sky around a model costs a compare per eight texels too.
#if defined(__SSE2__)
// The residuals of texels i .. i + 7, unzigzagged: e >> 1, inverted where e is odd.
__m128i residuals8(const uint8_t* hi, const uint8_t* lo) {
  const __m128i e = _mm_unpacklo_epi8(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(lo)),
                                      _mm_loadl_epi64(reinterpret_cast<const __m128i*>(hi)));
  return _mm_xor_si128(_mm_srli_epi16(e, 1),
                       _mm_sub_epi16(_mm_setzero_si128(), _mm_and_si128(e, _mm_set1_epi16(1))));
}
// Lane j: d(0) + ... + d(j).
__m128i prefix8(__m128i d) {
  d = _mm_add_epi16(d, _mm_slli_si128(d, 2));
  d = _mm_add_epi16(d, _mm_slli_si128(d, 4));
  return _mm_add_epi16(d, _mm_slli_si128(d, 8));
}
#endif

// The first row of a rectangle's run x0 .. x0 + n - 1: code(x) = code(x - 1) + d(x), code(-1) = 0.
void first_row_run(const uint8_t* hi, const uint8_t* lo, size_t x0, size_t n, uint8_t* row) {
  uint16_t carry = x0 > 0 ? load_code(row + 2 * (x0 - 1)) : 0;
  uint8_t* out = row + 2 * x0;
  size_t i = 0;
#if defined(__SSE2__)
  __m128i run = _mm_set1_epi16(static_cast<int16_t>(carry));
  for (; i + 8 <= n; i += 8) {
    const __m128i codes = _mm_add_epi16(prefix8(residuals8(hi + i, lo + i)), run);
    _mm_storeu_si128(reinterpret_cast<__m128i*>(out + 2 * i), codes);
    const __m128i last = _mm_shufflehi_epi16(codes, _MM_SHUFFLE(3, 3, 3, 3));
    run = _mm_unpackhi_epi64(last, last);  // lane 7 in every lane
  }
  carry = static_cast<uint16_t>(_mm_cvtsi128_si32(run));
#endif
  for (; i < n; ++i) {
    carry = unzigzag16(static_cast<uint16_t>(hi[i] << 8 | lo[i]), carry);
    store_code(out + 2 * i, carry);
  }
}

// Texels x0 .. x0 + n - 1 of a later row, one at a time with the full predictor. `row` and `up`
// point at the row's and the upper row's first code.
void general_run(const uint8_t* hi, const uint8_t* lo, const uint8_t* up, size_t x0, size_t n,
                 uint8_t* row) {
  for (size_t i = 0; i < n; ++i) {
    const size_t x = x0 + i;
    const uint16_t pred =
        x == 0 ? load_code(up)
               : depth_predict_inner(load_code(row + 2 * (x - 1)), load_code(up + 2 * x),
                                     load_code(up + 2 * (x - 1)));
    store_code(row + 2 * x, unzigzag16(static_cast<uint16_t>(hi[i] << 8 | lo[i]), pred));
  }
}

// Texels x0 .. x0 + n - 1 of row y of a rectangle whose row y - 1 (`up`, null on the first row)
// and the texels left of x0 are final, eight at a time where the block is the plane's or sky.
void reconstruct_run(const uint8_t* hi, const uint8_t* lo, const uint8_t* up, size_t x0, size_t n,
                     uint8_t* row) {
  if (up == nullptr) {
    first_row_run(hi, lo, x0, n, row);
    return;
  }
  size_t i = 0;
#if defined(__SSE2__)
  const __m128i sky = _mm_set1_epi16(static_cast<int16_t>(kLog16Sky));
  for (; i + 8 <= n; i += 8) {
    const size_t x = x0 + i;
    const __m128i above = _mm_loadu_si128(reinterpret_cast<const __m128i*>(up + 2 * x));
    const int above_sky = _mm_movemask_epi8(_mm_cmpeq_epi16(above, sky));  // 2 bits a texel
    // The predictions of x .. x + 7 read up(x - 1 .. x + 7), code(x - 1) and codes x .. x + 6.
    const bool left_sky = x > 0 && load_code(row + 2 * (x - 1)) == kLog16Sky;
    const bool up_left_sky = x > 0 && load_code(up + 2 * (x - 1)) == kLog16Sky;
    const __m128i d = residuals8(hi + i, lo + i);
    if (above_sky == 0 && !left_sky && !up_left_sky) {
      const uint16_t carry =
          x > 0 ? static_cast<uint16_t>(load_code(row + 2 * (x - 1)) - load_code(up + 2 * (x - 1)))
                : 0;
      const __m128i codes = _mm_add_epi16(
          _mm_add_epi16(prefix8(d), _mm_set1_epi16(static_cast<int16_t>(carry))), above);
      _mm_storeu_si128(reinterpret_cast<__m128i*>(row + 2 * x), codes);
      // A sky code in lanes 0..6 takes the median into the next lane: redo the block below.
      if ((_mm_movemask_epi8(_mm_cmpeq_epi16(codes, sky)) & 0x3FFF) == 0) continue;
    } else if (above_sky == 0xFFFF && (x == 0 || left_sky) &&
               _mm_movemask_epi8(_mm_cmpeq_epi16(d, _mm_setzero_si128())) == 0xFFFF) {
      _mm_storeu_si128(reinterpret_cast<__m128i*>(row + 2 * x), sky);
      continue;
    }
    general_run(hi + i, lo + i, up, x, 8, row);
  }
#endif
  general_run(hi + i, lo + i, up, x0 + i, n - i, row);
}

// The first index in [i, end) whose mask bit is `set`, or end.
size_t next_bit(const uint8_t* mask, size_t i, size_t end, bool set) {
  const uint8_t skip = set ? 0x00 : 0xFF;  // a byte with no bit of the kind looked for
  while (i < end) {
    if ((i & 7) == 0 && i + 8 <= end && mask[i >> 3] == skip) {
      i += 8;
      continue;
    }
    if (mask_bit(mask, i) == set) return i;
    ++i;
  }
  return end;
}

}  // namespace

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
  // Row by row: the predictor reads the codes already written (the output's little-endian pairs,
  // no scratch buffer, so a small rectangle costs no allocation).
  for (uint32_t y = 0; y < h; ++y) {
    const size_t base = size_t{y} * w;
    reconstruct_run(hi + base, lo + base, y > 0 ? out + 2 * (base - w) : nullptr, 0, w,
                    out + 2 * base);
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
  // Row by row, each run of set bits as one run of reconstruct_run: its left neighbour and the row
  // above are final (this frame's, from the state or from earlier runs). P-frame rectangles are
  // mostly unchanged texels, which cost a byte compare per 8 here.
  size_t k = 0;  // residuals used so far
  for (uint32_t y = 0; y < h; ++y) {
    const size_t base = size_t{y} * w, end = base + w;
    uint8_t* row = inout + 2 * base;
    const uint8_t* up = y > 0 ? row - 2 * size_t{w} : nullptr;
    size_t i = next_bit(mask, base, end, true);
    while (i < end) {
      const size_t j = next_bit(mask, i, end, false);
      reconstruct_run(hi + k, lo + k, up, i - base, j - i, row);
      k += j - i;
      i = next_bit(mask, j, end, true);
    }
  }
}

}  // namespace calf::lf
