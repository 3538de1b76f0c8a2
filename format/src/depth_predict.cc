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

constexpr uint16_t kSkyCode = 65535;

uint16_t load_code(const uint8_t* p) {
  uint16_t v;
  std::memcpy(&v, p, 2);  // little-endian host: asserted at the top of the file
  return v;
}
void store_code(uint8_t* p, uint16_t v) {
  std::memcpy(p, &v, 2);
}

// Whether any of the n codes at `codes` (little-endian u16) is sky.
bool any_sky(const uint8_t* codes, size_t n) {
  unsigned all = 0xFFFF;
  for (size_t i = 0; i < n; ++i) all &= load_code(codes + 2 * i) == kSkyCode ? 0u : 0xFFFFu;
  return all != 0xFFFF;
}

// The plane predictor's closed form along a run. Where every prediction of a run of texels
// x0 .. x0 + n - 1 is the plane a + b - c, code(x) - up(x) = code(x - 1) - up(x - 1) + d(x), so
//   code(x0 + i) = up(x0 + i) + carry + d(x0) + ... + d(x0 + i),
// carry = code(x0 - 1) - up(x0 - 1) (0 at the row's start, where the prediction is up(x0)); on the
// first row, where the prediction is the left code, the same with up = 0 and carry = code(x0 - 1).
// A prefix sum has no serial chain through the predictor's branches: SSE2 sums eight residuals in
// three shifted additions. Writes n codes to `out` (little-endian u16) and returns the index of the
// first sky code among them (n if none); the run is the plane's only if none of the codes it
// predicts from is sky, which the caller checks with this index and the codes above.
size_t prefix_run(const uint8_t* hi, const uint8_t* lo, const uint8_t* up, uint16_t carry, size_t n,
                  uint8_t* out) {
  size_t i = 0;
  bool sky = false;
#if defined(__SSE2__)
  const __m128i zero = _mm_setzero_si128(), one = _mm_set1_epi16(1), ones = _mm_set1_epi16(-1);
  __m128i run = _mm_set1_epi16(static_cast<int16_t>(carry));
  __m128i sky_lanes = zero;
  for (; i + 8 <= n; i += 8) {
    const __m128i e = _mm_unpacklo_epi8(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(lo + i)),
                                        _mm_loadl_epi64(reinterpret_cast<const __m128i*>(hi + i)));
    // unzigzag: e >> 1, inverted where e is odd.
    __m128i d = _mm_xor_si128(_mm_srli_epi16(e, 1), _mm_sub_epi16(zero, _mm_and_si128(e, one)));
    d = _mm_add_epi16(d, _mm_slli_si128(d, 2));
    d = _mm_add_epi16(d, _mm_slli_si128(d, 4));
    d = _mm_add_epi16(d, _mm_slli_si128(d, 8));
    d = _mm_add_epi16(d, run);
    const __m128i last = _mm_shufflehi_epi16(d, _MM_SHUFFLE(3, 3, 3, 3));
    run = _mm_unpackhi_epi64(last, last);  // lane 7 in every lane
    if (up != nullptr)
      d = _mm_add_epi16(d, _mm_loadu_si128(reinterpret_cast<const __m128i*>(up + 2 * i)));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(out + 2 * i), d);
    sky_lanes = _mm_or_si128(sky_lanes, _mm_cmpeq_epi16(d, ones));
  }
  sky = _mm_movemask_epi8(sky_lanes) != 0;
  carry = static_cast<uint16_t>(_mm_cvtsi128_si32(run));
#endif
  for (; i < n; ++i) {
    carry = unzigzag16(static_cast<uint16_t>(hi[i] << 8 | lo[i]), carry);
    const uint16_t code =
        up != nullptr ? static_cast<uint16_t>(load_code(up + 2 * i) + carry) : carry;
    store_code(out + 2 * i, code);
    sky |= code == kSkyCode;
  }
  if (!sky) return n;
  for (size_t k = 0; k < n; ++k) {
    if (load_code(out + 2 * k) == kSkyCode) return k;
  }
  return n;  // not reached
}

// Texels x0 .. x0 + n - 1 of row y (> 0) one at a time, with the full predictor: where a sky code
// takes the median into a run. `row` and `up` point at the row's and the upper row's first code.
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

// Texels x0 .. x0 + n - 1 of row y of a rectangle whose row y - 1 (`up`, or null on the first row)
// is final: the prefix sum where the plane holds, else the texel-by-texel predictor.
void reconstruct_run(const uint8_t* hi, const uint8_t* lo, const uint8_t* up, size_t x0, size_t n,
                     uint8_t* row) {
  if (up == nullptr) {  // the first row predicts from the left whatever the codes: always a sum
    const uint16_t carry = x0 > 0 ? load_code(row + 2 * (x0 - 1)) : 0;
    (void)prefix_run(hi, lo, nullptr, carry, n, row + 2 * x0);
    return;
  }
  // The run's predictions read up(x0 - 1 .. x0 + n - 1), code(x0 - 1) and its own first n - 1.
  const size_t from = x0 > 0 ? x0 - 1 : 0;
  const bool left_sky = x0 > 0 && load_code(row + 2 * (x0 - 1)) == kSkyCode;
  if (!left_sky && !any_sky(up + 2 * from, x0 + n - from)) {
    const uint16_t carry =
        x0 > 0 ? static_cast<uint16_t>(load_code(row + 2 * (x0 - 1)) - load_code(up + 2 * (x0 - 1)))
               : 0;
    if (prefix_run(hi, lo, up + 2 * x0, carry, n, row + 2 * x0) + 1 >= n) return;
  }
  general_run(hi, lo, up, x0, n, row);
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
