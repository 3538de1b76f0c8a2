// Rate-distortion pass over coded BC1 / BC6H / BC7 blocks (calf/encoder/bc_rdo.h).
#include "calf/encoder/bc_rdo.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "bc_encode_internal.h"
#include "calf/format/colour.h"

namespace calf::bc {
namespace {

constexpr int kMinRun = 3;         // zstd's shortest match
constexpr double kMatchBits = 24;  // an offset and a length, roughly, in zstd's sequences

// The copied lengths tried, as prefixes (side 0; 16 = the whole block) and suffixes (side 1).
// Measured on mirror-box's BC6H cells at face 64, lambda 0.5 (all lengths 3..16 from 8 previous
// blocks and the 3 above): these were the lengths of 96.5 % of the accepted copies. With the
// window cut to 2 this halves the pass's time for 0.5 % more colour bytes.
constexpr bool kTried[2][17] = {
    {0, 0, 0, 0, 1, 1, 0, 0, 1, 1, 0, 0, 1, 0, 1, 1, 1},
    {0, 0, 0, 0, 1, 1, 1, 1, 1, 1, 1, 1, 1, 0, 0, 1, 0},
};

// One block's target texels, gathered once: `valid` marks those inside the image (an edge
// block's others are not part of it, SPEC §11.1.5).
struct Bc7Target {
  uint8_t v[16][4];
  bool valid[16];
};
struct Bc6hTarget {
  float v[16][3];   // 255 x sRGB-encoded (extended above 1)
  int half[16][3];  // the half-float bit patterns themselves
  bool valid[16];
};

// A candidate may not move any texel further from its target, in half-float ulps (1024 = one
// stop), than the larger of this and the BCn encoder's own block did: the display metric alone
// would turn deep shadows (below ~1/255 after the sRGB curve) into anything dark, and HDR content
// may be shown brighter later.
constexpr int kBc6hGuardUlps = 128;  // 1/8 stop, about 9 %

// Every unsigned half-float bit pattern as 255 times its sRGB-encoded value, the curve extended
// past 1 (1.055 v^(1/2.4) - 0.055, continuous at 1) so that highlights keep a weight, falling as
// the eye's: the display metric of a BC6H block's error (bc_rdo.h).
const std::vector<float>& perceptual_of_half() {
  static const std::vector<float> table = [] {
    std::vector<float> t(65536);
    for (uint32_t h = 0; h < 65536; ++h) {
      const float v = half_to_float(static_cast<uint16_t>(h));
      const float s = !(v > 0.0f) ? 0.0f
                      : v <= 1.0f ? srgb_from_linear(v)
                                  : 1.055f * std::pow(std::min(v, 65504.0f), 1.0f / 2.4f) - 0.055f;
      t[h] = 255.0f * s;
    }
    return t;
  }();
  return table;
}

struct Bc6hCodec {
  using Target = Bc6hTarget;
  static void set(Target& t, int k, int c, uint16_t half) {
    t.v[k][c] = perceptual_of_half()[half];
    t.half[k][c] = half;
  }
  // Squared error of the decoded block; `deviation` gets its largest texel deviation in ulps.
  static double error(const uint8_t* block, const Target& t, int* deviation) {
    uint16_t out[16][3];
    decode_bc6h_block(block, false, &out[0][0]);
    const std::vector<float>& p = perceptual_of_half();
    double e = 0;
    int dev = 0;
    for (int i = 0; i < 16; ++i) {
      if (!t.valid[i]) continue;
      for (int c = 0; c < 3; ++c) {
        const double d = static_cast<double>(p[out[i][c]]) - t.v[i][c];
        e += d * d;
        dev = std::max(dev, std::abs(static_cast<int>(out[i][c]) - t.half[i][c]));
      }
    }
    *deviation = dev;
    return e;
  }
  static int guard(int deviation) { return std::max(deviation, kBc6hGuardUlps); }
};

// Squared error of decoded 8-bit RGBA texels against the target's valid ones (BC7, BC1).
double rgba8_error(const uint8_t (&out)[16][4], const Bc7Target& t) {
  double e = 0;
  for (int i = 0; i < 16; ++i) {
    if (!t.valid[i]) continue;
    for (int c = 0; c < 4; ++c) {
      const double d = static_cast<double>(out[i][c]) - t.v[i][c];
      e += d * d;
    }
  }
  return e;
}

struct Bc7Codec {
  using Target = Bc7Target;
  static void set(Target& t, int k, int c, uint8_t v) { t.v[k][c] = v; }
  static double error(const uint8_t* block, const Target& t, int* deviation) {
    uint8_t out[16][4];
    decode_bc7_block(block, &out[0][0]);
    *deviation = 0;
    return rgba8_error(out, t);
  }
  static int guard(int) { return 0; }  // 8-bit display values: the squared error says it all
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

// The checks every pass makes before touching a block.
Status check_rdo_arguments(const void* target, uint32_t width, uint32_t height,
                           const uint8_t* blocks, size_t blocks_size, const BcRdoOptions& options,
                           Format format) {
  if (!(options.lambda >= 0 && std::isfinite(options.lambda)) || options.window < 1 ||
      options.window > 256) {
    return Status(ErrorId::kBcOptions, std::string(format_name(format)) +
                                           " RDO: lambda must be finite and >= 0, window 1..256");
  }
  CALF_ASSIGN_OR_RETURN(const size_t needed, compressed_size(format, width, height));
  if (target == nullptr || blocks == nullptr || blocks_size < needed) {
    return Status(ErrorId::kBcBufferSize, std::string(format_name(format)) +
                                              " RDO: " + std::to_string(width) + " x " +
                                              std::to_string(height) + " image needs " +
                                              std::to_string(needed) + " block bytes");
  }
  return Status::Ok();
}

// Block (bx, by)'s C-channel target texels through `set(k, c, value)`; `valid[k]` marks those
// inside the image (an edge block's others repeat the edge and do not count).
template <int C, typename T, typename Set>
void gather_target(const T* target, uint32_t width, uint32_t height, uint32_t bx, uint32_t by,
                   bool* valid, Set set) {
  for (int k = 0; k < 16; ++k) {
    const uint32_t x = bx * 4 + k % 4, y = by * 4 + k / 4;
    valid[k] = x < width && y < height;
    const size_t at = (size_t{std::min(y, height - 1)} * width + std::min(x, width - 1)) * C;
    for (int c = 0; c < C; ++c) set(k, c, target[at + c]);
  }
}

// The sources of block i (at bx, by of a row of bw blocks of `block_bytes` each): the previous
// `window` blocks, then the three above that are not among them. A source equal to an earlier one
// offers the same candidates (common once blocks have been copied): it is listed once. Returns
// the count.
int gather_sources(const uint8_t* blocks, size_t block_bytes, size_t i, uint32_t bx, uint32_t by,
                   uint32_t bw, uint32_t window, std::array<const uint8_t*, 256 + 3>& sources) {
  int n = 0;
  auto add_source = [&](const uint8_t* b) {
    for (int s = 0; s < n; ++s)
      if (std::memcmp(sources[s], b, block_bytes) == 0) return;
    sources[n++] = b;
  };
  for (size_t j = 1; j <= window && j <= i; ++j) add_source(blocks + (i - j) * block_bytes);
  if (by > 0) {
    for (int dx = -1; dx <= 1; ++dx) {
      const int64_t x = static_cast<int64_t>(bx) + dx;
      if (x < 0 || x >= bw) continue;
      const size_t j = size_t{by - 1} * bw + static_cast<size_t>(x);
      if (i - j > window) add_source(blocks + j * block_bytes);
    }
  }
  return n;
}

void add_stats(const BcRdoStats& local, BcRdoStats* stats) {
  if (stats == nullptr) return;
  stats->blocks += local.blocks;
  stats->changed += local.changed;
  stats->error_before += local.error_before;
  stats->error_after += local.error_after;
}

template <typename Codec, typename T, int C>
Status rdo_image(const T* target, uint32_t width, uint32_t height, uint8_t* blocks,
                 size_t blocks_size, const BcRdoOptions& options, BcRdoStats* stats,
                 Format format) {
  CALF_RETURN_IF_ERROR(
      check_rdo_arguments(target, width, height, blocks, blocks_size, options, format));
  BcRdoStats local;
  const uint32_t bw = blocks_along(width), bh = blocks_along(height);
  const size_t count = size_t{bw} * bh;
  const double lambda = options.lambda;
  for (size_t i = 0; i < count; ++i) {
    const uint32_t bx = static_cast<uint32_t>(i % bw), by = static_cast<uint32_t>(i / bw);
    typename Codec::Target t;
    gather_target<C>(target, width, height, bx, by, t.valid,
                     [&t](int k, int c, T v) { Codec::set(t, k, c, v); });
    uint8_t* block = blocks + i * 16;
    std::array<const uint8_t*, 256 + 3> sources;
    const int n = gather_sources(blocks, 16, i, bx, by, bw, options.window, sources);
    int deviation = 0;
    const double d0 = Codec::error(block, t, &deviation);
    const int limit = Codec::guard(deviation);
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
    for (int len = 16; len >= 4; --len) {
      if (lambda * (8.0 * (16 - len) + kMatchBits) >= best_j) break;
      for (int s = 0; s < n; ++s) {
        for (int side = 0; side < (len == 16 ? 1 : 2); ++side) {
          if (!kTried[side][len]) continue;
          std::memcpy(cand, block, 16);
          const int from = side == 0 ? 0 : 16 - len;  // prefix, then suffix
          std::memcpy(cand + from, sources[s] + from, static_cast<size_t>(len));
          if (std::memcmp(cand, block, 16) == 0 || std::memcmp(cand, best, 16) == 0) continue;
          const double r = rate_bits(cand, sources.data(), n);
          if (lambda * r >= best_j) continue;
          const double d = Codec::error(cand, t, &deviation);
          if (deviation > limit) continue;
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
  add_stats(local, stats);
  return Status::Ok();
}

// ---- BC1 ----
//
// calf stores BC1 block-split (SPEC §7): a chunk's 4-byte endpoint halves, then its 4-byte index
// halves. So each half of a block is its own LZ symbol: it repeats the half of the block before
// it (offset 4 in its plane; where that block did the same, zstd is extending one match and the
// half costs almost nothing), repeats the half of another source block (a new match), or is
// literal. Candidates per source: the whole block, the source's endpoints with indices re-chosen
// for them (the nearest of their four colours, texel by texel), and the source's indices with the
// block's own endpoints.
constexpr double kBc1LiteralBits = 32;  // 4 literal bytes
constexpr double kBc1MatchBits = 20;    // a new match: offset and length
constexpr double kBc1RunBits = 2;       // the same match, four bytes longer

// Estimated LZ bits of the half at byte `side` (0: endpoints, 4: indices) of candidate `c` for
// block i, given the final blocks before it and the sources.
double bc1_half_bits(const uint8_t* c, int side, const uint8_t* blocks, size_t i,
                     const uint8_t* const* sources, int count) {
  const uint8_t* half = c + side;
  if (i >= 1 && std::memcmp(half, blocks + (i - 1) * 8 + side, 4) == 0) {
    const bool run =
        i >= 2 && std::memcmp(blocks + (i - 1) * 8 + side, blocks + (i - 2) * 8 + side, 4) == 0;
    return run ? kBc1RunBits : kBc1MatchBits;
  }
  for (int s = 0; s < count; ++s) {
    if (std::memcmp(half, sources[s] + side, 4) == 0) return kBc1MatchBits;
  }
  return kBc1LiteralBits;
}

// Squared 8-bit RGBA error of a BC1 block against the target texels.
double bc1_error(const uint8_t* block, const Bc7Target& t) {
  uint8_t out[16][4];
  decode_bc1_block(block, &out[0][0]);
  return rgba8_error(out, t);
}

}  // namespace

Status rdo_bc1(const uint8_t* target, uint32_t width, uint32_t height, uint8_t* blocks,
               size_t blocks_size, const BcRdoOptions& options, BcRdoStats* stats) {
  CALF_RETURN_IF_ERROR(
      check_rdo_arguments(target, width, height, blocks, blocks_size, options, Format::kBc1));
  BcRdoStats local;
  const uint32_t bw = blocks_along(width), bh = blocks_along(height);
  const size_t count = size_t{bw} * bh;
  const double lambda = options.lambda;
  for (size_t i = 0; i < count; ++i) {
    const uint32_t bx = static_cast<uint32_t>(i % bw), by = static_cast<uint32_t>(i / bw);
    Bc7Target t;
    gather_target<4>(target, width, height, bx, by, t.valid,
                     [&t](int k, int c, uint8_t v) { t.v[k][c] = v; });
    uint8_t* block = blocks + i * 8;
    std::array<const uint8_t*, 256 + 3> sources;
    const int n = gather_sources(blocks, 8, i, bx, by, bw, options.window, sources);
    const double d0 = bc1_error(block, t);
    local.blocks += 1;
    local.error_before += d0;
    if (lambda == 0 || n == 0) {
      local.error_after += d0;
      continue;
    }
    auto rate = [&](const uint8_t* c) {
      return bc1_half_bits(c, 0, blocks, i, sources.data(), n) +
             bc1_half_bits(c, 4, blocks, i, sources.data(), n);
    };
    uint8_t best[8];
    std::memcpy(best, block, 8);
    double best_d = d0, best_j = d0 + lambda * rate(block);
    auto consider = [&](const uint8_t* cand) {
      if (std::memcmp(cand, best, 8) == 0) return;
      const double r = rate(cand);
      if (lambda * r >= best_j) return;
      const double d = bc1_error(cand, t);
      if (d + lambda * r < best_j) {
        best_j = d + lambda * r;
        best_d = d;
        std::memcpy(best, cand, 8);
      }
    };
    for (int s = 0; s < n; ++s) {
      uint8_t cand[8];
      consider(sources[s]);  // the whole block
      std::memcpy(cand, sources[s], 4);
      std::memcpy(cand + 4, block + 4, 4);
      internal::bc1_choose_indices(cand, &t.v[0][0]);
      consider(cand);  // its endpoints, indices re-chosen
      std::memcpy(cand, block, 4);
      std::memcpy(cand + 4, sources[s] + 4, 4);
      consider(cand);  // its indices, own endpoints
    }
    if (std::memcmp(best, block, 8) != 0) {
      std::memcpy(block, best, 8);
      local.changed += 1;
    }
    local.error_after += best_d;
  }
  add_stats(local, stats);
  return Status::Ok();
}

Status rdo_bc6h(const uint16_t* target, uint32_t width, uint32_t height, uint8_t* blocks,
                size_t blocks_size, const BcRdoOptions& options, BcRdoStats* stats) {
  return rdo_image<Bc6hCodec, uint16_t, 3>(target, width, height, blocks, blocks_size, options,
                                           stats, Format::kBc6hUnsigned);
}

Status rdo_bc7(const uint8_t* target, uint32_t width, uint32_t height, uint8_t* blocks,
               size_t blocks_size, const BcRdoOptions& options, BcRdoStats* stats) {
  return rdo_image<Bc7Codec, uint8_t, 4>(target, width, height, blocks, blocks_size, options, stats,
                                         Format::kBc7);
}

}  // namespace calf::bc
