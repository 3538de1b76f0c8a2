// Least-squares tile colour (texturing, paper 000 Sec. 5): the texel values whose bilinear
// interpolation best reproduces the samples that landed on the tile.
//
// Seurat filters the samples into each texture (a normalised splat) and the renderer then
// magnifies the texture with GL_LINEAR: every sample is low-passed twice, once by the splat and
// once by the magnification, and hard edges (texture edges, silhouettes' colour) lose contrast at
// every viewpoint, the capture's own included. Solving
//   min_x  sum_s |B_s x - c_s|^2 + lambda sum_(i,j neighbours) |x_i - x_j|^2
// (B_s: the sample's four bilinear weights at its texture position, the same interpolation the
// renderer applies) inverts the magnification instead of repeating it; the membrane term keeps
// texels no sample constrains harmonic (Seurat's Laplace inpainting) and damps ringing where the
// samples disagree. The normal matrix has a 3 x 3 stencil, so it is accumulated per texel while
// the samples stream by (TileNormals) and solved per tile by Jacobi-preconditioned conjugate
// gradients, starting from the splat's values.
#include <algorithm>
#include <cmath>

#include "tiles_internal.h"

namespace calf::encoder::tiles {

void TileNormals::reset(uint32_t side_in, bool with_coupling) {
  side = side_in;
  sums.assign(size_t{side} * side * 4, 0.0f);
  coupling.assign(with_coupling ? size_t{side} * side * 5 : 0, 0.0f);
}

void TileNormals::add(double u, double w, const float* colour, double weight) {
  const double fu = std::clamp(u, 0.0, side - 1.0), fw = std::clamp(w, 0.0, side - 1.0);
  const uint32_t x0 = std::min<uint32_t>(static_cast<uint32_t>(fu), side - 2);
  const uint32_t y0 = std::min<uint32_t>(static_cast<uint32_t>(fw), side - 2);
  const double ax = fu - x0, ay = fw - y0;
  // Bilinear weights of the four texels: (x0, y0), (x0 + 1, y0), (x0, y0 + 1), (x0 + 1, y0 + 1).
  const double b[4] = {(1 - ax) * (1 - ay), ax * (1 - ay), (1 - ax) * ay, ax * ay};
  const size_t i00 = size_t{y0} * side + x0, i10 = i00 + 1, i01 = i00 + side, i11 = i01 + 1;
  const size_t idx[4] = {i00, i10, i01, i11};
  // The sample's weight scales its row of the least-squares system: weight * b on the
  // right-hand side, weight * b_i * b_j in the normal matrix.
  for (int k = 0; k < 4; ++k) {
    const double wb = weight * b[k];
    for (int c = 0; c < 3; ++c) sums[4 * idx[k] + c] += static_cast<float>(wb * colour[c]);
    sums[4 * idx[k] + 3] += static_cast<float>(wb);
  }
  if (coupling.empty()) return;
  for (int k = 0; k < 4; ++k) {
    coupling[5 * idx[k] + kDiag] += static_cast<float>(weight * b[k] * b[k]);
  }
  coupling[5 * i00 + kRight] += static_cast<float>(weight * b[0] * b[1]);
  coupling[5 * i01 + kRight] += static_cast<float>(weight * b[2] * b[3]);
  coupling[5 * i00 + kDown] += static_cast<float>(weight * b[0] * b[2]);
  coupling[5 * i10 + kDown] += static_cast<float>(weight * b[1] * b[3]);
  coupling[5 * i00 + kDownRight] += static_cast<float>(weight * b[0] * b[3]);
  coupling[5 * i10 + kDownLeft] += static_cast<float>(weight * b[1] * b[2]);
}

void solve_tile_colour(const TileNormals& n, double smoothness, uint32_t iterations, float* rgba) {
  const uint32_t side = n.side;
  const size_t count = size_t{side} * side;
  if (iterations == 0 || count == 0 || n.coupling.empty()) return;
  // The membrane weight scales with the samples' own weight, so the same smoothness means the
  // same thing at every texel density and view count.
  double diag_sum = 0;
  size_t diag_count = 0;
  for (size_t i = 0; i < count; ++i) {
    const float d = n.coupling[5 * i + TileNormals::kDiag];
    if (d > 0) {
      diag_sum += d;
      ++diag_count;
    }
  }
  if (diag_count == 0) return;
  const double lambda = smoothness * diag_sum / double(diag_count);

  // y = (N + lambda L) x for the three channels at once.
  auto apply = [&](const std::vector<double>& x, std::vector<double>* y) {
    for (uint32_t ty = 0; ty < side; ++ty) {
      for (uint32_t tx = 0; tx < side; ++tx) {
        const size_t i = size_t{ty} * side + tx;
        const float* c = &n.coupling[5 * i];
        double acc[3];
        int degree = 0;
        for (int ch = 0; ch < 3; ++ch) acc[ch] = c[TileNormals::kDiag] * x[3 * i + ch];
        auto couple = [&](size_t j, double weight) {
          for (int ch = 0; ch < 3; ++ch) acc[ch] += weight * x[3 * j + ch];
        };
        auto membrane = [&](size_t j) {
          ++degree;
          for (int ch = 0; ch < 3; ++ch) acc[ch] -= lambda * x[3 * j + ch];
        };
        if (tx + 1 < side) {
          couple(i + 1, c[TileNormals::kRight]);
          membrane(i + 1);
        }
        if (tx > 0) {
          couple(i - 1, n.coupling[5 * (i - 1) + TileNormals::kRight]);
          membrane(i - 1);
        }
        if (ty + 1 < side) {
          couple(i + side, c[TileNormals::kDown]);
          membrane(i + side);
          if (tx + 1 < side) couple(i + side + 1, c[TileNormals::kDownRight]);
          if (tx > 0) couple(i + side - 1, c[TileNormals::kDownLeft]);
        }
        if (ty > 0) {
          couple(i - side, n.coupling[5 * (i - side) + TileNormals::kDown]);
          membrane(i - side);
          if (tx > 0)
            couple(i - side - 1, n.coupling[5 * (i - side - 1) + TileNormals::kDownRight]);
          if (tx + 1 < side) {
            couple(i - side + 1, n.coupling[5 * (i - side + 1) + TileNormals::kDownLeft]);
          }
        }
        for (int ch = 0; ch < 3; ++ch) (*y)[3 * i + ch] = acc[ch] + lambda * degree * x[3 * i + ch];
      }
    }
  };
  std::vector<double> precond(count);
  for (uint32_t ty = 0; ty < side; ++ty) {
    for (uint32_t tx = 0; tx < side; ++tx) {
      const int degree = (tx > 0) + (tx + 1 < side) + (ty > 0) + (ty + 1 < side);
      const size_t i = size_t{ty} * side + tx;
      const double d = n.coupling[5 * i + TileNormals::kDiag] + lambda * degree;
      precond[i] = d > 0 ? 1.0 / d : 0.0;
    }
  }
  std::vector<double> x(3 * count), r(3 * count), z(3 * count), p(3 * count), q(3 * count);
  for (size_t i = 0; i < count; ++i) {
    for (int ch = 0; ch < 3; ++ch) x[3 * i + ch] = rgba[4 * i + ch];
  }
  apply(x, &q);
  for (size_t k = 0; k < 3 * count; ++k) r[k] = n.sums[4 * (k / 3) + k % 3] - q[k];
  double rz[3] = {0, 0, 0};
  for (size_t k = 0; k < 3 * count; ++k) {
    z[k] = precond[k / 3] * r[k];
    p[k] = z[k];
    rz[k % 3] += r[k] * z[k];
  }
  for (uint32_t it = 0; it < iterations; ++it) {
    apply(p, &q);
    double pq[3] = {0, 0, 0};
    for (size_t k = 0; k < 3 * count; ++k) pq[k % 3] += p[k] * q[k];
    double alpha[3];
    for (int ch = 0; ch < 3; ++ch) alpha[ch] = pq[ch] > 0 ? rz[ch] / pq[ch] : 0.0;
    double rz_next[3] = {0, 0, 0};
    for (size_t k = 0; k < 3 * count; ++k) {
      x[k] += alpha[k % 3] * p[k];
      r[k] -= alpha[k % 3] * q[k];
      z[k] = precond[k / 3] * r[k];
      rz_next[k % 3] += r[k] * z[k];
    }
    double beta[3];
    for (int ch = 0; ch < 3; ++ch) {
      beta[ch] = rz[ch] > 0 ? rz_next[ch] / rz[ch] : 0.0;
      rz[ch] = rz_next[ch];
    }
    for (size_t k = 0; k < 3 * count; ++k) p[k] = z[k] + beta[k % 3] * p[k];
  }
  // Inverting the magnification overshoots at edges; radiance is never negative.
  for (size_t i = 0; i < count; ++i) {
    for (int ch = 0; ch < 3; ++ch)
      rgba[4 * i + ch] = static_cast<float>(std::max(0.0, x[3 * i + ch]));
  }
}

}  // namespace calf::encoder::tiles
