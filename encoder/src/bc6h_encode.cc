// BC6H encoder. Works in the space the format interpolates in: the decoder's output is
// finish(interp(unq0, unq1, w)) where finish scales by 31/64 (unsigned) or 31/32 (signed) into
// half-float bit patterns. So texels are targets t = their half bits (as a signed integer for
// BC6H_SF16), endpoints are fitted against u = t * 64/31 (resp. 32/31), and errors are squared
// differences of half bit patterns — a piecewise-linear log2 scale, i.e. relative error, which
// is what HDR content needs (an error of 1 = one half-float ulp).
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "bc_encode_internal.h"
#include "calf/format/bc_tables.h"

namespace calf::bc {
namespace {

using internal::BitWriter;

// Decoded value (as target-space integer) of an interpolated unquantised value.
int finish(int v, bool is_signed) {
  if (!is_signed) return (v * 31) >> 6;
  return v < 0 ? -(((-v) * 31) >> 5) : (v * 31) >> 5;
}

int min_q(int bits, bool is_signed) {
  return is_signed ? -((1 << (bits - 1)) - 1) : 0;
}
int max_q(int bits, bool is_signed) {
  return is_signed ? (1 << (bits - 1)) - 1 : (1 << bits) - 1;
}

// Nearest endpoint value of `bits` precision to the unquantised target u.
int quantize(float u, int bits, bool is_signed) {
  const int lo = min_q(bits, is_signed), hi = max_q(bits, is_signed);
  const float scale = is_signed ? static_cast<float>(1 << (bits - 1)) / 32768.0f
                                : static_cast<float>(1 << bits) / 65536.0f;
  const int q0 = std::clamp(static_cast<int>(std::floor(u * scale)), lo, hi);
  int best = q0;
  float best_d = std::numeric_limits<float>::max();
  for (int q = std::max(lo, q0 - 1); q <= std::min(hi, q0 + 1); ++q) {
    const float d = std::fabs(static_cast<float>(bc6h_unquantize(q, bits, is_signed)) - u);
    if (d < best_d) best_d = d, best = q;
  }
  return best;
}

struct Texels {
  int t[16][3];    // targets: half bits (signed: sign-magnitude as a signed int)
  float u[16][3];  // the same in the unquantised endpoint domain
  bool is_signed;
};

// Endpoints of one region in the unquantised domain (floats), by principal axis extremes.
void fit_line(const Texels& tx, const int* members, int count, float (*ep)[3]) {
  float mean[3] = {}, cov[3][3] = {};
  for (int m = 0; m < count; ++m)
    for (int c = 0; c < 3; ++c) mean[c] += tx.u[members[m]][c];
  for (int c = 0; c < 3; ++c) mean[c] /= static_cast<float>(count);
  for (int m = 0; m < count; ++m)
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b)
        cov[a][b] += (tx.u[members[m]][a] - mean[a]) * (tx.u[members[m]][b] - mean[b]);
  float axis[3];
  for (int c = 0; c < 3; ++c) axis[c] = cov[c][c] + 1e-3f;
  for (int it = 0; it < 8; ++it) {
    float next[3] = {}, norm = 0;
    for (int a = 0; a < 3; ++a) {
      for (int b = 0; b < 3; ++b) next[a] += cov[a][b] * axis[b];
      norm = std::max(norm, std::fabs(next[a]));
    }
    if (norm < 1e-12f) break;
    for (int c = 0; c < 3; ++c) axis[c] = next[c] / norm;
  }
  const float len2 = axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2];
  float tmin = 0, tmax = 0;
  for (int m = 0; m < count; ++m) {
    float t = 0;
    for (int c = 0; c < 3; ++c) t += (tx.u[members[m]][c] - mean[c]) * axis[c];
    tmin = std::min(tmin, t / len2);
    tmax = std::max(tmax, t / len2);
  }
  for (int c = 0; c < 3; ++c) {
    ep[0][c] = mean[c] + axis[c] * tmin;
    ep[1][c] = mean[c] + axis[c] * tmax;
  }
}

// One region's quantised endpoints, indices and error.
struct RegionFit {
  int q[2][3];
  uint8_t index[16];
  long err;
};

long assign(const Texels& tx, const int* members, int count, int bits, int index_bits,
            RegionFit& f) {
  const int n = 1 << index_bits;
  const uint8_t* w = weights_for_bits(index_bits);
  int e[2][3], pal[16][3];
  for (int j = 0; j < 2; ++j)
    for (int c = 0; c < 3; ++c) e[j][c] = bc6h_unquantize(f.q[j][c], bits, tx.is_signed);
  for (int k = 0; k < n; ++k)
    for (int c = 0; c < 3; ++c)
      pal[k][c] = finish((e[0][c] * (64 - w[k]) + e[1][c] * w[k] + 32) >> 6, tx.is_signed);
  long total = 0;
  for (int m = 0; m < count; ++m) {
    const int* t = tx.t[members[m]];
    long best_e = std::numeric_limits<long>::max();
    int best = 0;
    for (int k = 0; k < n; ++k) {
      long d = 0;
      for (int c = 0; c < 3; ++c) d += long{pal[k][c] - t[c]} * (pal[k][c] - t[c]);
      if (d < best_e) best_e = d, best = k;
    }
    f.index[members[m]] = static_cast<uint8_t>(best);
    total += best_e;
  }
  f.err = total;
  return total;
}

// Quantises float endpoints, assigns indices, then refines once by least squares.
RegionFit fit_region(const Texels& tx, const int* members, int count, const float (*ep)[3],
                     int bits, int index_bits, int refinements) {
  RegionFit f;
  for (int j = 0; j < 2; ++j)
    for (int c = 0; c < 3; ++c) f.q[j][c] = quantize(ep[j][c], bits, tx.is_signed);
  assign(tx, members, count, bits, index_bits, f);
  const uint8_t* w = weights_for_bits(index_bits);
  for (int r = 0; r < refinements && f.err > 0; ++r) {
    float aa = 0, ab = 0, bb = 0, ax[3] = {}, bx[3] = {};
    for (int m = 0; m < count; ++m) {
      const float t = w[f.index[members[m]]] / 64.0f, s = 1.0f - t;
      aa += s * s, ab += s * t, bb += t * t;
      for (int c = 0; c < 3; ++c)
        ax[c] += s * tx.u[members[m]][c], bx[c] += t * tx.u[members[m]][c];
    }
    const float det = aa * bb - ab * ab;
    if (std::fabs(det) < 1e-6f) break;
    RegionFit g;
    for (int c = 0; c < 3; ++c) {
      g.q[0][c] = quantize((ax[c] * bb - bx[c] * ab) / det, bits, tx.is_signed);
      g.q[1][c] = quantize((bx[c] * aa - ax[c] * ab) / det, bits, tx.is_signed);
    }
    if (assign(tx, members, count, bits, index_bits, g) >= f.err) break;
    f = g;
  }
  return f;
}

struct Candidate {
  uint8_t block[16] = {};
  long err = std::numeric_limits<long>::max();
};

// Encodes with mode k and shape `partition` given per-region float endpoints: quantise, orient
// anchors, check that transformed (delta) endpoints fit, pack. A delta that does not fit is
// clamped and the indices recomputed; if that breaks an anchor the mode is skipped.
void try_mode(int k, int partition, const Texels& tx, const float (*ep)[2][3], int refinements,
              Candidate& best) {
  const Bc6hMode& mode = kBc6hModes[k];
  const int regions = mode.partition_bits ? 2 : 1;
  const int ib = regions == 2 ? 3 : 4, top = (1 << ib) - 1;
  const int eb = mode.endpoint_bits;
  int members[2][16], count[2] = {0, 0};
  for (int i = 0; i < 16; ++i) {
    const int s = subset_of(regions, partition, i);
    members[s][count[s]++] = i;
  }
  RegionFit fit[2];
  long err = 0;
  for (int s = 0; s < regions; ++s) {
    fit[s] = fit_region(tx, members[s], count[s], ep[s], eb, ib, refinements);
    err += fit[s].err;
    if (err >= best.err) return;
  }
  for (int attempt = 0; attempt < 2; ++attempt) {
    // Orient each region so that its anchor texel's index is < half (mirror the indices).
    for (int s = 0; s < regions; ++s) {
      if (fit[s].index[anchor_of(regions, partition, s)] <= top / 2) continue;
      std::swap(fit[s].q[0], fit[s].q[1]);
      for (int m = 0; m < count[s]; ++m)
        fit[s].index[members[s][m]] = static_cast<uint8_t>(top - fit[s].index[members[s][m]]);
    }
    if (!mode.transformed) break;
    bool fits = true;
    for (int e = 1; e < 2 * regions; ++e) {
      for (int c = 0; c < 3; ++c) {
        const int lim = 1 << (mode.delta_bits[c] - 1);
        int& v = fit[e / 2].q[e % 2][c];
        const int d = v - fit[0].q[0][c];
        if (d < -lim || d > lim - 1) {
          fits = false;
          v = fit[0].q[0][c] + std::clamp(d, -lim, lim - 1);
        }
      }
    }
    if (fits) break;
    if (attempt == 1) return;  // still does not fit after clamping: skip this mode
    err = 0;
    for (int s = 0; s < regions; ++s) err += assign(tx, members[s], count[s], eb, ib, fit[s]);
    if (err >= best.err) return;
    // Loop once more: re-orient (which may move e0 and change the deltas) and re-check.
  }
  if (mode.transformed) {
    // An anchor re-orientation in the last pass could have broken a delta: verify.
    for (int e = 1; e < 2 * regions; ++e)
      for (int c = 0; c < 3; ++c) {
        const int lim = 1 << (mode.delta_bits[c] - 1);
        const int d = fit[e / 2].q[e % 2][c] - fit[0].q[0][c];
        if (d < -lim || d > lim - 1) return;
      }
  }
  // Variables of Table.F: e0 as stored, the others as deltas (transformed) or values.
  int var[14] = {};
  for (int e = 0; e < 2 * regions; ++e) {
    for (int c = 0; c < 3; ++c) {
      const int v = fit[e / 2].q[e % 2][c];
      const int bits = (e == 0 || !mode.transformed) ? eb : mode.delta_bits[c];
      const int stored = (e == 0 || !mode.transformed) ? v : v - fit[0].q[0][c];
      var[3 * e + c] = stored & ((1 << bits) - 1);
    }
  }
  var[kBc6hModeVar] = mode.mode_value;
  var[kBc6hPartitionVar] = partition;
  Candidate c;
  c.err = err;
  BitWriter bw(c.block);
  const Bc6hLayout& layout = kBc6hLayouts[k];
  for (int i = 0; i < layout.count; ++i)
    bw.write(static_cast<uint32_t>(var[layout.field[i].var] >> layout.field[i].bit) & 1u, 1);
  for (int i = 0; i < 16; ++i) {
    const int s = subset_of(regions, partition, i);
    bw.write(fit[s].index[i], ib - (is_anchor(regions, partition, i) ? 1 : 0));
  }
  best = c;
}

// Residual of a line fit per region (as in the BC7 encoder), to rank the 32 two-region shapes.
float shape_estimate(const Texels& tx, int partition) {
  float total = 0;
  for (int s = 0; s < 2; ++s) {
    float mean[3] = {}, cov[3][3] = {};
    int n = 0;
    for (int i = 0; i < 16; ++i)
      if (kPartition2[partition][i] == s) {
        ++n;
        for (int c = 0; c < 3; ++c) mean[c] += tx.u[i][c];
      }
    for (int c = 0; c < 3; ++c) mean[c] /= static_cast<float>(n);
    for (int i = 0; i < 16; ++i)
      if (kPartition2[partition][i] == s)
        for (int a = 0; a < 3; ++a)
          for (int b = 0; b < 3; ++b) cov[a][b] += (tx.u[i][a] - mean[a]) * (tx.u[i][b] - mean[b]);
    float v[3] = {1, 1, 1}, lambda = 0;
    for (int it = 0; it < 4; ++it) {
      float next[3] = {}, norm2 = 0;
      for (int a = 0; a < 3; ++a) {
        for (int b = 0; b < 3; ++b) next[a] += cov[a][b] * v[b];
        norm2 += next[a] * next[a];
      }
      if (norm2 < 1e-12f) break;
      const float norm = std::sqrt(norm2);
      lambda = norm / std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
      for (int c = 0; c < 3; ++c) v[c] = next[c] / norm;
    }
    total += cov[0][0] + cov[1][1] + cov[2][2] - lambda;
  }
  return total;
}

}  // namespace

uint16_t bc6h_clamp_to_half(float v, bool is_signed) {
  if (std::isnan(v)) return 0;
  if (!is_signed && v < 0) return 0;  // -Inf and negatives
  const float m = std::min(std::fabs(v), 65504.0f);
  const uint16_t h = float_to_half(m);  // <= 0x7bff: 65504 is exact
  return static_cast<uint16_t>(v < 0 ? (h | 0x8000) : h);
}

void encode_bc6h_block(const float* rgb, uint8_t* out16, const Bc6hOptions& options) {
  const int q = std::clamp(options.quality, 0, 2);
  Texels tx;
  tx.is_signed = options.is_signed;
  for (int i = 0; i < 16; ++i) {
    for (int c = 0; c < 3; ++c) {
      const uint16_t h = bc6h_clamp_to_half(rgb[3 * i + c], tx.is_signed);
      const int t = (h & 0x8000) ? -(h & 0x7fff) : h;
      tx.t[i][c] = t;
      tx.u[i][c] = static_cast<float>(t) * (tx.is_signed ? 32.0f : 64.0f) / 31.0f;
    }
  }
  const int refinements = q == 0 ? 1 : 2;
  Candidate best;
  // One region: D3D modes 11 (10 bit), 12 (11 bit + 9-bit delta), 13 (12 + 8), 14 (16 + 4).
  {
    int all[16];
    for (int i = 0; i < 16; ++i) all[i] = i;
    float ep[2][2][3];
    fit_line(tx, all, 16, ep[0]);
    for (int k = 10; k < 14 && best.err > 0; ++k) try_mode(k, 0, tx, ep, refinements, best);
  }
  // Two regions: all ten endpoint precisions on the best-ranked shapes.
  static constexpr int kShapes[3] = {1, 4, 32};
  if (best.err > 0) {
    float score[32];
    int order[32];
    for (int p = 0; p < 32; ++p) score[p] = shape_estimate(tx, p), order[p] = p;
    const int keep = kShapes[q];
    std::partial_sort(order, order + keep, order + 32, [&](int a, int b) {
      return score[a] < score[b] || (score[a] == score[b] && a < b);
    });
    for (int n = 0; n < keep && best.err > 0; ++n) {
      const int p = order[n];
      float ep[2][2][3];
      for (int s = 0; s < 2; ++s) {
        int members[16], count = 0;
        for (int i = 0; i < 16; ++i)
          if (kPartition2[p][i] == s) members[count++] = i;
        fit_line(tx, members, count, ep[s]);
      }
      for (int k = 0; k < 10 && best.err > 0; ++k) try_mode(k, p, tx, ep, refinements, best);
    }
  }
  std::memcpy(out16, best.block, 16);
}

Status encode_bc6h(const ImageF& image, uint8_t* out, size_t out_size, const Bc6hOptions& options) {
  const Format f = options.is_signed ? Format::kBc6hSigned : Format::kBc6hUnsigned;
  CALF_RETURN_IF_ERROR(internal::check_image(f, image.pixels, image.width, image.height,
                                             image.row_stride, 4, image.channels, 3, 4, out_size,
                                             options.quality, 2, options.threads));
  if (options.policy == HdrPolicy::kReject) {
    for (uint32_t y = 0; y < image.height; ++y) {
      for (uint32_t x = 0; x < image.width; ++x) {
        for (int c = 0; c < 3; ++c) {
          const float v = image.pixels[y * image.row_stride + size_t{x} * image.channels + c];
          auto where = [&] {
            return std::string(format_name(f)) + " encoder: pixel (" + std::to_string(x) + ", " +
                   std::to_string(y) + ") channel " + std::to_string(c) + " is " +
                   std::to_string(v);
          };
          if (!std::isfinite(v)) {
            return Status(ErrorId::kBcNonFinite, where());
          }
          if ((!options.is_signed && v < 0) || std::fabs(v) > 65504.0f) {
            return Status(
                ErrorId::kBcOutOfRange,
                where() + ", expected " + (options.is_signed ? "-65504" : "0") + "..65504");
          }
        }
      }
    }
  }
  internal::for_each_block(image.width, image.height, options.threads, out, 16,
                           [&](uint32_t bx, uint32_t by, uint8_t* block) {
                             float px[48];
                             internal::gatherf(image, bx, by, px);
                             encode_bc6h_block(px, block, options);
                           });
  return Status::Ok();
}

}  // namespace calf::bc
