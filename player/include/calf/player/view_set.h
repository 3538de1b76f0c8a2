// The viewpoint textures the renderers read (paper 002 Sec. 6, Alg. 4 precondition): for each of
// N viewpoints its position, its log-depth range, and six colour, depth and (optionally) material
// faces. This is the CPU image of what the GL renderer keeps in cube-map textures.
//
// Conventions are the format layer's, never re-derived here:
//   - faces in OpenGL order and orientation, texel (x, y) of face f is the ray
//     direction_from_texel(f, x, y, face_size) (calf/format/cube.h); row 0 is the first row;
//   - depth is stored as log-16 codes of the radial distance (calf/format/log_depth.h), code
//     kLog16Sky (65535) = no hit / sky;
//   - colour is linear RGB float, 3 floats per texel, HDR values (> 1) kept;
//   - material is 3 floats per texel: reflect weight, refract weight, index of refraction
//     (format/CAPTURE.md; texels on plain surfaces and sky hold (0, 0, 1)).
//
// A view starts all sky (depth kLog16Sky, colour 0, material (0, 0, 1)). It is filled by rect
// writes, the shape of the decoder's texture updates (view, face, rect, bytes) and of
// glTexSubImage2D, so the same update stream can drive the CPU reference and the GL renderer.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "calf/capture/coverage_unmix.h"
#include "calf/format/cube.h"
#include "calf/format/geometry.h"
#include "calf/format/grid.h"
#include "calf/format/log_depth.h"
#include "calf/format/status.h"

namespace calf::player {

// Per-texel coverage (format/CAPTURE.md "Coverage", calf/capture/coverage_unmix.h). A view without
// coverage answers (0, 0, all cells): every texel wholly its own surface.
using Coverage = capture::TexelCoverage;

// Per-texel material (paper 002 Sec. 6.1).
struct Material {
  float reflect = 0;  // reflect weight in [0, 1]
  float refract = 0;  // refract weight in [0, 1], reflect + refract <= 1
  float ior = 1;      // index of refraction, finite and > 0
};

class View {
 public:
  // A view centred at `position` with faces of `face_size` texels (1..kMaxFaceSize), depth range
  // `range`, all sky. `with_material` allocates the material faces. Errors: CALF-E400 for a face
  // size out of range or a non-finite position.
  static Expected<View> make(const Vec3& position, const LogDepthRange& range, uint32_t face_size,
                             bool with_material);

  const Vec3& position() const { return position_; }
  const LogDepthRange& range() const { return range_; }
  uint32_t face_size() const { return face_size_; }
  bool has_material() const { return !material_[0].empty(); }
  bool has_coverage() const { return !coverage_[0].empty(); }
  // Gives the view coverage faces (all texels wholly their own surface) if it has none.
  void add_coverage();

  // Texture updates: copy `rect` of `face` from `src`, whose rows are `src_stride` elements apart
  // (elements: floats for colour / material, codes for depth; a row of the rect holds
  // rect.width * channels elements, channels = 3 for colour and material, 1 for depth).
  // src_stride 0 means tightly packed. Errors: CALF-E401 when the rect leaves the face, is empty,
  // the stride is shorter than a row or `src` is shorter than the rect; CALF-E402 when material
  // is written to a view made without it. Nothing is written on error.
  Status write_colour_rect(CubeFace face, const PixelRect& rect, std::span<const float> src,
                           size_t src_stride = 0);
  Status write_depth_rect(CubeFace face, const PixelRect& rect, std::span<const uint16_t> src,
                          size_t src_stride = 0);
  Status write_material_rect(CubeFace face, const PixelRect& rect, std::span<const float> src,
                             size_t src_stride = 0);
  // Coverage rows hold 3 floats per texel: near share, far share, mask (an integer 0..65535).
  // The first write gives the view coverage faces (add_coverage).
  Status write_coverage_rect(CubeFace face, const PixelRect& rect, std::span<const float> src,
                             size_t src_stride = 0);

  // Whole faces, row-major, for filling and for reading back (face_size^2 * channels elements).
  std::span<const float> colour_face(CubeFace f) const { return colour_[cube_face_index(f)]; }
  std::span<const uint16_t> depth_face(CubeFace f) const { return depth_[cube_face_index(f)]; }
  // Empty when the view has no material.
  std::span<const float> material_face(CubeFace f) const { return material_[cube_face_index(f)]; }
  // Empty when the view has no coverage.
  std::span<const Coverage> coverage_face(CubeFace f) const {
    return coverage_[cube_face_index(f)];
  }

  // Texel access for the renderers; x, y < face_size (asserted in debug).
  const float* colour_at(CubeFace f, uint32_t x, uint32_t y) const {
    return &colour_[cube_face_index(f)][3 * texel_index(x, y)];
  }
  uint16_t depth_code_at(CubeFace f, uint32_t x, uint32_t y) const {
    return depth_[cube_face_index(f)][texel_index(x, y)];
  }
  // (0, 0, 1) when the view has no material.
  Material material_at(CubeFace f, uint32_t x, uint32_t y) const;
  Coverage coverage_at(CubeFace f, uint32_t x, uint32_t y) const {
    if (!has_coverage()) return {};
    return coverage_[cube_face_index(f)][texel_index(x, y)];
  }

 private:
  View() = default;
  size_t texel_index(uint32_t x, uint32_t y) const;
  Status check_rect(CubeFace face, const PixelRect& rect, size_t src_size, size_t channels,
                    size_t* stride) const;

  Vec3 position_;
  LogDepthRange range_ = *LogDepthRange::make(1, 2);
  uint32_t face_size_ = 0;
  std::array<std::vector<float>, kCubeFaceCount> colour_;
  std::array<std::vector<uint16_t>, kCubeFaceCount> depth_;
  std::array<std::vector<float>, kCubeFaceCount> material_;
  std::array<std::vector<Coverage>, kCubeFaceCount> coverage_;
};

// Unmixes the view's colour (calf/capture/coverage_unmix.h), so that any renderer can take its
// texels. Returns how many texels changed; a view without coverage is unchanged (0). Errors:
// CALF-E169 for an option outside its range; nothing is written then.
[[nodiscard]] Expected<uint64_t> unmix_coverage_colour(
    View* view, const capture::CoverageUnmixOptions& options);

// The views one frame renders from. Views may differ in face size and depth range.
struct ViewSet {
  std::vector<View> views;
  // Whether any view carries material (the RR variant needs at least one).
  bool has_material() const;
};

}  // namespace calf::player
