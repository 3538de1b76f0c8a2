// Private to calf_encoder: what the BCn encoders share (argument checks, block gathering with
// edge clamping, threading over block rows, a 128-bit bit writer).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "calf/encoder/bc_encode.h"

namespace calf::bc::internal {

// Checks size, stride, buffers, channels and quality/threads; `min_channels`..`max_channels`
// bounds image.channels; `max_quality` bounds quality.
Status check_image(Format f, const void* pixels, uint32_t width, uint32_t height, size_t row_stride,
                   size_t row_units, uint32_t channels, uint32_t min_channels,
                   uint32_t max_channels, size_t out_size, int quality, int max_quality,
                   int threads);

// Gathers block (bx, by) as 16 RGBA8 texels, clamping coordinates to the image. Missing
// channels read as 0 (G, B) and 255 (A).
void gather8(const Image8& image, uint32_t bx, uint32_t by, uint8_t* rgba);
// Gathers block (bx, by) as 16 RGB floats, clamping coordinates to the image.
void gatherf(const ImageF& image, uint32_t bx, uint32_t by, float* rgb);

// Calls fn(bx, by, block) for every block of a width x height image, where `block` points at
// that block's `block_bytes` in `out` (blocks row-major), on up to `threads` threads (0 = all
// cores). Blocks are independent, so the result never depends on the thread count.
template <typename Fn>
void for_each_block(uint32_t width, uint32_t height, int threads, uint8_t* out, size_t block_bytes,
                    const Fn& fn);
void run_rows(uint32_t rows, int threads, void (*row)(void*, uint32_t), void* ctx);

template <typename Fn>
void for_each_block(uint32_t width, uint32_t height, int threads, uint8_t* out, size_t block_bytes,
                    const Fn& fn) {
  struct Ctx {
    const Fn* fn;
    uint32_t bw;
    uint8_t* out;
    size_t block_bytes;
  } ctx{&fn, blocks_along(width), out, block_bytes};
  run_rows(
      blocks_along(height), threads,
      [](void* p, uint32_t by) {
        auto* c = static_cast<Ctx*>(p);
        uint8_t* row = c->out + size_t{by} * c->bw * c->block_bytes;
        for (uint32_t bx = 0; bx < c->bw; ++bx) (*c->fn)(bx, by, row + bx * c->block_bytes);
      },
      &ctx);
}

// BC1 (encoder/src/bc1_refine.cc). The indices (bytes 4..7 of `block`) that pick, for every
// texel of `rgba` (16 RGBA8 texels), the nearest of the four colours of the endpoints in bytes
// 0..3 by squared RGBA distance (ties: the lower index); the palette is the decoder's own.
void bc1_choose_indices(uint8_t* block, const uint8_t* rgba);
// Rewrites `block` with least-squares endpoints for its indices and indices chosen again for
// them, while that lowers the squared RGBA error as calf's decoder shows the block; the block is
// kept where nothing does. Opaque blocks only (the fit assumes four-colour mode).
void bc1_refine(const uint8_t* rgba, uint8_t* block);

// Writes fields LSB-first into a 16-byte block (the inverse of format/src/bc_bits.h).
class BitWriter {
 public:
  explicit BitWriter(uint8_t* block) : block_(block) {
    for (int i = 0; i < 16; ++i) block_[i] = 0;
  }
  void write(uint32_t value, int bits) {
    for (int i = 0; i < bits; ++i, ++pos_) {
      if ((value >> i) & 1)
        block_[pos_ >> 3] = static_cast<uint8_t>(block_[pos_ >> 3] | (1u << (pos_ & 7)));
    }
  }
  int position() const { return pos_; }

 private:
  uint8_t* block_;
  int pos_ = 0;
};

}  // namespace calf::bc::internal
