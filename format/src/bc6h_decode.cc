// BC6H (BPTC float) block decoder, written from ARB_texture_compression_bptc.
//
// Fields are gathered with the compile-time parse of the specification's Table.F
// (kBc6hLayouts), so the layout is the specification's text rather than 14 hand-written readers.
#include <cstring>

#include "bc_bits.h"
#include "calf/format/bc.h"
#include "calf/format/bc_tables.h"

namespace calf::bc {
namespace {

int sign_extend(int v, int bits) {
  const int m = 1 << (bits - 1);
  return ((v & ((1 << bits) - 1)) ^ m) - m;
}

// Endpoint unquantisation (specification pseudocode) to the 16-bit interpolation domain.
int unquantize(int x, int bits, bool is_signed) {
  if (!is_signed) {
    if (bits >= 15) return x;
    if (x == 0) return 0;
    if (x == (1 << bits) - 1) return 0xffff;
    return ((x << 15) + 0x4000) >> (bits - 1);
  }
  if (bits >= 16) return x;
  const bool negative = x < 0;
  if (negative) x = -x;
  int q;
  if (x == 0) {
    q = 0;
  } else if (x >= (1 << (bits - 1)) - 1) {
    q = 0x7fff;
  } else {
    q = ((x << 15) + 0x4000) >> (bits - 1);
  }
  return negative ? -q : q;
}

// Final scaling of an interpolated value to half-float bits: x31/64 (unsigned) or x31/32 on the
// magnitude with the sign put back (signed). Never yields Inf or NaN (max 0x7bff).
uint16_t finish(int v, bool is_signed) {
  if (!is_signed) return static_cast<uint16_t>((v * 31) >> 6);
  if (v < 0) return static_cast<uint16_t>((((-v) * 31) >> 5) | 0x8000);
  return static_cast<uint16_t>((v * 31) >> 5);
}

}  // namespace

int bc6h_unquantize(int x, int bits, bool is_signed) {
  return unquantize(x, bits, is_signed);
}

void decode_bc6h_block(const uint8_t* block, bool is_signed, uint16_t* rgb_half) {
  const int k = bc6h_mode_index(block[0]);
  if (k < 0) {  // reserved mode: (0, 0, 0)
    std::memset(rgb_half, 0, 16 * 3 * sizeof(uint16_t));
    return;
  }
  const Bc6hMode& mode = kBc6hModes[k];
  const Bc6hLayout& layout = kBc6hLayouts[k];
  BitReader br(block);
  int var[14] = {};
  for (int i = 0; i < layout.count; ++i) {
    var[layout.field[i].var] |= static_cast<int>(br.read(1)) << layout.field[i].bit;
  }
  const int regions = mode.partition_bits ? 2 : 1;
  const int partition = var[kBc6hPartitionVar];
  const int eb = mode.endpoint_bits;

  // Endpoints: e0 as stored (sign-extended for signed blocks); the others sign-extended when
  // signed or stored as deltas; deltas added to e0 and wrapped to the endpoint precision.
  int ep[4][3];
  for (int c = 0; c < 3; ++c) {
    ep[0][c] = is_signed ? sign_extend(var[c], eb) : var[c];
    for (int e = 1; e < 2 * regions; ++e) {
      const int bits = mode.transformed ? mode.delta_bits[c] : eb;
      int v = var[3 * e + c];
      if (is_signed || mode.transformed) v = sign_extend(v, bits);
      if (mode.transformed) {
        v = (ep[0][c] + v) & ((1 << eb) - 1);
        if (is_signed) v = sign_extend(v, eb);
      }
      ep[e][c] = v;
    }
  }
  for (int e = 0; e < 2 * regions; ++e)
    for (int c = 0; c < 3; ++c) ep[e][c] = unquantize(ep[e][c], eb, is_signed);

  // Indices: 3 bits (two regions) or 4 bits (one region); anchors one bit shorter.
  const int ib = regions == 2 ? 3 : 4;
  const uint8_t* w = weights_for_bits(ib);
  for (int i = 0; i < 16; ++i) {
    const int index = static_cast<int>(br.read(ib - (is_anchor(regions, partition, i) ? 1 : 0)));
    const int s = subset_of(regions, partition, i);
    for (int c = 0; c < 3; ++c) {
      const int v = (ep[2 * s][c] * (64 - w[index]) + ep[2 * s + 1][c] * w[index] + 32) >> 6;
      rgb_half[3 * i + c] = finish(v, is_signed);
    }
  }
}

}  // namespace calf::bc
