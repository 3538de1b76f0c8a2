// BC1 index choice and least-squares endpoint refinement, measured with calf's own decoder
// (calf/format/bc.h), shared by the BC1 encoder (Bc1Options::refine) and the BC1 RDO pass.
//
// Why a refinement after libsquish: its range fit (Bc1Options quality 0) puts the endpoints at
// the extremes of the block's principal axis, which over-spreads them for most blocks; cluster
// fit searches index partitions instead and costs several times more. Given indices, the best
// endpoints are a 2 x 2 linear least-squares problem per channel; solving it, quantising to 5:6:5
// and choosing the indices again gains most of cluster fit's quality on the synthetic LDR set
// (31.69 dB against 31.84, range fit 30.76) and a third of it on interior's captures (+0.09 dB
// against +0.28), at a fraction of its time (docs/ENCODER.md "BC1 fit").
#include <cmath>
#include <cstring>
#include <utility>

#include "bc_encode_internal.h"
#include "calf/format/bc.h"

namespace calf::bc::internal {
namespace {

// Squared 8-bit RGBA error of `block` as calf's decoder shows it against 16 RGBA texels.
uint32_t bc1_block_error(const uint8_t* block, const uint8_t* rgba) {
  uint8_t out[64];
  decode_bc1_block(block, out);
  uint32_t e = 0;
  for (int i = 0; i < 64; ++i) {
    const int d = static_cast<int>(out[i]) - rgba[i];
    e += static_cast<uint32_t>(d * d);
  }
  return e;
}

// 0..255 to the nearest 5- or 6-bit value (the decoder expands by bit replication, which this
// rounding matches within one step; the index choice afterwards absorbs the rest).
uint32_t quantise(float v, int bits) {
  const float max = static_cast<float>((1 << bits) - 1);
  const float q = std::nearbyint(std::fmin(std::fmax(v, 0.0f), 255.0f) * max / 255.0f);
  return static_cast<uint32_t>(q);
}

uint16_t pack565(const float* c) {
  return static_cast<uint16_t>((quantise(c[0], 5) << 11) | (quantise(c[1], 6) << 5) |
                               quantise(c[2], 5));
}

// The endpoints that fit the texels best in the least-squares sense for the block's current
// indices, in four-colour mode (colour 0 > colour 1), with the indices chosen again for them.
// Returns false when the indices do not determine two endpoints (every texel on one colour).
bool least_squares_block(const uint8_t* block, const uint8_t* rgba, uint8_t* out) {
  const uint16_t c0 = static_cast<uint16_t>(block[0] | (block[1] << 8));
  const uint16_t c1 = static_cast<uint16_t>(block[2] | (block[3] << 8));
  const bool four = c0 > c1;
  // Weight of endpoint 0 per index; the three-colour mode's index 3 (black) has none.
  const float four_w[4] = {1.0f, 0.0f, 2.0f / 3.0f, 1.0f / 3.0f};
  const float three_w[4] = {1.0f, 0.0f, 0.5f, -1.0f};
  const float* w = four ? four_w : three_w;
  const uint32_t idx = static_cast<uint32_t>(block[4]) | (static_cast<uint32_t>(block[5]) << 8) |
                       (static_cast<uint32_t>(block[6]) << 16) |
                       (static_cast<uint32_t>(block[7]) << 24);
  double aa = 0, ab = 0, bb = 0, xa[3] = {0, 0, 0}, xb[3] = {0, 0, 0};
  for (int i = 0; i < 16; ++i) {
    const float a = w[(idx >> (2 * i)) & 3];
    if (a < 0) continue;
    const float b = 1 - a;
    aa += a * a, ab += a * b, bb += b * b;
    for (int c = 0; c < 3; ++c) xa[c] += a * rgba[4 * i + c], xb[c] += b * rgba[4 * i + c];
  }
  const double det = aa * bb - ab * ab;
  if (!(det > 1e-6)) return false;
  float e0[3], e1[3];
  for (int c = 0; c < 3; ++c) {
    e0[c] = static_cast<float>((bb * xa[c] - ab * xb[c]) / det);
    e1[c] = static_cast<float>((aa * xb[c] - ab * xa[c]) / det);
  }
  uint16_t p0 = pack565(e0), p1 = pack565(e1);
  if (p0 == p1) return false;  // would be three-colour mode: not what the fit assumed
  if (p0 < p1) std::swap(p0, p1);
  out[0] = static_cast<uint8_t>(p0), out[1] = static_cast<uint8_t>(p0 >> 8);
  out[2] = static_cast<uint8_t>(p1), out[3] = static_cast<uint8_t>(p1 >> 8);
  bc1_choose_indices(out, rgba);
  return true;
}

}  // namespace

void bc1_choose_indices(uint8_t* block, const uint8_t* rgba) {
  uint8_t probe[8];
  std::memcpy(probe, block, 4);
  const uint32_t ramp = 0xE4E4E4E4u;  // texel k: index k mod 4
  for (int k = 0; k < 4; ++k) probe[4 + k] = static_cast<uint8_t>(ramp >> (8 * k));
  uint8_t palette[16][4];
  decode_bc1_block(probe, &palette[0][0]);
  uint32_t idx = 0;
  for (int i = 0; i < 16; ++i) {
    int best = 0;
    int best_d = -1;
    for (int p = 0; p < 4; ++p) {
      int d = 0;
      for (int c = 0; c < 4; ++c) {
        const int x = static_cast<int>(palette[p][c]) - rgba[4 * i + c];
        d += x * x;
      }
      if (best_d < 0 || d < best_d) {
        best_d = d;
        best = p;
      }
    }
    idx |= static_cast<uint32_t>(best) << (2 * i);
  }
  for (int k = 0; k < 4; ++k) block[4 + k] = static_cast<uint8_t>(idx >> (8 * k));
}

void bc1_refine(const uint8_t* rgba, uint8_t* block) {
  uint8_t best[8], cand[8];
  std::memcpy(best, block, 8);
  uint32_t best_e = bc1_block_error(best, rgba);
  // The encoder's own endpoints with the decoder's nearest colours first: squish picks indices
  // with its own rounding of the palette.
  std::memcpy(cand, block, 8);
  bc1_choose_indices(cand, rgba);
  uint32_t e = bc1_block_error(cand, rgba);
  if (e < best_e) best_e = e, std::memcpy(best, cand, 8);
  // Two rounds of fit-then-choose: the second rarely changes a block, a third almost never.
  uint8_t from[8];
  std::memcpy(from, best, 8);
  for (int round = 0; round < 2 && best_e > 0; ++round) {
    if (!least_squares_block(from, rgba, cand)) break;
    e = bc1_block_error(cand, rgba);
    if (e >= best_e) break;
    best_e = e;
    std::memcpy(best, cand, 8);
    std::memcpy(from, cand, 8);
  }
  std::memcpy(block, best, 8);
}

}  // namespace calf::bc::internal
