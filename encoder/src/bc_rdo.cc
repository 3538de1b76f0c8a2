// Rate-distortion pass over coded BC6H / BC7 blocks (calf/encoder/bc_rdo.h).
#include "calf/encoder/bc_rdo.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "calf/format/colour.h"

namespace calf::bc {
namespace {

constexpr int kMinRun = 3;        // zstd's shortest match
constexpr double kMatchBits = 24;  // an offset and a length, roughly, in zstd's sequences

// One block's target texels, gathered once: `valid` marks those inside the image (an edge
// block's others are not part of it, SPEC §11.1.5).
template <typename T, int C>
struct BlockTarget {
  T v[16][C];
  bool valid[16];
};

// Every unsigned half-float bit pattern as 255 times its sRGB-encoded value, the curve extended
// past 1 (1.055 v^(1/2.4) - 0.055, continuous at 1) so that highlights keep a weight, falling as
// the eye's: the display metric of a BC6H block's error (bc_rdo.h).
const std::vector<float>& perceptual_of_half() {
  static const std::vector<float> table = [] {
    std::vector<float> t(65536);
    for (uint32_t h = 0; h < 65536; ++h) {
      const float v = half_to_float(static_cast<uint16_t>(h));
      const float s = !(v > 0.0f)   ? 0.0f
                      : v <= 1.0f ? srgb_from_linear(v)
                                  : 1.055f * std::pow(std::min(v, 65504.0f), 1.0f / 2.4f) - 0.055f;
      t[h] = 255.0f * s;
    }
    return t;
  }();
  return table;
}

// Squared error of a decoded block against its target.
double block_error(const uint16_t (*half)[3], const BlockTarget<float, 3>& t) {
  const std::vector<float>& p = perceptual_of_half();
  double e = 0;
  for (int i = 0; i < 16; ++i) {
    if (!t.valid[i]) continue;
    for (int c = 0; c < 3; ++c) {
      const double d = static_cast<double>(p[half[i][c]]) - t.v[i][c];
      e += d * d;
    }
  }
  return e;
}
double block_error(const uint8_t (*rgba)[4], const BlockTarget<uint8_t, 4>& t) {
  double e = 0;
  for (int i = 0; i < 16; ++i) {
    if (!t.valid[i]) continue;
    for (int c = 0; c < 4; ++c) {
      const double d = static_cast<double>(rgba[i][c]) - t.v[i][c];
      e += d * d;
    }
  }
  return e;
}

struct Bc6hCodec {
  using Target = BlockTarget<float, 3>;
  static float target_value(uint16_t half) { return perceptual_of_half()[half]; }
  static double error(const uint8_t* block, const Target& t) {
    uint16_t out[16][3];
    decode_bc6h_block(block, false, &out[0][0]);
    return block_error(out, t);
  }
};
struct Bc7Codec {
  using Target = BlockTarget<uint8_t, 4>;
  static uint8_t target_value(uint8_t v) { return v; }
  static double error(const uint8_t* block, const Target& t) {
    uint8_t out[16][4];
    decode_bc7_block(block, &out[0][0]);
    return block_error(out, t);
  }
};

// Estimated LZ bits of `c` given the source blocks: the longest run of bytes it shares, at the
// same offsets, with one of them (a match), the rest as literals.
double rate_bits(const uint8_t* c, const uint8_t* const* sources, int count) {
  int best = 0;
  for (int s = 0; s < count && best < 16; ++s) {
    const uint8_t* b = sources[s];
    int run = 0;
    for (int k = 0; k < 16; ++k) {
      run = c[k] == b[k] ? run + 1 : 0;
      best = std::max(best, run);
    }
  }
  if (best < kMinRun) return 128;
  return 8.0 * (16 - best) + kMatchBits;
}

template <typename Codec, typename T, int C>
Status rdo_image(const T* target, uint32_t width, uint32_t height, uint8_t* blocks,
                 size_t blocks_size, const BcRdoOptions& options, BcRdoStats* stats,
                 Format format) {
  if (!(options.lambda >= 0 && std::isfinite(options.lambda)) || options.window < 1 ||
      options.window > 256) {
    return Status(ErrorId::kBcOptions, std::string(format_name(format)) +
                                           " RDO: lambda must be finite and >= 0, window 1..256");
  }
  CALF_ASSIGN_OR_RETURN(const size_t needed, compressed_size(format, width, height));
  if (target == nullptr || blocks == nullptr || blocks_size < needed) {
    return Status(ErrorId::kBcBufferSize, std::string(format_name(format)) + " RDO: " +
                                              std::to_string(width) + " x " +
                                              std::to_string(height) + " image needs " +
                                              std::to_string(needed) + " block bytes");
  }
  BcRdoStats local;
  const uint32_t bw = blocks_along(width), bh = blocks_along(height);
  const size_t count = size_t{bw} * bh;
  const double lambda = options.lambda;
  for (size_t i = 0; i < count; ++i) {
    const uint32_t bx = static_cast<uint32_t>(i % bw), by = static_cast<uint32_t>(i / bw);
    typename Codec::Target t;
    for (int k = 0; k < 16; ++k) {
      const uint32_t x = bx * 4 + k % 4, y = by * 4 + k / 4;
      t.valid[k] = x < width && y < height;
      const size_t at = (size_t{std::min(y, height - 1)} * width + std::min(x, width - 1)) * C;
      for (int c = 0; c < C; ++c) t.v[k][c] = Codec::target_value(target[at + c]);
    }
    uint8_t* block = blocks + i * 16;
    // Sources: the previous `window` blocks, then the three above that are not among them.
    std::array<const uint8_t*, 256 + 3> sources;
    int n = 0;
    for (size_t j = 1; j <= options.window && j <= i; ++j) sources[n++] = blocks + (i - j) * 16;
    if (by > 0) {
      for (int dx = -1; dx <= 1; ++dx) {
        const int64_t x = static_cast<int64_t>(bx) + dx;
        if (x < 0 || x >= bw) continue;
        const size_t j = size_t{by - 1} * bw + static_cast<size_t>(x);
        if (i - j > options.window) sources[n++] = blocks + j * 16;
      }
    }
    const double d0 = Codec::error(block, t);
    local.blocks += 1;
    local.error_before += d0;
    if (lambda == 0 || n == 0) {
      local.error_after += d0;
      continue;
    }
    uint8_t best[16];
    std::memcpy(best, block, 16);
    double best_d = d0;
    double best_j = d0 + lambda * rate_bits(block, sources.data(), n);
    uint8_t cand[16];
    // Candidates by decreasing copied length, so that their rate (at least 8 bits per byte not
    // copied) only grows: once lambda times that floor reaches the best cost, nothing later wins.
    for (int len = 16; len >= kMinRun; --len) {
      if (lambda * (8.0 * (16 - len) + kMatchBits) >= best_j) break;
      for (int s = 0; s < n; ++s) {
        for (int side = 0; side < (len == 16 ? 1 : 2); ++side) {
          std::memcpy(cand, block, 16);
          const int from = side == 0 ? 0 : 16 - len;  // prefix, then suffix
          std::memcpy(cand + from, sources[s] + from, static_cast<size_t>(len));
          if (std::memcmp(cand, block, 16) == 0 || std::memcmp(cand, best, 16) == 0) continue;
          const double r = rate_bits(cand, sources.data(), n);
          if (lambda * r >= best_j) continue;
          const double d = Codec::error(cand, t);
          const double j = d + lambda * r;
          if (j < best_j) {
            best_j = j;
            best_d = d;
            std::memcpy(best, cand, 16);
          }
        }
      }
    }
    if (std::memcmp(best, block, 16) != 0) {
      std::memcpy(block, best, 16);
      local.changed += 1;
    }
    local.error_after += best_d;
  }
  if (stats != nullptr) {
    stats->blocks += local.blocks;
    stats->changed += local.changed;
    stats->error_before += local.error_before;
    stats->error_after += local.error_after;
  }
  return Status::Ok();
}

}  // namespace

Status rdo_bc6h(const uint16_t* target, uint32_t width, uint32_t height, uint8_t* blocks,
                size_t blocks_size, const BcRdoOptions& options, BcRdoStats* stats) {
  return rdo_image<Bc6hCodec, uint16_t, 3>(target, width, height, blocks, blocks_size, options,
                                           stats, Format::kBc6hUnsigned);
}

Status rdo_bc7(const uint8_t* target, uint32_t width, uint32_t height, uint8_t* blocks,
               size_t blocks_size, const BcRdoOptions& options, BcRdoStats* stats) {
  return rdo_image<Bc7Codec, uint8_t, 4>(target, width, height, blocks, blocks_size, options,
                                         stats, Format::kBc7);
}

}  // namespace calf::bc
