// Where the error against ground truth comes from (docs/PLAYER.md "Error breakdown"):
// each pixel's squared error is split into five classes, and a pose's (or a path's) MSE into
// their shares, so that a figure says what to fix.
//
// The per-pixel squared error is that of psnr() (calf/player/image_compare.h): the mean over R,
// G, B of the squared differences of the sRGB-encoded, clamped values; the classes' sums over an
// image add up to its MSE times the pixel count exactly.
//   - codec: with a render of the same pose from a lossless clip of the same capture (raw colour,
//     raw depth), the error the lossy clip adds to it: max(0, e^2 - e_lossless^2). Without one
//     the class is not measured and stays 0.
// The rest of a pixel's error (all of it without a lossless render) goes to one class, the first
// that applies, from the ground truth's own depth (the surface a pixel shows: P = eye + ray *
// depth) and the capture set's views at the pose's frame:
//   - disocclusion: P is a surface no capture view saw: for every view, the view's depth along its
//     ray through P (the nearest texel and its 8 neighbours on the face) differs from the
//     distance to P by more than `visibility_tolerance` of it. Reconstruction has nothing to show
//     there but a guess.
//   - silhouette: a depth edge lies within `silhouette_radius` pixels: two 4-neighbour pixels
//     whose depths differ by more than `silhouette_ratio` of the nearer, or a surface next to sky.
//     A texel off there shows the wrong surface.
//   - geometry: away from edges, the reconstruction shows another surface than the ground truth:
//     its own depth differs from the ground truth's by more than `visibility_tolerance` of it
//     (or one of them is sky). A missing layer, a hole, a surface placed wrong.
//   - shading: everything else: the right surface, seen and smooth, in the wrong colour (noise,
//     filtering, view-dependent light, resampling).
// Sky pixels (no depth) are never disoccluded; they are silhouette or shading.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <vector>

#include "calf/capture/capture_set.h"
#include "calf/capture/eye_path.h"
#include "calf/format/camera.h"
#include "calf/format/status.h"
#include "calf/player/image_compare.h"

namespace calf::player {

enum class ErrorClass : uint8_t {
  kShading = 0,
  kSilhouette = 1,
  kDisocclusion = 2,
  kCodec = 3,
  kGeometry = 4
};
inline constexpr size_t kErrorClassCount = 5;
// "shading", "silhouette", "disocclusion", "codec", "geometry".
const char* error_class_name(ErrorClass c);

struct ErrorBreakdownOptions {
  double visibility_tolerance = 0.02;  // relative depth agreement of "a view saw P", (0, 1)
  double silhouette_ratio = 0.05;      // relative depth step of an edge, > 0
  uint32_t silhouette_radius = 1;      // pixels around an edge, 0..16
};

struct ErrorBreakdown {
  // Per class: the sum of the pixels' squared errors (the class's part of MSE * pixels) and the
  // pixels whose largest part is that class.
  std::array<double, kErrorClassCount> squared{};
  std::array<uint64_t, kErrorClassCount> pixels{};
  uint64_t pixel_count = 0;
  bool codec_measured = false;

  double total() const;                    // sum of squared
  double share(ErrorClass c) const;        // squared[c] / total(), 0 when total() is 0
  double pixel_share(ErrorClass c) const;  // pixels[c] / pixel_count
  ErrorBreakdown& operator+=(const ErrorBreakdown& other);
};

// Every capture view's depth at one frame, to ask whether any of them saw a point.
class CaptureVisibility {
 public:
  // Reads frame `frame` of every view of `reader` (the reader's errors: CALF-E135..E140).
  static Expected<CaptureVisibility> load(const capture::CaptureSetReader& reader, uint32_t frame);
  // Whether some view's surface lies within `tolerance` (relative) of p's distance along that
  // view's ray through p, at the nearest texel or one of its 8 neighbours on the same face.
  bool seen(const Vec3& p, double tolerance) const;
  uint32_t frame() const { return frame_; }

 private:
  uint32_t face_size_ = 0, frame_ = 0;
  std::vector<Vec3> positions_;
  std::vector<std::vector<float>> depth_;  // per view: 6 * face_size^2, ViewFrame's order
};

// Classifies the error of `test` against `truth` (both eye.width x eye.height; truth's depth is
// the ground truth's radial depth) at the pose `eye`; without test.depth (empty) no pixel is
// geometry. `lossless` (optional, same size) is the same
// pose rendered from a lossless clip. `classes` (optional) receives each pixel's class (the one
// holding most of its squared error; shading where it has none) and `squared` (optional) its
// squared error. Errors: CALF-E431 for images of unequal or zero size or missing depth, CALF-E432
// for an option outside its range.
Expected<ErrorBreakdown> classify_errors(const RenderedImage& test,
                                         const capture::PerspectiveImage& truth, const Camera& eye,
                                         const CaptureVisibility& views,
                                         const RgbImageRef* lossless,
                                         const ErrorBreakdownOptions& options,
                                         std::vector<uint8_t>* classes = nullptr,
                                         std::vector<float>* squared = nullptr);

// Writes the class map as an 8-bit RGB PNG: each pixel in its class's colour (shading blue,
// silhouette yellow, disocclusion red, codec green, geometry magenta) scaled by its error, RMS /
// full_scale clamped to 1 (so black is exact, full colour is an error of full_scale and above; 0.1
// by default, as the heat maps). CALF-E431 for sizes that disagree, E432 for full_scale outside (0,
// 1], E004 when the file cannot be written.
Status write_error_class_png(const std::filesystem::path& path, uint32_t width, uint32_t height,
                             const std::vector<uint8_t>& classes, const std::vector<float>& squared,
                             double full_scale = 0.1);

}  // namespace calf::player
