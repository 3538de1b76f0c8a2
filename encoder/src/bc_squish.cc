// BC1, BC4 and BC5 encoders: libsquish does the fitting; calf adds argument checks, edge
// clamping, threads, and endpoint refinements measured with calf's own decoder rounding (BC4/BC5
// quality 1 here; BC1's `refine` in bc1_refine.cc).
//
// libsquish 1.15 facts used here (DESIGN.md): kBc4 compresses the R byte of RGBA input, kBc5 the
// R and G bytes (two DXT5-alpha blocks); its Decompress decodes BC4/BC5 wrongly, so nothing here
// decodes with it. kDxt1 turns texels with alpha < 128 into 3-colour-mode transparent texels.
#include <squish.h>

#include <algorithm>
#include <cstring>

#include "bc_encode_internal.h"

namespace calf::bc {
namespace {

int bc1_flags(int quality) {
  switch (quality) {
    case 0:
      return squish::kDxt1 | squish::kColourRangeFit;
    case 1:
      return squish::kDxt1 | squish::kColourClusterFit;
    default:
      return squish::kDxt1 | squish::kColourIterativeClusterFit;
  }
}

// Squared error of a BC4 block on 16 values, decoding with calf's (Mesa's) rounding, and the
// best index per texel written into `block` when `write` is set.
int bc4_fit_indices(uint8_t* block, const uint8_t* v, bool write) {
  uint8_t palette[16];
  {
    uint8_t probe[8] = {block[0], block[1], 0x00, 0x00, 0x00, 0x00, 0x00, 0x00};
    // Indices 0..7 for texels 0..7: selectors 0,1,...,7 packed 3 bits each.
    uint64_t s = 0;
    for (int i = 0; i < 8; ++i) s |= uint64_t(i) << (3 * i);
    for (int i = 0; i < 6; ++i) probe[2 + i] = static_cast<uint8_t>(s >> (8 * i));
    decode_bc4_block(probe, palette);
  }
  int total = 0;
  uint64_t sel = 0;
  for (int i = 0; i < 16; ++i) {
    int best = 0, best_e = 1 << 30;
    for (int k = 0; k < 8; ++k) {
      const int d = palette[k] - v[i];
      if (d * d < best_e) best_e = d * d, best = k;
    }
    total += best_e;
    sel |= uint64_t(best) << (3 * i);
  }
  if (write) {
    for (int i = 0; i < 6; ++i) block[2 + i] = static_cast<uint8_t>(sel >> (8 * i));
  }
  return total;
}

// Searches endpoint pairs around the value range in both BC4 modes; keeps squish's block unless
// a candidate is strictly better. Deterministic: candidates are visited in a fixed order.
void bc4_refine(const uint8_t* v, uint8_t* block) {
  int best_e = bc4_fit_indices(block, v, false);
  uint8_t best[8];
  std::memcpy(best, block, 8);
  int lo = 255, hi = 0, lo_in = 255, hi_in = 0;
  for (int i = 0; i < 16; ++i) {
    lo = std::min<int>(lo, v[i]);
    hi = std::max<int>(hi, v[i]);
    if (v[i] != 0 && v[i] != 255)
      lo_in = std::min<int>(lo_in, v[i]), hi_in = std::max<int>(hi_in, v[i]);
  }
  if (lo_in > hi_in) lo_in = hi_in = lo;
  uint8_t cand[8];
  auto consider = [&](int a, int b) {
    if (a < 0 || a > 255 || b < 0 || b > 255) return;
    cand[0] = static_cast<uint8_t>(a);
    cand[1] = static_cast<uint8_t>(b);
    const int e = bc4_fit_indices(cand, v, true);
    if (e < best_e) best_e = e, std::memcpy(best, cand, 8);
  };
  for (int da = -2; da <= 2; ++da) {
    for (int db = -2; db <= 2; ++db) {
      if (hi + da > lo + db) consider(hi + da, lo + db);               // 8-level: a > b
      if (lo_in + db <= hi_in + da) consider(lo_in + db, hi_in + da);  // 6-level + 0/255
    }
  }
  std::memcpy(block, best, 8);
}

}  // namespace

void encode_bc1_block(const uint8_t* rgba, uint8_t* out8, const Bc1Options& options) {
  uint8_t px[64];
  std::memcpy(px, rgba, 64);
  if (!options.punch_through_alpha) {
    for (int i = 0; i < 16; ++i) px[4 * i + 3] = 255;
  }
  squish::Compress(px, out8, bc1_flags(std::clamp(options.quality, 0, 2)));
  if (options.refine && !options.punch_through_alpha) internal::bc1_refine(px, out8);
}

void encode_bc4_block(const uint8_t* r, uint8_t* out8, const Bc4Options& options) {
  uint8_t px[64] = {};
  for (int i = 0; i < 16; ++i) px[4 * i] = r[i], px[4 * i + 3] = 255;
  squish::Compress(px, out8, squish::kBc4);
  if (options.quality >= 1) bc4_refine(r, out8);
}

Status encode_bc1(const Image8& image, uint8_t* out, size_t out_size, const Bc1Options& options) {
  CALF_RETURN_IF_ERROR(internal::check_image(Format::kBc1, image.pixels, image.width, image.height,
                                             image.row_stride, 1, image.channels, 3, 4, out_size,
                                             options.quality, 2, options.threads));
  internal::for_each_block(image.width, image.height, options.threads, out, 8,
                           [&](uint32_t bx, uint32_t by, uint8_t* block) {
                             uint8_t px[64];
                             internal::gather8(image, bx, by, px);
                             encode_bc1_block(px, block, options);
                           });
  return Status::Ok();
}

Status encode_bc4(const Image8& image, uint8_t* out, size_t out_size, const Bc4Options& options) {
  CALF_RETURN_IF_ERROR(internal::check_image(Format::kBc4, image.pixels, image.width, image.height,
                                             image.row_stride, 1, image.channels, 1, 4, out_size,
                                             options.quality, 1, options.threads));
  internal::for_each_block(image.width, image.height, options.threads, out, 8,
                           [&](uint32_t bx, uint32_t by, uint8_t* block) {
                             uint8_t px[64], r[16];
                             internal::gather8(image, bx, by, px);
                             for (int i = 0; i < 16; ++i) r[i] = px[4 * i];
                             encode_bc4_block(r, block, options);
                           });
  return Status::Ok();
}

Status encode_bc5(const Image8& image, uint8_t* out, size_t out_size, const Bc4Options& options) {
  CALF_RETURN_IF_ERROR(internal::check_image(Format::kBc5, image.pixels, image.width, image.height,
                                             image.row_stride, 1, image.channels, 2, 4, out_size,
                                             options.quality, 1, options.threads));
  internal::for_each_block(image.width, image.height, options.threads, out, 16,
                           [&](uint32_t bx, uint32_t by, uint8_t* block) {
                             uint8_t px[64], r[16], g[16];
                             internal::gather8(image, bx, by, px);
                             for (int i = 0; i < 16; ++i) r[i] = px[4 * i], g[i] = px[4 * i + 1];
                             uint8_t* dst = block;
                             // BC5 = BC4(R) then BC4(G); the same fitter as squish's kBc5.
                             encode_bc4_block(r, dst, options);
                             encode_bc4_block(g, dst + 8, options);
                           });
  return Status::Ok();
}

}  // namespace calf::bc
