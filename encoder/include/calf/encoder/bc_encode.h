// BCn texture block encoders: BC1, BC4, BC5 (through libsquish), BC7 and BC6H (in-house).
//
// The blocks these produce are decoded by calf/format/bc.h (the meaning of the bits) and by any
// GPU. Every encoder here is
//  - deterministic: the same pixels and options give the same bytes, whatever `threads` is;
//  - thread-safe: no global state; any number of calls may run at once;
//  - caller-owned: output goes to a buffer of at least compressed_size() bytes (encode_bound()
//    gives the same number without a Status);
//  - edge-clamping: where width or height is not a multiple of 4, the missing texels of the last
//    block column/row are copies of the nearest edge texel (so the block fits only real colours).
//
// What each encoder searches (docs/BLOCK_CODECS.md has the reasons and measured numbers):
//  - BC1: libsquish. quality 0 = range fit (fast), 1 = cluster fit, 2 = iterative cluster fit;
//    `refine` adds an in-house least-squares endpoint refinement measured with calf's decoder.
//  - BC4/BC5: libsquish's DXT5-alpha fitter per channel (it tries the 8- and 6-level modes);
//    quality 1 adds an in-house refinement that searches endpoint pairs near squish's.
//  - BC7 (quality 0 / 1 / 2):
//        mode 6 (one subset, 7777+p RGBA, 4-bit indices): always — the best single-subset mode
//          for smooth colour, and it carries alpha;
//        opaque blocks: mode 1 (two subsets, 666 + shared p, 3-bit indices) on the best
//          2 / 8 / 64 of the 64 shapes ranked by a principal-axis residual estimate; mode 3 (two
//          subsets, 777+p, 2-bit indices) on the same shapes at q >= 1; at q = 2 also mode 2
//          (three subsets, 555, 2-bit) on the best 16 three-subset shapes and mode 0 (three
//          subsets, 444+p, 3-bit) on those among its 16 shapes;
//        blocks with alpha (q >= 1): mode 5 (colour and alpha fitted apart, rotation 0) and
//          mode 7 (two subsets, 5555+p) on the best 8 / 64 shapes. Modes 4 and the rotations
//          of 5 are never produced (they decode, of course).
//  - BC6H (quality 0 / 1 / 2): error measured on the half-float bit patterns (a piecewise-linear
//    log2 scale, the space BC6H interpolates in):
//        one-region modes 11..14 (D3D numbering; 10-bit plain, 11/12/16-bit with deltas):
//          always; the one with the smallest error wins (deltas that do not fit are clamped,
//          or the mode skipped);
//        two-region modes 1..10 (all ten endpoint precisions) on the best 1 / 4 / 32 of the 32
//          shapes.
//
// HDR inputs (BC6H): NaN, +-Inf, negative values in unsigned BC6H, and magnitudes above 65504
// are either clamped (HdrPolicy::kClamp, default: NaN -> 0, +Inf -> 65504, -Inf -> 0 (unsigned)
// or -65504 (signed), negatives -> 0 (unsigned), |x| > 65504 -> +-65504, as the BPTC spec asks:
// "flush to max half float") or rejected with kBcNonFinite / kBcOutOfRange (HdrPolicy::kReject).
// Tiny positives are rounded to the nearest half (subnormals kept; below 2^-25 they become 0).
#pragma once

#include <cstddef>
#include <cstdint>

#include "calf/format/bc.h"
#include "calf/format/status.h"

namespace calf::bc {

// An 8-bit image: `channels` interleaved bytes per pixel (1..4), rows `row_stride` bytes apart.
// BC1/BC7 read RGB(A) (3 channels: alpha is 255), BC4 reads channel 0, BC5 channels 0 and 1.
struct Image8 {
  const uint8_t* pixels = nullptr;
  uint32_t width = 0, height = 0;
  size_t row_stride = 0;  // bytes
  uint32_t channels = 4;
};

// A float image (linear HDR): 3 (RGB) or 4 (RGBA, alpha ignored) floats per pixel, rows
// `row_stride` floats apart.
struct ImageF {
  const float* pixels = nullptr;
  uint32_t width = 0, height = 0;
  size_t row_stride = 0;  // floats
  uint32_t channels = 3;
};

// `threads` in every options struct: how many threads may encode blocks of one image (1 = the
// calling thread only; 0 = all the machine's cores). The output never depends on it.

struct Bc1Options {
  int quality = 0;  // 0 range fit, 1 cluster fit, 2 iterative cluster fit
  // false (default): alpha is ignored and every block is opaque. true: texels with alpha < 128
  // become transparent black through BC1's 3-colour mode.
  bool punch_through_alpha = false;
  int threads = 1;
  // After the fit: least-squares endpoints for the block's indices, indices chosen again, kept
  // only where calf's decoder shows a smaller RGB error (docs/ENCODER.md "BC1 fit"). Blocks with
  // punched-through alpha are left as fitted.
  bool refine = false;
};

struct Bc4Options {
  int quality = 0;  // 0 libsquish, 1 libsquish + endpoint refinement
  int threads = 1;
};

struct Bc7Options {
  int quality = 1;  // 0 fast, 1 default, 2 slow (see the mode list above)
  int threads = 1;
};

enum class HdrPolicy : uint8_t { kClamp, kReject };

struct Bc6hOptions {
  int quality = 1;         // 0 fast, 1 default, 2 slow
  bool is_signed = false;  // BC6H_SF16 (keeps negatives) instead of BC6H_UF16
  HdrPolicy policy = HdrPolicy::kClamp;
  int threads = 1;
};

// compressed_size(f, width, height) without the Status: 0 for an invalid size.
size_t encode_bound(Format f, uint32_t width, uint32_t height);

// Whole images. Errors: kBcDimensions (size), kBcStride, kBcBufferSize (out too small or null
// pixels), kBcOptions (quality or threads or channels out of range), and for BC6H with
// HdrPolicy::kReject kBcNonFinite / kBcOutOfRange naming the first offending pixel.
Status encode_bc1(const Image8& image, uint8_t* out, size_t out_size, const Bc1Options& options);
Status encode_bc4(const Image8& image, uint8_t* out, size_t out_size, const Bc4Options& options);
Status encode_bc5(const Image8& image, uint8_t* out, size_t out_size, const Bc4Options& options);
Status encode_bc7(const Image8& image, uint8_t* out, size_t out_size, const Bc7Options& options);
Status encode_bc6h(const ImageF& image, uint8_t* out, size_t out_size, const Bc6hOptions& options);

// Single blocks (16 texels row-major). Options are not validated here (quality is clamped).
void encode_bc1_block(const uint8_t* rgba, uint8_t* out8, const Bc1Options& options);
void encode_bc4_block(const uint8_t* r, uint8_t* out8, const Bc4Options& options);
void encode_bc7_block(const uint8_t* rgba, uint8_t* out16, const Bc7Options& options);
// `rgb` holds 16 x 3 floats; specials are clamped as HdrPolicy::kClamp describes.
void encode_bc6h_block(const float* rgb, uint8_t* out16, const Bc6hOptions& options);

// The HDR clamp described above, for one value: the half-float bit pattern BC6H will try to
// reproduce (signed: sign-magnitude; unsigned: never negative).
uint16_t bc6h_clamp_to_half(float v, bool is_signed);

}  // namespace calf::bc
