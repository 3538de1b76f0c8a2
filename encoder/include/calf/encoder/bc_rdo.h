// Rate-distortion optimisation of coded BC1 / BC6H / BC7 images for an LZ supercompressor (zstd,
// LZMA).
//
// BC6H and BC7 blocks are dense bit fields: two blocks of the same colour rarely share a byte,
// so a chunk of them barely compresses. This pass rewrites already coded blocks, in order,
// towards bytes an LZ coder finds again: for each block it tries, from each of the previous
// `window` blocks of the image (and the three blocks above it), a copy of that block whole, of a
// prefix of its bytes (mode and endpoints, own indices kept) and of a suffix (indices, own mode
// and endpoints kept), at the lengths listed in bc_rdo.cc. Each candidate is decoded and measured
// against the target texels; the one of least cost J = D + lambda · R is kept, with D the block's
// squared error as a display shows it, in 8-bit sRGB units (BC7: the 8-bit sRGB RGBA values it
// stores; BC6H: 255 times the sRGB encoding of the linear values, the curve extended past 1
// as 1.055 v^(1/2.4) - 0.055 so that highlights keep a weight that falls as the eye's) and R an
// estimate of its LZ bits (8 per byte not covered by the longest run it shares, at the same byte
// offsets, with a source block; a run of at least 3 bytes costs 24 bits). A BC6H candidate that
// moves a texel further from its target than 1/8 stop (128 half ulps) or than the original block
// did, whichever is larger, is refused: the display metric alone would let deep shadows become
// any dark value, and HDR content may be shown brighter. The blocks stay standard blocks: any
// decoder reads them; only the error and the supercompressed size change. lambda 0 leaves the
// blocks untouched.
//
// Deterministic (a sequential pass over the blocks; no threads), no global state. The idea is
// Geldreich's "entropy reduction transform" (bc7enc_rdo); this implementation and its rate
// model are calf's own.
#pragma once

#include <cstddef>
#include <cstdint>

#include "calf/format/bc.h"
#include "calf/format/status.h"

namespace calf::bc {

struct BcRdoOptions {
  double lambda = 0;    // squared 8-bit sRGB error per estimated bit; 0 = off, >= 0
  uint32_t window = 2;  // previous blocks in row order tried as sources, 1..256
};

// What one pass did (for the encoder's statistics).
struct BcRdoStats {
  uint64_t blocks = 0, changed = 0;
  double error_before = 0, error_after = 0;  // sum of D over the blocks, before / after
};

// Rewrites the BC6H_UF16 blocks of a width x height image (`blocks`, row-major, 16 bytes each,
// compressed_size() bytes) against `target`: the image's texels as half-float bit patterns,
// 3 per texel (RGB), rows width * 3 apart. Errors: kBcBufferSize (a buffer too small),
// kBcOptions (lambda negative or not finite, window out of range).
Status rdo_bc6h(const uint16_t* target, uint32_t width, uint32_t height, uint8_t* blocks,
                size_t blocks_size, const BcRdoOptions& options, BcRdoStats* stats = nullptr);

// The same for BC7 blocks against 8-bit RGBA texels (rows width * 4 apart).
Status rdo_bc7(const uint8_t* target, uint32_t width, uint32_t height, uint8_t* blocks,
               size_t blocks_size, const BcRdoOptions& options, BcRdoStats* stats = nullptr);

// The same for BC1 blocks (8 bytes each) against 8-bit RGBA texels (rows width * 4 apart), with a
// rate model for calf's block-split BC1 chunks (SPEC §7: all endpoint halves, then all index
// halves): each 4-byte half costs 32 bits as literals, 20 when it repeats the same half of a
// source block (the previous `window` blocks and the three above), 2 when it repeats the previous
// block's half as that block repeated the one before it (zstd extending one match). Candidates per
// source: the whole block; its endpoints with indices re-chosen for them (nearest colour per
// texel, as the decoder's palette gives it); its indices with the block's own endpoints. D is the
// squared 8-bit RGBA error, so no block gains more than lambda * 60 (64 - 4 bits saved).
Status rdo_bc1(const uint8_t* target, uint32_t width, uint32_t height, uint8_t* blocks,
               size_t blocks_size, const BcRdoOptions& options, BcRdoStats* stats = nullptr);

}  // namespace calf::bc
