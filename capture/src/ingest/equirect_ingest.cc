// Equirectangular colour + radial depth -> calf cube faces (format/CAPTURE.md, "Ingest"): colour
// is the mean of k x k filtered samples per texel (the equirectangular image oversamples towards
// its poles, so one sample would alias there), depth the nearest pixel's (or edge-aware bilinear).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <numbers>
#include <string>
#include <vector>

#include "calf/capture/capture_set.h"
#include "calf/capture/ingest.h"
#include "calf/format/cube.h"
#include "ingest_folder.h"
#include "ingest_image.h"
#include "json_fields.h"

namespace calf::capture {

Vec3 direction_from_equirect(double u, double v, uint32_t width, uint32_t height) {
  const double phi = 2 * std::numbers::pi * u / width - std::numbers::pi;
  const double theta = std::numbers::pi / 2 - std::numbers::pi * v / height;
  return {std::cos(theta) * std::sin(phi), std::sin(theta), -std::cos(theta) * std::cos(phi)};
}

void equirect_from_direction(const Vec3& d, uint32_t width, uint32_t height, double* u, double* v) {
  const double phi = std::atan2(d.x, -d.z);
  const double theta = std::atan2(d.y, std::hypot(d.x, d.z));
  *u = (phi + std::numbers::pi) / (2 * std::numbers::pi) * width;
  *v = (std::numbers::pi / 2 - theta) / std::numbers::pi * height;
}

namespace {

constexpr const char* kEquirectFormat = "calf-equirect-set";

// The equirectangular manifest is a capture-set manifest with another format name and no face
// size or material: checked by the capture-set rules after those two differences are removed.
Expected<CaptureManifest> parse_equirect_manifest(const std::string& text,
                                                  const std::string& source) {
  CALF_ASSIGN_OR_RETURN(detail::Json root, detail::parse_json_object(text, source));
  const auto format = root.find("format");
  if (format == root.end() || !format->is_string() ||
      format->get<std::string>() != kEquirectFormat) {
    return Status(ErrorId::kEquirectInput,
                  source + ": field 'format': expected \"" + kEquirectFormat + "\"");
  }
  for (const char* key : {"face_size", "material"}) {
    if (root.contains(key)) {
      return Status(ErrorId::kEquirectInput,
                    source + ": field '" + key + "': not allowed in an equirectangular set");
    }
  }
  root["format"] = "calf-capture-set";
  root["face_size"] = 1;
  return parse_manifest(detail::dump_json(root), source);
}

struct Equirect {
  uint32_t w = 0, h = 0;
  std::vector<float> rgb, depth;
};

Status load(const std::filesystem::path& path, uint64_t max_pixels, Equirect* e) {
  detail::NamedPlanes planes;
  // Every image after the first has the first one's size, checked from its header.
  detail::ImageExpect expect;
  expect.width = e->w;
  expect.height = e->h;
  expect.wrong_size = ErrorId::kEquirectInput;
  expect.expected_by = "the first image is";
  expect.max_pixels = max_pixels;
  CALF_RETURN_IF_ERROR(detail::read_named_planes(
      path, {"R", "G", "B", "Z"}, std::vector<detail::PngSamples>(4, detail::PngSamples::kLinear),
      ErrorId::kEquirectInput, expect, &planes));
  const std::string p = path.string();
  if (planes.width != 2 * planes.height) {
    return Status(ErrorId::kEquirectInput, p + ": is " + std::to_string(planes.width) + " x " +
                                               std::to_string(planes.height) +
                                               ", an equirectangular image is 2:1");
  }
  if (e->w && (e->w != planes.width || e->h != planes.height)) {
    return Status(ErrorId::kEquirectInput, p + ": is " + std::to_string(planes.width) + " x " +
                                               std::to_string(planes.height) +
                                               ", the first image " + std::to_string(e->w) + " x " +
                                               std::to_string(e->h));
  }
  e->w = planes.width;
  e->h = planes.height;
  const size_t n = size_t{e->w} * e->h;
  e->rgb.resize(3 * n);
  e->depth.resize(n);
  for (size_t k = 0; k < n; ++k) {
    for (int c = 0; c < 3; ++c) {
      const float v = planes.planes[c][k];
      if (!(v >= 0) || !std::isfinite(v)) {
        return Status(ErrorId::kEquirectInput, p + ": pixel (" + std::to_string(k % e->w) + ", " +
                                                   std::to_string(k / e->w) +
                                                   ") colour is negative or not finite");
      }
      e->rgb[3 * k + c] = v;
    }
    const float z = planes.planes[3][k];
    if (!(z > 0)) {
      return Status(ErrorId::kEquirectInput, p + ": pixel (" + std::to_string(k % e->w) + ", " +
                                                 std::to_string(k / e->w) +
                                                 ") depth is NaN, zero or negative (sky is +inf)");
    }
    e->depth[k] = z;
  }
  return Status::Ok();
}

// Reads an equirectangular image between pixel centres: longitude wraps, latitude clamps at the
// poles' rows.
class EquirectSampler {
 public:
  EquirectSampler(const Equirect& e, EquirectFilter filter, double sharpen)
      : e_(e), filter_(filter) {
    if (sharpen > 0) sharpen_pixels(sharpen);
  }

  // Colour at image position (u, v) (pixel (i, j)'s centre is (i + 0.5, j + 0.5)).
  void colour(double u, double v, double rgb[3]) const {
    const double fx = u - 0.5, fy = v - 0.5;
    const double x0 = std::floor(fx), y0 = std::floor(fy);
    const double tx = fx - x0, ty = fy - y0;
    const auto x = static_cast<int64_t>(x0), y = static_cast<int64_t>(y0);
    rgb[0] = rgb[1] = rgb[2] = 0;
    if (filter_ == EquirectFilter::kBilinear) {
      const double wx[2] = {1 - tx, tx}, wy[2] = {1 - ty, ty};
      for (int b = 0; b < 2; ++b) {
        for (int a = 0; a < 2; ++a) add(x + a, y + b, wx[a] * wy[b], rgb);
      }
    } else {
      double wx[4], wy[4];
      catmull_rom(tx, wx);
      catmull_rom(ty, wy);
      for (int b = 0; b < 4; ++b) {
        for (int a = 0; a < 4; ++a) add(x + a - 1, y + b - 1, wx[a] * wy[b], rgb);
      }
    }
    // The kernel's lobes (and the sharpening's) undershoot next to an HDR edge.
    for (int c = 0; c < 3; ++c) rgb[c] = std::max(0.0, rgb[c]);
  }

  // Depth along image position (u, v).
  float depth(double u, double v, EquirectDepth mode) const {
    const float nearest =
        e_.depth[index(static_cast<int64_t>(std::floor(u)), static_cast<int64_t>(std::floor(v)))];
    if (mode == EquirectDepth::kNearest) return nearest;
    const double fx = u - 0.5, fy = v - 0.5;
    const double x0 = std::floor(fx), y0 = std::floor(fy);
    const double tx = fx - x0, ty = fy - y0;
    const auto x = static_cast<int64_t>(x0), y = static_cast<int64_t>(y0);
    float z[4];
    float lo = INFINITY, hi = 0;
    for (int k = 0; k < 4; ++k) {
      z[k] = e_.depth[index(x + (k & 1), y + (k >> 1))];
      lo = std::min(lo, z[k]);
      hi = std::max(hi, z[k]);
    }
    // Sky (+inf) or two surfaces: no depth between them is real.
    if (!std::isfinite(hi) || hi > 1.02f * lo) return nearest;
    return static_cast<float>((1 - ty) * ((1 - tx) * z[0] + tx * z[1]) +
                              ty * ((1 - tx) * z[2] + tx * z[3]));
  }

 private:
  static void catmull_rom(double t, double w[4]) {
    const double t2 = t * t, t3 = t2 * t;
    w[0] = 0.5 * (-t + 2 * t2 - t3);
    w[1] = 0.5 * (2 - 5 * t2 + 3 * t3);
    w[2] = 0.5 * (t + 4 * t2 - 3 * t3);
    w[3] = 0.5 * (-t2 + t3);
  }

  size_t index(int64_t x, int64_t y) const {
    const int64_t w = e_.w, h = e_.h;
    const int64_t xm = ((x % w) + w) % w;
    const int64_t ym = std::clamp<int64_t>(y, 0, h - 1);
    return static_cast<size_t>(ym * w + xm);
  }

  void add(int64_t x, int64_t y, double weight, double rgb[3]) const {
    const float* p = (sharp_.empty() ? e_.rgb.data() : sharp_.data()) + 3 * index(x, y);
    for (int c = 0; c < 3; ++c) rgb[c] += weight * p[c];
  }

  // [-a, 1 + 2a, -a] along x, then along y (variance -2a pixel^2; a one-pixel box's is +1/12).
  void sharpen_pixels(double a) {
    const size_t n = size_t{e_.w} * e_.h;
    std::vector<float> row(3 * n);
    for (int64_t y = 0; y < e_.h; ++y) {
      for (int64_t x = 0; x < e_.w; ++x) {
        for (int c = 0; c < 3; ++c) {
          const double l = e_.rgb[3 * index(x - 1, y) + c], m = e_.rgb[3 * index(x, y) + c],
                       r = e_.rgb[3 * index(x + 1, y) + c];
          row[3 * index(x, y) + c] = static_cast<float>((1 + 2 * a) * m - (l + r) * a);
        }
      }
    }
    sharp_.resize(3 * n);
    for (int64_t y = 0; y < e_.h; ++y) {
      for (int64_t x = 0; x < e_.w; ++x) {
        for (int c = 0; c < 3; ++c) {
          const double t = row[3 * index(x, y - 1) + c], m = row[3 * index(x, y) + c],
                       b = row[3 * index(x, y + 1) + c];
          sharp_[3 * index(x, y) + c] = static_cast<float>((1 + 2 * a) * m - (t + b) * a);
        }
      }
    }
  }

  const Equirect& e_;
  EquirectFilter filter_;
  std::vector<float> sharp_;  // the sharpened colour (empty: none)
};

void resample(const Equirect& e, uint32_t n, const IngestOptions& options, ViewFrame* out) {
  const EquirectSampler sampler(e, options.equirect_filter, options.equirect_sharpen);
  const uint32_t ss = options.supersample;
  for (int f = 0; f < kCubeFaceCount; ++f) {
    const CubeFace face = cube_face_from_index(f);
    for (uint32_t y = 0; y < n; ++y) {
      for (uint32_t x = 0; x < n; ++x) {
        double sum[3] = {0, 0, 0};
        for (uint32_t b = 0; b < ss; ++b) {
          for (uint32_t a = 0; a < ss; ++a) {
            const Vec3 d =
                direction_from_texel_coord({face, x + (a + 0.5) / ss, y + (b + 0.5) / ss}, n);
            double u, v, rgb[3];
            equirect_from_direction(d, e.w, e.h, &u, &v);
            sampler.colour(u, v, rgb);
            for (int c = 0; c < 3; ++c) sum[c] += rgb[c];
          }
        }
        const size_t t = out->texel_index(face, x, y);
        for (int c = 0; c < 3; ++c) out->color[3 * t + c] = static_cast<float>(sum[c] / (ss * ss));
        double u, v;
        equirect_from_direction(direction_from_texel(face, x, y, n), e.w, e.h, &u, &v);
        out->depth[t] = sampler.depth(u, v, options.equirect_depth);
      }
    }
  }
}

}  // namespace

Status ingest_equirect(const std::filesystem::path& manifest_path,
                       const std::filesystem::path& out_dir, const IngestOptions& options,
                       IngestReport* report) {
  return ingest_equirect(std::vector<std::filesystem::path>{manifest_path}, out_dir, options,
                         report);
}

Status ingest_equirect(const std::vector<std::filesystem::path>& manifests,
                       const std::filesystem::path& out_dir, const IngestOptions& options,
                       IngestReport* report) {
  if (manifests.empty() || manifests.size() > 1000000) {
    return Status(ErrorId::kInvalidArgument,
                  "an equirectangular sequence needs 1..1000000 manifests, not " +
                      std::to_string(manifests.size()));
  }
  const std::string source = manifests[0].string();
  if (options.supersample < 1 || options.supersample > 8) {
    return Status(ErrorId::kInvalidArgument,
                  "supersample " + std::to_string(options.supersample) + " is outside 1..8");
  }
  if (!(options.equirect_sharpen >= 0 && options.equirect_sharpen <= 0.25)) {
    return Status(ErrorId::kInvalidArgument,
                  "sharpen " + std::to_string(options.equirect_sharpen) + " is outside 0..0.25");
  }
  const auto check_faces = [&](const std::string& what, uint32_t n) {
    return check_image_budget(what + std::to_string(n), n, n, options.max_image_pixels, 6);
  };
  if (options.face_size) CALF_RETURN_IF_ERROR(check_faces("face size ", options.face_size));
  // Every manifest first: the same rig, volume and fps as the first, frames added up.
  std::vector<CaptureManifest> inputs;
  uint64_t frame_total = 0;
  for (const std::filesystem::path& path : manifests) {
    CALF_ASSIGN_OR_RETURN(std::string text, read_small_file(path));
    CALF_ASSIGN_OR_RETURN(CaptureManifest in, parse_equirect_manifest(text, path.string()));
    if (!inputs.empty()) {
      const CaptureManifest& a = inputs[0];
      const char* what = a.viewpoints != in.viewpoints        ? "viewpoints"
                         : !(a.view_volume == in.view_volume) ? "view_volume"
                         : a.fps != in.fps                    ? "fps"
                                                              : nullptr;
      if (what) {
        return Status(ErrorId::kEquirectInput,
                      path.string() + " (a part of the sequence): its " + what + " differ from " +
                          source + "'s (the first part); every part must be the same rig");
      }
    }
    frame_total += in.frame_count;
    if (frame_total > 1000000) {
      return Status(ErrorId::kCaptureLimit, path.string() +
                                                ": the sequence has more than "
                                                "1000000 frames");
    }
    inputs.push_back(std::move(in));
  }
  std::filesystem::path dir = manifests[0].parent_path();
  // The first image decides the face size (and every other image must match it).
  Equirect image;
  CALF_RETURN_IF_ERROR(
      load(dir / capture_file_name(inputs[0], 0, 0), options.max_image_pixels, &image));
  CaptureManifest m = inputs[0];
  m.frame_count = static_cast<uint32_t>(frame_total);
  m.generator = "calf-ingest";
  m.file_pattern = kDefaultFilePattern;
  m.face_size =
      options.face_size
          ? options.face_size
          : std::max<uint32_t>(1, static_cast<uint32_t>(std::lround(image.w / std::numbers::pi)));
  if (!options.face_size) {
    CALF_RETURN_IF_ERROR(
        check_faces(source + ": the face size the first image implies, ", m.face_size));
  }
  // A failed ingest removes the folders it created (remove_empty_folders after abandon()).
  std::vector<std::filesystem::path> created;
  CALF_ASSIGN_OR_RETURN(CaptureSetWriter writer,
                        detail::create_ingest_writer(out_dir, m, &created));
  ViewFrame frame;
  frame.resize(m.face_size, false);
  uint32_t out_frame = 0;
  for (size_t part = 0; part < inputs.size(); ++part) {
    const CaptureManifest& input = inputs[part];
    dir = manifests[part].parent_path();
    for (uint32_t v = 0; v < m.viewpoints.size(); ++v) {
      for (uint32_t f = 0; f < input.frame_count; ++f) {
        Status s;
        if (part != 0 || v != 0 || f != 0) {
          s = load(dir / capture_file_name(input, v, f), options.max_image_pixels, &image);
        }
        if (s.ok()) {
          resample(image, m.face_size, options, &frame);
          s = writer.write(v, out_frame + f, frame);
        }
        if (!s.ok()) {
          writer.abandon();
          detail::remove_empty_folders(created);
          return s;
        }
      }
    }
    out_frame += input.frame_count;
  }
  if (Status s = writer.finish(); !s.ok()) {
    writer.abandon();
    detail::remove_empty_folders(created);
    return s;
  }
  if (report) {
    *report = {static_cast<uint32_t>(m.viewpoints.size()), m.frame_count, m.face_size, 0};
  }
  return Status::Ok();
}

}  // namespace calf::capture
