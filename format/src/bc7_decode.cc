// BC7 (BPTC unorm) block decoder, written from ARB_texture_compression_bptc.
//
// Deliberately the plain field-by-field reading of the specification (Table.M drives a generic
// bit reader): this is the reference against which encoders and any faster path are tested.
#include <cstring>

#include "bc_bits.h"
#include "calf/format/bc.h"
#include "calf/format/bc_tables.h"

namespace calf::bc {
namespace {

// Table.M of the specification, one row per mode.
struct Bc7Mode {
  int subsets, partition_bits, rotation_bits, index_select_bits, colour_bits, alpha_bits;
  int endpoint_pbits, shared_pbits, index_bits, index2_bits;
};
constexpr Bc7Mode kModes[8] = {
    {3, 4, 0, 0, 4, 0, 1, 0, 3, 0}, {2, 6, 0, 0, 6, 0, 0, 1, 3, 0}, {3, 6, 0, 0, 5, 0, 0, 0, 2, 0},
    {2, 6, 0, 0, 7, 0, 1, 0, 2, 0}, {1, 0, 2, 1, 5, 6, 0, 0, 2, 3}, {1, 0, 2, 0, 7, 8, 0, 0, 2, 2},
    {1, 0, 0, 0, 7, 7, 1, 0, 4, 0}, {2, 6, 0, 0, 5, 5, 1, 0, 2, 0},
};

// A `bits`-bit value (p-bit included) scaled to 8 bits by replicating its top bits.
int unquantize(int v, int bits) {
  v <<= 8 - bits;
  return v | (v >> bits);
}

}  // namespace

void decode_bc7_block(const uint8_t* block, uint8_t* rgba) {
  if (block[0] == 0) {  // reserved mode: transparent black
    std::memset(rgba, 0, 64);
    return;
  }
  int mode_index = 0;
  while (!((block[0] >> mode_index) & 1)) ++mode_index;
  const Bc7Mode& m = kModes[mode_index];
  BitReader br(block);
  br.skip(mode_index + 1);
  const int partition = static_cast<int>(br.read(m.partition_bits));
  const int rotation = static_cast<int>(br.read(m.rotation_bits));
  const int index_select = static_cast<int>(br.read(m.index_select_bits));

  const int ns = m.subsets, ne = 2 * ns;
  int ep[6][4];  // endpoint e = 2 * subset + {0, 1}; channels RGBA
  for (int c = 0; c < 3; ++c)
    for (int e = 0; e < ne; ++e) ep[e][c] = static_cast<int>(br.read(m.colour_bits));
  for (int e = 0; e < ne; ++e)
    ep[e][3] = m.alpha_bits ? static_cast<int>(br.read(m.alpha_bits)) : 255;

  int pbit[6] = {0, 0, 0, 0, 0, 0};
  if (m.endpoint_pbits) {
    for (int e = 0; e < ne; ++e) pbit[e] = static_cast<int>(br.read(1));
  } else if (m.shared_pbits) {
    for (int s = 0; s < ns; ++s) pbit[2 * s] = pbit[2 * s + 1] = static_cast<int>(br.read(1));
  }
  const bool has_pbit = m.endpoint_pbits || m.shared_pbits;
  for (int e = 0; e < ne; ++e) {
    for (int c = 0; c < 3; ++c) {
      ep[e][c] = has_pbit ? unquantize(ep[e][c] << 1 | pbit[e], m.colour_bits + 1)
                          : unquantize(ep[e][c], m.colour_bits);
    }
    if (m.alpha_bits) {
      ep[e][3] = has_pbit ? unquantize(ep[e][3] << 1 | pbit[e], m.alpha_bits + 1)
                          : unquantize(ep[e][3], m.alpha_bits);
    }
  }

  // Primary indices (anchors one bit shorter), then secondary ones (anchor: texel 0 only).
  int index1[16], index2[16] = {};
  for (int i = 0; i < 16; ++i) {
    index1[i] = static_cast<int>(br.read(m.index_bits - (is_anchor(ns, partition, i) ? 1 : 0)));
  }
  if (m.index2_bits) {
    for (int i = 0; i < 16; ++i) index2[i] = static_cast<int>(br.read(m.index2_bits - (i == 0)));
  }

  // Which index set drives colour and which alpha (index selection only in mode 4).
  const bool swap = m.index2_bits && index_select;
  const int colour_bits = swap ? m.index2_bits : m.index_bits;
  const int alpha_bits = m.index2_bits ? (swap ? m.index_bits : m.index2_bits) : m.index_bits;
  const uint8_t* wc = weights_for_bits(colour_bits);
  const uint8_t* wa = weights_for_bits(alpha_bits);
  for (int i = 0; i < 16; ++i) {
    const int s = subset_of(ns, partition, i);
    const int* e0 = ep[2 * s];
    const int* e1 = ep[2 * s + 1];
    const int ci = swap ? index2[i] : index1[i];
    const int ai = m.index2_bits ? (swap ? index1[i] : index2[i]) : index1[i];
    int px[4];
    for (int c = 0; c < 3; ++c) px[c] = ((64 - wc[ci]) * e0[c] + wc[ci] * e1[c] + 32) >> 6;
    px[3] = ((64 - wa[ai]) * e0[3] + wa[ai] * e1[3] + 32) >> 6;
    if (rotation) std::swap(px[3], px[rotation - 1]);
    for (int c = 0; c < 4; ++c) rgba[4 * i + c] = static_cast<uint8_t>(px[c]);
  }
}

}  // namespace calf::bc
