// Image metrics and image files for measuring reconstruction quality against ground truth
// (DESIGN.md "Measuring"; docs/RENDERING.md "Quality").
//
// Both metrics judge what a viewer sees on an ordinary display: linear RGB is encoded with the
// sRGB transfer curve and clamped to [0, 1] (calf/format/colour.h, srgb_from_linear; HDR values
// above 1 all show as 1), so an error in the shadows weighs as the eye sees it, not as linear
// light does.
//
// PSNR: over every pixel and the three channels of the encoded values a and b (N pixels),
//   MSE = sum (a - b)^2 / (3 N),   PSNR = 10 log10(1 / MSE) dB   (peak 1; +inf when MSE = 0).
//
// SSIM (Wang, Bovik, Sheikh, Simoncelli 2004, "Image quality assessment: from error visibility to
// structural similarity", with the authors' reference settings): on the luma
// Y = 0.2126 R' + 0.7152 G' + 0.0722 B' of the encoded values (BT.709 weights: sRGB's primaries),
// dynamic range L = 1, a Gaussian window of 11 x 11 taps with sigma 1.5 (normalised to sum 1),
// K1 = 0.01, K2 = 0.03 (C1 = (K1 L)^2, C2 = (K2 L)^2). At every position where the window lies
// wholly inside the image ("valid" filtering, (W - 10) x (H - 10) positions), with weighted means
// mu, variances sigma^2 = E[Y^2] - mu^2 and covariance sigma_xy = E[XY] - mu_x mu_y,
//   SSIM = (2 mu_x mu_y + C1)(2 sigma_xy + C2) / ((mu_x^2 + mu_y^2 + C1)(sigma_x^2 + sigma_y^2 +
//   C2))
// and the image's SSIM is the plain mean over those positions. 1 for identical images. The
// reference code's down-sampling of images above 256 pixels is not applied.
//
// Errors: CALF-E431 for images that are empty, differ in size or whose buffers are shorter than
// their size (and, for SSIM, images narrower or shorter than the 11-tap window); CALF-E432 for an
// option outside its range; CALF-E004 when a file cannot be written (nothing half-written is left).
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <span>
#include <vector>

#include "calf/capture/eye_path.h"
#include "calf/format/status.h"
#include "calf/player/lightfield_cpu_renderer.h"
#include "calf/player/rendered_image.h"

namespace calf::player {

// A linear-RGB image as the metrics read it: width x height pixels of 3 floats each (R, G, B),
// row-major from the top row. Borrowed: `rgb` must outlive the reference.
struct RgbImageRef {
  uint32_t width = 0, height = 0;
  std::span<const float> rgb;
};
inline RgbImageRef rgb_ref(const RenderedImage& image) {
  return {image.width, image.height, image.color};
}
inline RgbImageRef rgb_ref(const capture::PerspectiveImage& image) {
  return {image.width, image.height, image.color};
}

// The side of the SSIM window and its Gaussian's sigma (Wang et al. 2004).
inline constexpr uint32_t kSsimWindow = 11;
inline constexpr double kSsimSigma = 1.5;

// PSNR in dB of the sRGB-encoded, clamped images (definition above); +inf for identical ones.
Expected<double> psnr(const RgbImageRef& a, const RgbImageRef& b);

// Mean SSIM of the sRGB luma (definition above), in [-1, 1]; 1 for identical images.
Expected<double> ssim(const RgbImageRef& a, const RgbImageRef& b);

// The pixel error epsilon of paper 004 (Popescu et al., Sec. 5): the share of pixels where a
// triangle is missing. A pixel counts when the reference (the full scene, rendered by the same
// renderer at the same pose) shows a surface there, and the image under test shows nothing or a
// surface farther than it by more than the tolerance:
//   reference depth r finite  and  not (test depth <= r * (1 + relative) + absolute)
// (a NaN test depth counts; a NaN or +inf reference depth never does). A test surface nearer
// than the reference is not counted: a subset of the scene's triangles cannot occlude more. The
// tolerance absorbs float noise between two renders of the same triangle, which the same renderer
// makes bit-identical anyway; its default (0.1 % + 1e-6 scene units) lies far below the depth gap
// a missing triangle leaves on the visible-set walk traces (docs/VISIBILITY.md).
struct DepthTolerance {
  double relative = 1e-3;  // >= 0, finite
  double absolute = 1e-6;  // >= 0, finite
};
struct MissingGeometry {
  uint64_t missing = 0;  // pixels counted
  uint64_t pixels = 0;   // all pixels of the image
  double epsilon = 0;    // missing / pixels, in [0, 1]
};
// Epsilon of `test` against `reference` (depth buffers of two RenderedImages). Errors: CALF-E431
// for images of different or zero size or incomplete depth buffers, CALF-E432 for a negative or
// non-finite tolerance.
Expected<MissingGeometry> missing_geometry(const RenderedImage& test,
                                           const RenderedImage& reference,
                                           const DepthTolerance& tolerance = {});

// Per-pixel error for heat maps: the root mean square over R, G, B of the differences of the
// sRGB-encoded, clamped values, in [0, 1]; width * height values, row-major from the top row.
// Its mean square over the image is the MSE of psnr().
Expected<std::vector<float>> error_map(const RgbImageRef& a, const RgbImageRef& b);

// The heat-map colour ramp, 8-bit RGB: t <= 0 black, 1/4 blue, 1/2 cyan, 3/4 yellow, t >= 1 red,
// linear in between (NaN gives red: an undefined error is shown as the worst).
std::array<uint8_t, 3> heat_colour(double t);

// Writes the heat map of error_map(a, b) as an 8-bit RGB PNG: a pixel's colour is
// heat_colour(error / full_scale), so full_scale (in (0, 1]; 0.1 by default, a per-pixel error of
// 20 dB) and above is red.
Status write_heat_map_png(const std::filesystem::path& path, const RgbImageRef& a,
                          const RgbImageRef& b, double full_scale = 0.1);

// Writes a linear-RGB image as an 8-bit sRGB PNG (srgb8_from_linear; HDR values clip to 255).
Status write_png(const std::filesystem::path& path, const RgbImageRef& image);

// Writes a rendered frame as an OpenEXR with the ground-truth layout of format/CAPTURE.md:
// half R, G, B (linear) and float Z (radial depth from the eye, +inf for sky), so that it reads
// back with capture::read_perspective_image and opens beside calf-capture's ground truth.
Status write_exr(const std::filesystem::path& path, const RenderedImage& image);

}  // namespace calf::player
