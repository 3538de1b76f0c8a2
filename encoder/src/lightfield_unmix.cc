// Unmixed colour baked into the clip (LightfieldEncodeOptions::coverage_unmix): the view's colour,
// depth codes and coverage of each frame handed to calf/capture/coverage_unmix.h.
#include <array>
#include <vector>

#include "calf/capture/coverage_unmix.h"
#include "calf/format/bc.h"
#include "lightfield_view_pass.h"

namespace calf::encoder::lightfield_internal {

Expected<uint64_t> unmix_view_colour(const capture::CoverageUnmixOptions& options, ViewData* view) {
  const uint32_t n = view->face_size;
  const size_t face_texels = size_t{n} * n;
  std::array<std::vector<float>, kCubeFaceCount> colour;
  std::array<std::vector<capture::TexelCoverage>, kCubeFaceCount> coverage;
  for (int f = 0; f < kCubeFaceCount; ++f) {
    colour[f].resize(3 * face_texels);
    coverage[f].resize(face_texels);
  }
  uint64_t changed = 0;
  for (uint32_t frame = 0; frame < view->frames; ++frame) {
    capture::CoverageUnmixFaces faces;
    faces.face_size = n;
    faces.relative_step = view->range->relative_step();
    for (int f = 0; f < kCubeFaceCount; ++f) {
      const size_t first = view->index(frame, static_cast<uint32_t>(f), 0, 0);
      for (size_t i = 0; i < face_texels; ++i) {
        for (int c = 0; c < 3; ++c) {
          colour[f][3 * i + c] = bc::half_to_float(view->colour[3 * (first + i) + c]);
        }
        // The shares a decoder gives: counts of the texel's 16 cells.
        const lf::CoverageTexel& t = view->coverage[first + i];
        coverage[f][i] = {t.near / 16.0f, t.far() / 16.0f, t.mask};
      }
      faces.depth[f] = std::span<const uint16_t>(view->depth).subspan(first, face_texels);
      faces.coverage[f] = coverage[f];
      faces.colour[f] = colour[f];
    }
    CALF_ASSIGN_OR_RETURN(const uint64_t frame_changed,
                          capture::unmix_coverage_colour(faces, options));
    changed += frame_changed;
    if (frame_changed == 0) continue;
    for (int f = 0; f < kCubeFaceCount; ++f) {
      const size_t first = view->index(frame, static_cast<uint32_t>(f), 0, 0);
      for (size_t i = 0; i < 3 * face_texels; ++i) {
        view->colour[3 * first + i] = half_from_colour(colour[f][i]);
      }
    }
  }
  return changed;
}

}  // namespace calf::encoder::lightfield_internal
