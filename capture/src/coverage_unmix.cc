#include "calf/capture/coverage_unmix.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <string>
#include <vector>

#include "calf/capture/capture_set.h"
#include "calf/format/log_depth.h"

namespace calf::capture {

namespace {

// Where a neighbour's surface lies against the texel's own (format/CAPTURE.md "Coverage" names a
// cell's surface the same way).
enum class Side { kOwn, kNearer, kFarther, kNone };

Side side_of(uint16_t own, uint16_t other, double tolerance_codes, double jump_codes) {
  if (own == kLog16Sky) return other == kLog16Sky ? Side::kOwn : Side::kNearer;
  if (other == kLog16Sky) return Side::kFarther;
  const double d = static_cast<double>(other) - static_cast<double>(own);
  if (d < -jump_codes) return Side::kNearer;
  if (d > jump_codes) return Side::kFarther;
  if (std::fabs(d) <= tolerance_codes) return Side::kOwn;
  return Side::kNone;
}

Status bad(const std::string& what) {
  return Status(ErrorId::kCoverageUnmixInput, "coverage unmixing: " + what);
}

}  // namespace

Expected<uint64_t> unmix_coverage_colour(const CoverageUnmixFaces& faces,
                                         const CoverageUnmixOptions& options) {
  const uint32_t n = faces.face_size;
  if (n == 0) return bad("face size 0");
  if (!(faces.relative_step > 0) || !std::isfinite(faces.relative_step)) {
    return bad("relative depth step " + std::to_string(faces.relative_step) +
               " is not positive and finite");
  }
  if (!(options.min_share >= 0 && options.min_share <= 1)) {
    return bad("minimum share " + std::to_string(options.min_share) + " is outside [0, 1]");
  }
  if (!(options.min_jump >= 0) || !std::isfinite(options.min_jump)) {
    return bad("minimum jump " + std::to_string(options.min_jump) + " is not finite and >= 0");
  }
  const size_t texels = size_t{n} * n;
  for (int f = 0; f < kCubeFaceCount; ++f) {
    if (faces.depth[f].size() != texels || faces.coverage[f].size() != texels ||
        faces.colour[f].size() != 3 * texels) {
      return bad("face " + std::to_string(f) + " holds " + std::to_string(faces.depth[f].size()) +
                 " depth, " + std::to_string(faces.coverage[f].size()) + " coverage and " +
                 std::to_string(faces.colour[f].size()) + " colour values for " +
                 std::to_string(texels) + " texels");
    }
  }
  // The capture's own-surface tolerance, in codes.
  const double tolerance_codes = coverage_tolerance(n) / faces.relative_step;
  // The other side: a neighbour at least min_jump (and the tolerance) nearer or farther.
  const double jump_codes = std::max(coverage_tolerance(n), options.min_jump) / faces.relative_step;
  const auto index = [n](const Texel& t) { return size_t{t.y} * n + t.x; };
  // Neighbours read the input: every face's colour is kept until all are solved.
  std::array<std::vector<float>, kCubeFaceCount> in;
  for (int f = 0; f < kCubeFaceCount; ++f)
    in[f].assign(faces.colour[f].begin(), faces.colour[f].end());
  uint64_t changed = 0;
  for (int f = 0; f < kCubeFaceCount; ++f) {
    const CubeFace face = cube_face_from_index(f);
    for (uint32_t y = 0; y < n; ++y) {
      for (uint32_t x = 0; x < n; ++x) {
        const TexelCoverage& cov = faces.coverage[f][size_t{y} * n + x];
        if (cov.mask == 0xFFFF) continue;
        const double own = std::popcount(cov.mask) / 16.0;
        const double share[2] = {cov.near, cov.far};  // the other surfaces' shares
        const uint16_t code = faces.depth[f][size_t{y} * n + x];
        // The centroid of the cells the texel's own surface does not cover, in texels from its
        // centre: the side of the texel where the other surface lies.
        double cx = 0, cy = 0;
        for (int j = 0; j < 4; ++j) {
          for (int i = 0; i < 4; ++i) {
            if ((cov.mask >> (4 * j + i)) & 1u) continue;
            cx += (i + 0.5) / 4 - 0.5;
            cy += (j + 0.5) / 4 - 0.5;
          }
        }
        // Per side (own, nearer, farther) the best neighbour among the eight: one wholly its own
        // surface first, then the one that lies most towards the uncovered cells.
        const float* pick[3] = {nullptr, nullptr, nullptr};
        double best[3] = {-1e9, -1e9, -1e9};
        for (int dy = -1; dy <= 1; ++dy) {
          for (int dx = -1; dx <= 1; ++dx) {
            if (dx == 0 && dy == 0) continue;
            const Texel t = texel_beyond_face(face, int64_t{x} + dx, int64_t{y} + dy, n);
            const int tf = cube_face_index(t.face);
            const uint16_t other = faces.depth[tf][index(t)];
            const int s = static_cast<int>(side_of(code, other, tolerance_codes, jump_codes));
            if (s == static_cast<int>(Side::kNone)) continue;
            const double toward = (dx * cx + dy * cy) / std::sqrt(double(dx * dx + dy * dy));
            // The own surface's colour comes from the side away from the uncovered cells.
            double score = s == 0 ? -toward : toward;
            if (faces.coverage[tf][index(t)].mask == 0xFFFF) score += 10;
            if (score > best[s]) {
              best[s] = score;
              pick[s] = &in[tf][3 * index(t)];
            }
          }
        }
        float* c = &faces.colour[f][3 * (size_t{y} * n + x)];
        const float before[3] = {c[0], c[1], c[2]};
        if (own < options.min_share || own == 0) {
          // Too little of the texel is its own surface to solve for it: take a neighbour on it.
          if (pick[0]) std::copy(pick[0], pick[0] + 3, c);
        } else if ((share[0] > 0 && !pick[1]) || (share[1] > 0 && !pick[2])) {
          continue;
        } else {
          for (int ch = 0; ch < 3; ++ch) {
            double rest = c[ch];
            if (share[0] > 0) rest -= share[0] * pick[1][ch];
            if (share[1] > 0) rest -= share[1] * pick[2][ch];
            // In [0, c / own]: the other surfaces add light, never take it away. Where a
            // neighbour shows the own surface, no farther from c than it: a wrong estimate of
            // the other side (a texture, a light) must not be amplified by 1 / own.
            double lo = 0, hi = c[ch] / own;
            if (pick[0]) {
              lo = std::min<double>(c[ch], pick[0][ch]);
              hi = std::max<double>(c[ch], pick[0][ch]);
            }
            c[ch] = static_cast<float>(std::clamp(rest / own, lo, hi));
          }
        }
        if (c[0] != before[0] || c[1] != before[1] || c[2] != before[2]) ++changed;
      }
    }
  }
  return changed;
}

}  // namespace calf::capture
