// The error breakdown of calf-play --compare (definitions in error_breakdown.h).
#include "calf/player/error_breakdown.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "calf/format/cube.h"
#include "calf/player/contact_sheet.h"

namespace calf::player {

const char* error_class_name(ErrorClass c) {
  switch (c) {
    case ErrorClass::kShading:
      return "shading";
    case ErrorClass::kSilhouette:
      return "silhouette";
    case ErrorClass::kDisocclusion:
      return "disocclusion";
    case ErrorClass::kCodec:
      return "codec";
    case ErrorClass::kGeometry:
      return "geometry";
  }
  return "?";
}

double ErrorBreakdown::total() const {
  double t = 0;
  for (double s : squared) t += s;
  return t;
}

double ErrorBreakdown::share(ErrorClass c) const {
  const double t = total();
  return t > 0 ? squared[static_cast<size_t>(c)] / t : 0.0;
}

double ErrorBreakdown::pixel_share(ErrorClass c) const {
  return pixel_count > 0 ? double(pixels[static_cast<size_t>(c)]) / double(pixel_count) : 0.0;
}

ErrorBreakdown& ErrorBreakdown::operator+=(const ErrorBreakdown& other) {
  for (size_t c = 0; c < kErrorClassCount; ++c) {
    squared[c] += other.squared[c];
    pixels[c] += other.pixels[c];
  }
  pixel_count += other.pixel_count;
  codec_measured = codec_measured || other.codec_measured;
  return *this;
}

Expected<CaptureVisibility> CaptureVisibility::load(const capture::CaptureSetReader& reader,
                                                    uint32_t frame) {
  CaptureVisibility out;
  const capture::CaptureManifest& m = reader.manifest();
  out.face_size_ = m.face_size;
  out.frame_ = frame;
  capture::ViewFrame view;
  for (uint32_t v = 0; v < m.viewpoints.size(); ++v) {
    CALF_RETURN_IF_ERROR(reader.read(v, frame, &view));
    out.positions_.push_back(m.viewpoints[v].position);
    out.depth_.push_back(std::move(view.depth));
    view = capture::ViewFrame{};
  }
  return out;
}

bool CaptureVisibility::seen(const Vec3& p, double tolerance) const {
  const uint32_t n = face_size_;
  for (size_t v = 0; v < positions_.size(); ++v) {
    const Vec3 d = p - positions_[v];
    const double r = length(d);
    if (!(r > 0)) return true;  // the viewpoint itself
    const Texel t = texel_from_direction(d, n);
    const float* face =
        depth_[v].data() + size_t{static_cast<uint32_t>(cube_face_index(t.face))} * n * n;
    // The nearest texel and its neighbours on the face: the view's depth is point-sampled, and
    // P may lie between texel centres on a slope.
    const uint32_t x0 = t.x > 0 ? t.x - 1 : 0, x1 = std::min(t.x + 1, n - 1);
    const uint32_t y0 = t.y > 0 ? t.y - 1 : 0, y1 = std::min(t.y + 1, n - 1);
    for (uint32_t y = y0; y <= y1; ++y) {
      for (uint32_t x = x0; x <= x1; ++x) {
        const float depth = face[size_t{y} * n + x];
        if (std::isfinite(depth) && std::abs(depth - r) <= tolerance * r) return true;
      }
    }
  }
  return false;
}

namespace {

// Whether pixels a and b (depths) lie across a depth edge.
bool depth_edge(float a, float b, double ratio) {
  const bool fa = std::isfinite(a), fb = std::isfinite(b);
  if (fa != fb) return true;
  if (!fa) return false;
  return std::abs(double{a} - b) > ratio * std::min(a, b);
}

}  // namespace

Expected<ErrorBreakdown> classify_errors(const RenderedImage& test,
                                         const capture::PerspectiveImage& truth, const Camera& eye,
                                         const CaptureVisibility& views,
                                         const RgbImageRef* lossless,
                                         const ErrorBreakdownOptions& options,
                                         std::vector<uint8_t>* classes,
                                         std::vector<float>* squared_out) {
  if (!(options.visibility_tolerance > 0 && options.visibility_tolerance < 1) ||
      !(options.silhouette_ratio > 0 && std::isfinite(options.silhouette_ratio)) ||
      options.silhouette_radius > 16) {
    return Status(ErrorId::kImageCompareOption,
                  "error breakdown: visibility_tolerance must lie in (0, 1), silhouette_ratio be "
                  "positive and silhouette_radius at most 16");
  }
  const uint32_t w = eye.width, h = eye.height;
  const size_t n = size_t{w} * h;
  if (truth.width != w || truth.height != h || truth.depth.size() < n) {
    return Status(ErrorId::kImageCompare,
                  "error breakdown: the ground truth is " + std::to_string(truth.width) + " x " +
                      std::to_string(truth.height) + " with " + std::to_string(truth.depth.size()) +
                      " depths, the pose " + std::to_string(w) + " x " + std::to_string(h));
  }
  const bool has_test_depth = !test.depth.empty();
  if (has_test_depth && test.depth.size() < n) {
    return Status(ErrorId::kImageCompare, "error breakdown: the reconstruction has " +
                                              std::to_string(test.depth.size()) + " depths for " +
                                              std::to_string(n) + " pixels");
  }
  auto err = error_map(rgb_ref(test), rgb_ref(truth));
  if (!err.ok()) return err.status();
  std::vector<float> err_lossless;
  if (lossless != nullptr) {
    auto e = error_map(*lossless, rgb_ref(truth));
    if (!e.ok()) return e.status();
    err_lossless = std::move(*e);
  }
  // Depth edges between 4-neighbours, then grown by the radius.
  std::vector<uint8_t> edge(n, 0);
  const std::vector<float>& z = truth.depth;
  for (uint32_t y = 0; y < h; ++y) {
    for (uint32_t x = 0; x < w; ++x) {
      const size_t i = size_t{y} * w + x;
      if (x + 1 < w && depth_edge(z[i], z[i + 1], options.silhouette_ratio))
        edge[i] = edge[i + 1] = 1;
      if (y + 1 < h && depth_edge(z[i], z[i + w], options.silhouette_ratio))
        edge[i] = edge[i + w] = 1;
    }
  }
  std::vector<uint8_t> near_edge = edge;
  const int radius = static_cast<int>(options.silhouette_radius);
  if (radius > 0) {
    for (uint32_t y = 0; y < h; ++y) {
      for (uint32_t x = 0; x < w; ++x) {
        if (!edge[size_t{y} * w + x]) continue;
        for (int dy = -radius; dy <= radius; ++dy) {
          for (int dx = -radius; dx <= radius; ++dx) {
            const int xx = int(x) + dx, yy = int(y) + dy;
            if (xx >= 0 && yy >= 0 && xx < int(w) && yy < int(h))
              near_edge[size_t(yy) * w + xx] = 1;
          }
        }
      }
    }
  }

  ErrorBreakdown out;
  out.pixel_count = n;
  out.codec_measured = lossless != nullptr;
  if (classes) classes->assign(n, static_cast<uint8_t>(ErrorClass::kShading));
  if (squared_out) squared_out->assign(n, 0.0f);
  const CameraFrame frame = camera_frame(eye);
  for (uint32_t y = 0; y < h; ++y) {
    for (uint32_t x = 0; x < w; ++x) {
      const size_t i = size_t{y} * w + x;
      const double e2 = double{(*err)[i]} * (*err)[i];
      double codec = 0;
      if (lossless != nullptr) {
        const double l2 = double{err_lossless[i]} * err_lossless[i];
        codec = std::max(0.0, e2 - l2);
      }
      const double rest = e2 - codec;
      ErrorClass c = ErrorClass::kShading;
      if (std::isfinite(z[i]) &&
          !views.seen(eye.position + camera_ray(eye, frame, x, y) * double{z[i]},
                      options.visibility_tolerance)) {
        c = ErrorClass::kDisocclusion;
      } else if (near_edge[i]) {
        c = ErrorClass::kSilhouette;
      } else if (has_test_depth) {
        const float d = test.depth[i];
        const bool other_surface =
            std::isfinite(z[i]) != std::isfinite(d) ||
            (std::isfinite(d) && std::abs(double{d} - z[i]) > options.visibility_tolerance * z[i]);
        if (other_surface) c = ErrorClass::kGeometry;
      }
      out.squared[static_cast<size_t>(c)] += rest;
      out.squared[static_cast<size_t>(ErrorClass::kCodec)] += codec;
      const ErrorClass most = codec > rest ? ErrorClass::kCodec : c;
      ++out.pixels[static_cast<size_t>(most)];
      if (classes) (*classes)[i] = static_cast<uint8_t>(most);
      if (squared_out) (*squared_out)[i] = static_cast<float>(e2);
    }
  }
  return out;
}

Status write_error_class_png(const std::filesystem::path& path, uint32_t width, uint32_t height,
                             const std::vector<uint8_t>& classes, const std::vector<float>& squared,
                             double full_scale) {
  const size_t n = size_t{width} * height;
  if (n == 0 || classes.size() != n || squared.size() != n) {
    return Status(ErrorId::kImageCompare, "error class map: " + std::to_string(classes.size()) +
                                              " classes and " + std::to_string(squared.size()) +
                                              " errors for " + std::to_string(width) + " x " +
                                              std::to_string(height) + " pixels");
  }
  if (!(full_scale > 0 && full_scale <= 1)) {
    return Status(
        ErrorId::kImageCompareOption,
        "error class map: full scale " + std::to_string(full_scale) + " is outside (0, 1]");
  }
  // Shading blue, silhouette yellow, disocclusion red, codec green, geometry magenta.
  static constexpr uint8_t kColour[kErrorClassCount][3] = {
      {64, 128, 255}, {255, 220, 0}, {255, 40, 40}, {40, 255, 80}, {255, 64, 255}};
  Rgb8Image image{width, height, std::vector<uint8_t>(3 * n)};
  for (size_t i = 0; i < n; ++i) {
    const double t = std::min(1.0, std::sqrt(std::max(0.0f, squared[i])) / full_scale);
    const uint8_t* c = kColour[std::min<size_t>(classes[i], kErrorClassCount - 1)];
    for (int k = 0; k < 3; ++k) image.rgb[3 * i + k] = static_cast<uint8_t>(std::lround(c[k] * t));
  }
  return write_png_rgb8(path, image);
}

}  // namespace calf::player
