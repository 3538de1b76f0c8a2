// BC7 encoder: principal-axis endpoint fit, p-bit search, exact index assignment against the
// decoder's palette, one or two least-squares refinements, partition shapes ranked by a cheap
// residual estimate. Which modes run at which quality is documented in bc_encode.h.
//
// Errors are plain squared RGBA errors on 8-bit values, computed with exactly the arithmetic of
// calf/format/bc.h's decoder, so the block chosen is the one that decodes best.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "bc_encode_internal.h"
#include "calf/format/bc_tables.h"

namespace calf::bc {
namespace {

using internal::BitWriter;

// What one subset fit needs to know about a mode's endpoints and indices.
struct FitSpec {
  int c_begin, c_end;  // channels fitted together: [0,3) RGB, [0,4) RGBA, [3,4) alpha
  int bits;            // stored bits per channel, p-bit excluded
  int pbits;           // 0 none, 1 one per endpoint, 2 one shared by the subset's two endpoints
  int index_bits;
};

struct SubsetFit {
  int q[2][4] = {};  // stored endpoint values (without p-bit)
  int p[2] = {};     // p-bits
  int e[2][4] = {};  // decoded 8-bit endpoints
  uint8_t index[16] = {};
  long err = std::numeric_limits<long>::max();
};

int unquantize(int v, int bits) {
  v <<= 8 - bits;
  return v | (v >> bits);
}

// Decoded 8-bit value of stored `q` with p-bit `p` (ignored when the spec has none).
int decode_value(const FitSpec& s, int q, int p) {
  return s.pbits ? unquantize(q << 1 | p, s.bits + 1) : unquantize(q, s.bits);
}

// Nearest stored value to the 8-bit target v for p-bit p.
int quantize_value(const FitSpec& s, float v, int p) {
  const int total = s.bits + (s.pbits ? 1 : 0);
  const int max_q = (1 << s.bits) - 1;
  float guess = v * static_cast<float>((1 << total) - 1) / 255.0f;
  if (s.pbits) guess = (guess - static_cast<float>(p)) * 0.5f;
  const int q0 = std::clamp(static_cast<int>(std::lround(guess)), 0, max_q);
  int best = q0, best_d = 1 << 30;
  for (int q = std::max(0, q0 - 1); q <= std::min(max_q, q0 + 1); ++q) {
    const int d = std::abs(decode_value(s, q, p) - static_cast<int>(std::lround(v)));
    if (d < best_d) best_d = d, best = q;
  }
  return best;
}

// Assigns every member its best index for decoded endpoints f.e; returns the squared error.
long assign_indices(const FitSpec& s, const int (*px)[4], const int* members, int count,
                    SubsetFit& f) {
  const int n = 1 << s.index_bits;
  const uint8_t* w = weights_for_bits(s.index_bits);
  int pal[16][4];
  for (int k = 0; k < n; ++k)
    for (int c = s.c_begin; c < s.c_end; ++c)
      pal[k][c] = ((64 - w[k]) * f.e[0][c] + w[k] * f.e[1][c] + 32) >> 6;
  long total = 0;
  for (int m = 0; m < count; ++m) {
    const int* x = px[members[m]];
    int best = 0, best_e = std::numeric_limits<int>::max();
    for (int k = 0; k < n; ++k) {
      int e = 0;
      for (int c = s.c_begin; c < s.c_end; ++c) e += (pal[k][c] - x[c]) * (pal[k][c] - x[c]);
      if (e < best_e) best_e = e, best = k;
    }
    f.index[members[m]] = static_cast<uint8_t>(best);
    total += best_e;
  }
  return total;
}

// Quantises float endpoints `ep` trying every p-bit combination; keeps the best in `best`.
void quantize_and_score(const FitSpec& s, const float (*ep)[4], const int (*px)[4],
                        const int* members, int count, SubsetFit& best) {
  const int combos = s.pbits == 1 ? 4 : s.pbits == 2 ? 2 : 1;
  for (int combo = 0; combo < combos; ++combo) {
    SubsetFit f;
    f.p[0] = s.pbits == 1 ? (combo & 1) : combo;
    f.p[1] = s.pbits == 1 ? (combo >> 1) : combo;
    for (int j = 0; j < 2; ++j) {
      for (int c = s.c_begin; c < s.c_end; ++c) {
        f.q[j][c] = quantize_value(s, ep[j][c], f.p[j]);
        f.e[j][c] = decode_value(s, f.q[j][c], f.p[j]);
      }
    }
    f.err = assign_indices(s, px, members, count, f);
    if (f.err < best.err) best = f;
  }
}

// Fits one subset: principal axis -> extreme projections -> quantise -> least-squares refine.
SubsetFit fit_subset(const FitSpec& s, const int (*px)[4], const int* members, int count,
                     int refinements) {
  float mean[4] = {}, cov[4][4] = {};
  for (int m = 0; m < count; ++m)
    for (int c = s.c_begin; c < s.c_end; ++c) mean[c] += static_cast<float>(px[members[m]][c]);
  for (int c = s.c_begin; c < s.c_end; ++c) mean[c] /= static_cast<float>(count);
  for (int m = 0; m < count; ++m)
    for (int a = s.c_begin; a < s.c_end; ++a)
      for (int b = s.c_begin; b < s.c_end; ++b)
        cov[a][b] += (px[members[m]][a] - mean[a]) * (px[members[m]][b] - mean[b]);
  // Power iteration from the diagonal (deterministic start, converges on the dominant axis).
  float axis[4] = {};
  for (int c = s.c_begin; c < s.c_end; ++c) axis[c] = cov[c][c] + 1e-3f;
  for (int it = 0; it < 8; ++it) {
    float next[4] = {}, norm = 0;
    for (int a = s.c_begin; a < s.c_end; ++a) {
      for (int b = s.c_begin; b < s.c_end; ++b) next[a] += cov[a][b] * axis[b];
      norm = std::max(norm, std::fabs(next[a]));
    }
    if (norm < 1e-12f) break;
    for (int c = s.c_begin; c < s.c_end; ++c) axis[c] = next[c] / norm;
  }
  float len2 = 0;
  for (int c = s.c_begin; c < s.c_end; ++c) len2 += axis[c] * axis[c];
  float tmin = 0, tmax = 0;
  for (int m = 0; m < count; ++m) {
    float t = 0;
    for (int c = s.c_begin; c < s.c_end; ++c) t += (px[members[m]][c] - mean[c]) * axis[c];
    t /= len2;
    tmin = std::min(tmin, t);
    tmax = std::max(tmax, t);
  }
  float ep[2][4] = {};
  for (int c = s.c_begin; c < s.c_end; ++c) {
    ep[0][c] = std::clamp(mean[c] + axis[c] * tmin, 0.0f, 255.0f);
    ep[1][c] = std::clamp(mean[c] + axis[c] * tmax, 0.0f, 255.0f);
  }
  SubsetFit best;
  quantize_and_score(s, ep, px, members, count, best);

  // Least squares: the endpoints that best reproduce the pixels with the chosen indices.
  const uint8_t* w = weights_for_bits(s.index_bits);
  for (int r = 0; r < refinements && best.err > 0; ++r) {
    float aa = 0, ab = 0, bb = 0, ax[4] = {}, bx[4] = {};
    for (int m = 0; m < count; ++m) {
      const float t = w[best.index[members[m]]] / 64.0f, u = 1.0f - t;
      aa += u * u, ab += u * t, bb += t * t;
      for (int c = s.c_begin; c < s.c_end; ++c) {
        ax[c] += u * static_cast<float>(px[members[m]][c]);
        bx[c] += t * static_cast<float>(px[members[m]][c]);
      }
    }
    const float det = aa * bb - ab * ab;
    if (std::fabs(det) < 1e-6f) break;
    float ls[2][4] = {};
    for (int c = s.c_begin; c < s.c_end; ++c) {
      ls[0][c] = std::clamp((ax[c] * bb - bx[c] * ab) / det, 0.0f, 255.0f);
      ls[1][c] = std::clamp((bx[c] * aa - ax[c] * ab) / det, 0.0f, 255.0f);
    }
    const long before = best.err;
    quantize_and_score(s, ls, px, members, count, best);
    if (best.err >= before) break;
  }
  return best;
}

// The residual a single line leaves in each subset of `partition`: total variance minus the
// variance along the principal axis. Ranks shapes without fitting them.
float partition_estimate(const int (*px)[4], int subsets, int partition, int channels) {
  float total = 0;
  for (int sub = 0; sub < subsets; ++sub) {
    float mean[4] = {}, cov[4][4] = {};
    int n = 0;
    for (int i = 0; i < 16; ++i) {
      if (subset_of(subsets, partition, i) != sub) continue;
      ++n;
      for (int c = 0; c < channels; ++c) mean[c] += static_cast<float>(px[i][c]);
    }
    if (n == 0) continue;
    for (int c = 0; c < channels; ++c) mean[c] /= static_cast<float>(n);
    for (int i = 0; i < 16; ++i) {
      if (subset_of(subsets, partition, i) != sub) continue;
      for (int a = 0; a < channels; ++a)
        for (int b = 0; b < channels; ++b) cov[a][b] += (px[i][a] - mean[a]) * (px[i][b] - mean[b]);
    }
    float v[4] = {1, 1, 1, 1}, lambda = 0, trace = 0;
    for (int c = 0; c < channels; ++c) trace += cov[c][c];
    for (int it = 0; it < 4; ++it) {
      float next[4] = {}, norm2 = 0;
      for (int a = 0; a < channels; ++a) {
        for (int b = 0; b < channels; ++b) next[a] += cov[a][b] * v[b];
        norm2 += next[a] * next[a];
      }
      if (norm2 < 1e-12f) break;
      const float norm = std::sqrt(norm2);
      float vv = 0;
      for (int c = 0; c < channels; ++c) vv += v[c] * v[c];
      lambda = norm / std::sqrt(vv);
      for (int c = 0; c < channels; ++c) v[c] = next[c] / norm;
    }
    total += trace - lambda;
  }
  return total;
}

// Mode descriptions the generic path handles (modes 0, 1, 2, 3, 6, 7).
struct ModeSpec {
  int mode, subsets, partition_bits, colour_bits, alpha_bits, pbits, index_bits;
};
constexpr ModeSpec kMode0{0, 3, 4, 4, 0, 1, 3}, kMode1{1, 2, 6, 6, 0, 2, 3},
    kMode2{2, 3, 6, 5, 0, 0, 2}, kMode3{3, 2, 6, 7, 0, 1, 2}, kMode6{6, 1, 0, 7, 7, 1, 4},
    kMode7{7, 2, 6, 5, 5, 1, 2};

struct Candidate {
  uint8_t block[16] = {};  // zeroed only for GCC -O3 -Wmaybe-uninitialized (mode 6 writes it)
  long err = std::numeric_limits<long>::max();
};

// Fits, orients (anchor indices < half) and packs one block in `m` with shape `partition`.
void try_mode(const ModeSpec& m, int partition, const int (*px)[4], int refinements,
              Candidate& best) {
  const FitSpec spec{0, m.alpha_bits ? 4 : 3, m.colour_bits, m.pbits, m.index_bits};
  SubsetFit fit[3];
  long err = 0;
  for (int sub = 0; sub < m.subsets; ++sub) {
    int members[16], count = 0;
    for (int i = 0; i < 16; ++i)
      if (subset_of(m.subsets, partition, i) == sub) members[count++] = i;
    fit[sub] = fit_subset(spec, px, members, count, refinements);
    err += fit[sub].err;
    if (err >= best.err) return;
  }
  if (!m.alpha_bits) {
    // Decoded alpha is 255; count the error against the input alpha too.
    for (int i = 0; i < 16; ++i) err += (255 - px[i][3]) * (255 - px[i][3]);
    if (err >= best.err) return;
  }
  // Anchor texels must have index < half: swap that subset's endpoints and mirror its indices.
  const int top = (1 << m.index_bits) - 1;
  uint8_t index[16];
  for (int i = 0; i < 16; ++i) index[i] = fit[subset_of(m.subsets, partition, i)].index[i];
  for (int sub = 0; sub < m.subsets; ++sub) {
    if (index[anchor_of(m.subsets, partition, sub)] <= top / 2) continue;
    SubsetFit& f = fit[sub];
    std::swap(f.q[0], f.q[1]);
    std::swap(f.p[0], f.p[1]);
    for (int i = 0; i < 16; ++i)
      if (subset_of(m.subsets, partition, i) == sub)
        index[i] = static_cast<uint8_t>(top - index[i]);
  }
  Candidate c;
  c.err = err;
  BitWriter bw(c.block);
  bw.write(1u << m.mode, m.mode + 1);
  bw.write(static_cast<uint32_t>(partition), m.partition_bits);
  for (int ch = 0; ch < 3; ++ch)
    for (int sub = 0; sub < m.subsets; ++sub)
      for (int j = 0; j < 2; ++j) bw.write(static_cast<uint32_t>(fit[sub].q[j][ch]), m.colour_bits);
  if (m.alpha_bits) {
    for (int sub = 0; sub < m.subsets; ++sub)
      for (int j = 0; j < 2; ++j) bw.write(static_cast<uint32_t>(fit[sub].q[j][3]), m.alpha_bits);
  }
  if (m.pbits == 1) {
    for (int sub = 0; sub < m.subsets; ++sub)
      for (int j = 0; j < 2; ++j) bw.write(static_cast<uint32_t>(fit[sub].p[j]), 1);
  } else if (m.pbits == 2) {
    for (int sub = 0; sub < m.subsets; ++sub) bw.write(static_cast<uint32_t>(fit[sub].p[0]), 1);
  }
  for (int i = 0; i < 16; ++i)
    bw.write(index[i], m.index_bits - (is_anchor(m.subsets, partition, i) ? 1 : 0));
  best = c;
}

// Mode 5: one subset, RGB (7 bits, 2-bit indices) and alpha (8 bits, own 2-bit indices) fitted
// separately; rotation 0. For blocks whose alpha does not follow their colour.
void try_mode5(const int (*px)[4], int refinements, Candidate& best) {
  const int all[16] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15};
  SubsetFit col = fit_subset({0, 3, 7, 0, 2}, px, all, 16, refinements);
  SubsetFit alp = fit_subset({3, 4, 8, 0, 2}, px, all, 16, refinements);
  const long err = col.err + alp.err;
  if (err >= best.err) return;
  for (SubsetFit* f : {&col, &alp}) {
    if (f->index[0] <= 1) continue;
    std::swap(f->q[0], f->q[1]);
    for (auto& i : f->index) i = static_cast<uint8_t>(3 - i);
  }
  Candidate c;
  c.err = err;
  BitWriter bw(c.block);
  bw.write(1u << 5, 6);
  bw.write(0, 2);  // rotation
  for (int ch = 0; ch < 3; ++ch)
    for (int j = 0; j < 2; ++j) bw.write(static_cast<uint32_t>(col.q[j][ch]), 7);
  for (int j = 0; j < 2; ++j) bw.write(static_cast<uint32_t>(alp.q[j][3]), 8);
  for (int i = 0; i < 16; ++i) bw.write(col.index[i], i == 0 ? 1 : 2);
  for (int i = 0; i < 16; ++i) bw.write(alp.index[i], i == 0 ? 1 : 2);
  best = c;
}

// The `keep` shapes of `subsets` subsets with the smallest estimate, best first (ties: lower
// shape number first, so the order is deterministic).
int rank_partitions(const int (*px)[4], int subsets, int shapes, int channels, int keep, int* out) {
  float score[64];
  int order[64];
  for (int p = 0; p < shapes; ++p) {
    score[p] = partition_estimate(px, subsets, p, channels);
    order[p] = p;
  }
  keep = std::min(keep, shapes);
  std::partial_sort(order, order + keep, order + shapes, [&](int a, int b) {
    return score[a] < score[b] || (score[a] == score[b] && a < b);
  });
  std::copy(order, order + keep, out);
  return keep;
}

}  // namespace

void encode_bc7_block(const uint8_t* rgba, uint8_t* out16, const Bc7Options& options) {
  const int q = std::clamp(options.quality, 0, 2);
  int px[16][4];
  bool opaque = true;
  for (int i = 0; i < 16; ++i) {
    for (int c = 0; c < 4; ++c) px[i][c] = rgba[4 * i + c];
    opaque = opaque && px[i][3] == 255;
  }
  const int refinements = q == 0 ? 1 : 2;
  Candidate best;
  try_mode(kMode6, 0, px, refinements, best);
  static constexpr int kShapes2[3] = {2, 8, 64};
  int shapes[64];
  if (best.err > 0) {
    if (opaque) {
      const int n = rank_partitions(px, 2, 64, 3, kShapes2[q], shapes);
      for (int k = 0; k < n && best.err > 0; ++k) {
        try_mode(kMode1, shapes[k], px, refinements, best);
        if (q >= 1) try_mode(kMode3, shapes[k], px, refinements, best);
      }
      if (q >= 2 && best.err > 0) {
        const int n3 = rank_partitions(px, 3, 64, 3, 16, shapes);
        for (int k = 0; k < n3 && best.err > 0; ++k) {
          try_mode(kMode2, shapes[k], px, refinements, best);
          if (shapes[k] < 16) try_mode(kMode0, shapes[k], px, refinements, best);
        }
      }
    } else if (q >= 1) {
      try_mode5(px, refinements, best);
      const int n = rank_partitions(px, 2, 64, 4, kShapes2[q], shapes);
      for (int k = 0; k < n && best.err > 0; ++k)
        try_mode(kMode7, shapes[k], px, refinements, best);
    }
  }
  std::memcpy(out16, best.block, 16);
}

Status encode_bc7(const Image8& image, uint8_t* out, size_t out_size, const Bc7Options& options) {
  CALF_RETURN_IF_ERROR(internal::check_image(Format::kBc7, image.pixels, image.width, image.height,
                                             image.row_stride, 1, image.channels, 3, 4, out_size,
                                             options.quality, 2, options.threads));
  internal::for_each_block(image.width, image.height, options.threads, out, 16,
                           [&](uint32_t bx, uint32_t by, uint8_t* block) {
                             uint8_t px[64];
                             internal::gather8(image, bx, by, px);
                             encode_bc7_block(px, block, options);
                           });
  return Status::Ok();
}

}  // namespace calf::bc
