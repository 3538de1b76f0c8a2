// PSNR, SSIM and per-pixel error of sRGB-encoded images (definitions in image_compare.h).
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "calf/format/colour.h"
#include "calf/player/image_compare.h"

namespace calf::player {

namespace {

std::string size_text(const RgbImageRef& i) {
  return std::to_string(i.width) + " x " + std::to_string(i.height);
}

// Both images non-empty, of one size, with buffers holding that many pixels.
Status check_pair(const RgbImageRef& a, const RgbImageRef& b) {
  for (const RgbImageRef* i : {&a, &b}) {
    const size_t want = size_t{3} * i->width * i->height;
    if (want == 0)
      return Status(ErrorId::kImageCompare, "an image is empty (" + size_text(*i) + ")");
    if (i->rgb.size() < want) {
      return Status(ErrorId::kImageCompare, "an image of " + size_text(*i) + " holds " +
                                                std::to_string(i->rgb.size()) + " floats, needs " +
                                                std::to_string(want));
    }
  }
  if (a.width != b.width || a.height != b.height) {
    return Status(ErrorId::kImageCompare,
                  "images differ in size: " + size_text(a) + " and " + size_text(b));
  }
  return Status::Ok();
}

// The sRGB-encoded, clamped luma of every pixel (BT.709 weights on encoded values).
std::vector<double> srgb_luma(const RgbImageRef& image) {
  const size_t n = size_t{image.width} * image.height;
  std::vector<double> y(n);
  for (size_t i = 0; i < n; ++i) {
    const float* p = &image.rgb[3 * i];
    y[i] = 0.2126 * srgb_from_linear(p[0]) + 0.7152 * srgb_from_linear(p[1]) +
           0.0722 * srgb_from_linear(p[2]);
  }
  return y;
}

// "Valid" separable filtering of `in` (w x h) with the normalised 11-tap Gaussian: the output
// has (w - 10) x (h - 10) values, each the window's weighted sum.
std::vector<double> gaussian_valid(const std::vector<double>& in, uint32_t w, uint32_t h,
                                   const double (&g)[kSsimWindow]) {
  const uint32_t ow = w - (kSsimWindow - 1), oh = h - (kSsimWindow - 1);
  std::vector<double> rows(size_t{ow} * h), out(size_t{ow} * oh);
  for (uint32_t y = 0; y < h; ++y) {
    for (uint32_t x = 0; x < ow; ++x) {
      double s = 0;
      for (uint32_t k = 0; k < kSsimWindow; ++k) s += g[k] * in[size_t{y} * w + x + k];
      rows[size_t{y} * ow + x] = s;
    }
  }
  for (uint32_t y = 0; y < oh; ++y) {
    for (uint32_t x = 0; x < ow; ++x) {
      double s = 0;
      for (uint32_t k = 0; k < kSsimWindow; ++k) s += g[k] * rows[size_t{y + k} * ow + x];
      out[size_t{y} * ow + x] = s;
    }
  }
  return out;
}

}  // namespace

Expected<double> psnr(const RgbImageRef& a, const RgbImageRef& b) {
  CALF_RETURN_IF_ERROR(check_pair(a, b));
  const size_t n = size_t{3} * a.width * a.height;
  double sum = 0;
  for (size_t i = 0; i < n; ++i) {
    const double d = double{srgb_from_linear(a.rgb[i])} - srgb_from_linear(b.rgb[i]);
    sum += d * d;
  }
  if (sum == 0) return std::numeric_limits<double>::infinity();
  return 10 * std::log10(static_cast<double>(n) / sum);
}

Expected<double> ssim(const RgbImageRef& a, const RgbImageRef& b) {
  CALF_RETURN_IF_ERROR(check_pair(a, b));
  if (a.width < kSsimWindow || a.height < kSsimWindow) {
    return Status(ErrorId::kImageCompare,
                  "images of " + size_text(a) + " are smaller than the 11 x 11 SSIM window");
  }
  double g[kSsimWindow], gsum = 0;
  for (uint32_t k = 0; k < kSsimWindow; ++k) {
    const double t = static_cast<double>(k) - (kSsimWindow - 1) / 2.0;
    g[k] = std::exp(-t * t / (2 * kSsimSigma * kSsimSigma));
    gsum += g[k];
  }
  for (double& v : g) v /= gsum;
  const std::vector<double> x = srgb_luma(a), y = srgb_luma(b);
  std::vector<double> xx(x.size()), yy(x.size()), xy(x.size());
  for (size_t i = 0; i < x.size(); ++i) {
    xx[i] = x[i] * x[i];
    yy[i] = y[i] * y[i];
    xy[i] = x[i] * y[i];
  }
  const uint32_t w = a.width, h = a.height;
  const std::vector<double> mx = gaussian_valid(x, w, h, g), my = gaussian_valid(y, w, h, g),
                            sxx = gaussian_valid(xx, w, h, g), syy = gaussian_valid(yy, w, h, g),
                            sxy = gaussian_valid(xy, w, h, g);
  constexpr double c1 = 0.01 * 0.01, c2 = 0.03 * 0.03;
  double sum = 0;
  for (size_t i = 0; i < mx.size(); ++i) {
    const double vx = sxx[i] - mx[i] * mx[i], vy = syy[i] - my[i] * my[i];
    const double cov = sxy[i] - mx[i] * my[i];
    sum += (2 * mx[i] * my[i] + c1) * (2 * cov + c2) /
           ((mx[i] * mx[i] + my[i] * my[i] + c1) * (vx + vy + c2));
  }
  return sum / static_cast<double>(mx.size());
}

Expected<std::vector<float>> error_map(const RgbImageRef& a, const RgbImageRef& b) {
  CALF_RETURN_IF_ERROR(check_pair(a, b));
  const size_t n = size_t{a.width} * a.height;
  std::vector<float> e(n);
  for (size_t i = 0; i < n; ++i) {
    double s = 0;
    for (int c = 0; c < 3; ++c) {
      const double d =
          double{srgb_from_linear(a.rgb[3 * i + c])} - srgb_from_linear(b.rgb[3 * i + c]);
      s += d * d;
    }
    e[i] = static_cast<float>(std::sqrt(s / 3));
  }
  return e;
}

Expected<MissingGeometry> missing_geometry(const RenderedImage& test,
                                           const RenderedImage& reference,
                                           const DepthTolerance& tolerance) {
  if (!(std::isfinite(tolerance.relative) && tolerance.relative >= 0 &&
        std::isfinite(tolerance.absolute) && tolerance.absolute >= 0)) {
    return Status(ErrorId::kImageCompareOption,
                  "depth tolerance " + std::to_string(tolerance.relative) + " relative, " +
                      std::to_string(tolerance.absolute) + " absolute is not finite and >= 0");
  }
  const size_t n = size_t{test.width} * test.height;
  if (n == 0 || test.width != reference.width || test.height != reference.height ||
      test.depth.size() < n || reference.depth.size() < n) {
    return Status(ErrorId::kImageCompare, "depth images of " + std::to_string(test.width) + " x " +
                                              std::to_string(test.height) + " and " +
                                              std::to_string(reference.width) + " x " +
                                              std::to_string(reference.height) +
                                              " are empty, differ in size or lack depth values");
  }
  MissingGeometry m;
  m.pixels = n;
  for (size_t i = 0; i < n; ++i) {
    const double r = reference.depth[i];
    if (!std::isfinite(r)) continue;
    const double t = test.depth[i];
    if (!(t <= r * (1 + tolerance.relative) + tolerance.absolute)) ++m.missing;
  }
  m.epsilon = static_cast<double>(m.missing) / static_cast<double>(n);
  return m;
}

std::array<uint8_t, 3> heat_colour(double t) {
  // Stops at t = 0, 1/4, 1/2, 3/4, 1: black, blue, cyan, yellow, red.
  static constexpr double kStops[5][3] = {{0, 0, 0}, {0, 0, 1}, {0, 1, 1}, {1, 1, 0}, {1, 0, 0}};
  if (std::isnan(t)) t = 1;
  t = std::clamp(t, 0.0, 1.0) * 4;
  const int i = std::min(static_cast<int>(t), 3);
  const double f = t - i;
  std::array<uint8_t, 3> c;
  for (int ch = 0; ch < 3; ++ch) {
    const double v = kStops[i][ch] + f * (kStops[i + 1][ch] - kStops[i][ch]);
    c[ch] = static_cast<uint8_t>(std::lround(255 * v));
  }
  return c;
}

}  // namespace calf::player
