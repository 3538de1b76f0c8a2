#include <array>
#include <vector>

#include "calf/player/view_set.h"

namespace calf::player {

Expected<uint64_t> unmix_coverage_colour(View* view, const capture::CoverageUnmixOptions& options) {
  if (!view->has_coverage()) return uint64_t{0};
  const uint32_t n = view->face_size();
  std::array<std::vector<float>, kCubeFaceCount> colour;
  capture::CoverageUnmixFaces faces;
  faces.face_size = n;
  faces.relative_step = view->range().relative_step();
  for (int f = 0; f < kCubeFaceCount; ++f) {
    const CubeFace face = cube_face_from_index(f);
    const std::span<const float> c = view->colour_face(face);
    colour[f].assign(c.begin(), c.end());
    faces.depth[f] = view->depth_face(face);
    faces.coverage[f] = view->coverage_face(face);
    faces.colour[f] = colour[f];
  }
  CALF_ASSIGN_OR_RETURN(const uint64_t changed, capture::unmix_coverage_colour(faces, options));
  const PixelRect whole{0, 0, n, n};
  for (int f = 0; f < kCubeFaceCount; ++f) {
    // The rect is the whole face and `colour` holds it: the write cannot fail.
    (void)view->write_colour_rect(cube_face_from_index(f), whole, colour[f]);
  }
  return changed;
}

}  // namespace calf::player
