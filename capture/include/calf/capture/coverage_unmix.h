// Unmixed colour from coverage (format/CAPTURE.md "Coverage", docs/RENDERING.md "Coverage").
//
// A texel on a depth edge holds the anti-aliased mean of its own surface and the others its
// square shows: c = a c_own + near c_nearer + far c_farther, with a the share of its own cells.
// This solves for c_own, in linear light, taking c_nearer and c_farther from the texel's eight
// neighbours (across face seams) whose depth lies nearer / farther than its own by more than
// max(min_jump, the capture's own-surface tolerance min(4 / N, 0.05)) as relative depth: a
// neighbour wholly its own surface first, then the one lying most towards the cells the texel's
// surface does not cover. The result is clamped to [0, c / a], and where a neighbour (within the
// tolerance) shows the texel's own surface, to the range between c and that neighbour's colour,
// so that a wrong estimate of the other side is not amplified by 1 / a. Where a < min_share that
// neighbour's colour is taken instead; a texel whose other sides have no neighbour keeps its
// colour. All texels are read before any is written.
//
// The CPU reference applies it to the views it renders (bench-player_quality --coverage-unmix);
// calf-encode --coverage-unmix bakes it into a clip's colour, so every player shows it.
#pragma once

#include <array>
#include <cstdint>
#include <span>

#include "calf/format/cube.h"
#include "calf/format/status.h"

namespace calf::capture {

// One texel's coverage: the shares of its square that nearer and farther surfaces cover, and the
// 4 x 4 cell mask of the cells that show its own surface (bit 4 y + x for cell (x, y), x along
// the face's x). The default is a texel wholly its own surface.
struct TexelCoverage {
  float near = 0, far = 0;
  uint16_t mask = 0xFFFF;
};

struct CoverageUnmixOptions {
  // Below this share of its own cells a texel takes a neighbour's colour of its own surface
  // instead of solving for it; in [0, 1].
  double min_share = 0.25;
  // The least relative depth step to a neighbour that counts as the other side, beyond the
  // capture's own-surface tolerance; >= 0. 1000: only the sky (sky edges).
  double min_jump = 0;
};

// One view at one frame: six faces of face_size^2 texels, row-major, in cube-face order.
struct CoverageUnmixFaces {
  uint32_t face_size = 0;
  // The depth codes' relative step (LogDepthRange::relative_step()), > 0.
  double relative_step = 0;
  std::array<std::span<const uint16_t>, kCubeFaceCount> depth;  // log-16 codes, kLog16Sky: sky
  std::array<std::span<const TexelCoverage>, kCubeFaceCount> coverage;
  std::array<std::span<float>, kCubeFaceCount> colour;  // linear RGB, 3 floats a texel; in / out
};

// Unmixes `faces.colour` in place. Returns how many texels changed. Errors: CALF-E169 when a
// face's span is not face_size^2 texels long, face_size is 0, relative_step is not positive and
// finite, or an option is outside its range; nothing is written then.
[[nodiscard]] Expected<uint64_t> unmix_coverage_colour(const CoverageUnmixFaces& faces,
                                                       const CoverageUnmixOptions& options);

}  // namespace calf::capture
