// Equirectangular colour + radial depth -> calf cube faces (format/CAPTURE.md, "Ingest"): colour
// is the mean of k x k bilinear samples per texel (the equirectangular image oversamples towards
// its poles, so one sample would alias there), depth the nearest pixel's.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <vector>

#include "calf/capture/capture_set.h"
#include "calf/capture/ingest.h"
#include "calf/format/cube.h"
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

Status load(const std::filesystem::path& path, Equirect* e) {
  detail::NamedPlanes planes;
  CALF_RETURN_IF_ERROR(detail::read_named_planes(
      path, {"R", "G", "B", "Z"}, std::vector<detail::PngSamples>(4, detail::PngSamples::kLinear),
      ErrorId::kEquirectInput, &planes));
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

void resample(const Equirect& e, uint32_t n, uint32_t ss, ViewFrame* out) {
  const auto wrap = [&](double x) {
    const double m = std::fmod(x, static_cast<double>(e.w));
    return static_cast<uint32_t>(m < 0 ? m + e.w : m) % e.w;
  };
  const auto clamp_row = [&](double y) {
    return static_cast<uint32_t>(std::clamp(y, 0.0, static_cast<double>(e.h - 1)));
  };
  for (int f = 0; f < kCubeFaceCount; ++f) {
    const CubeFace face = cube_face_from_index(f);
    for (uint32_t y = 0; y < n; ++y) {
      for (uint32_t x = 0; x < n; ++x) {
        double sum[3] = {0, 0, 0};
        for (uint32_t b = 0; b < ss; ++b) {
          for (uint32_t a = 0; a < ss; ++a) {
            const Vec3 d =
                direction_from_texel_coord({face, x + (a + 0.5) / ss, y + (b + 0.5) / ss}, n);
            double u, v;
            equirect_from_direction(d, e.w, e.h, &u, &v);
            const double fx = u - 0.5, fy = v - 0.5;
            const double x0 = std::floor(fx), y0 = std::floor(fy);
            const double tx = fx - x0, ty = fy - y0;
            const uint32_t xa = wrap(x0), xb = wrap(x0 + 1);
            const uint32_t ya = clamp_row(y0), yb = clamp_row(y0 + 1);
            for (int c = 0; c < 3; ++c) {
              const auto at = [&](uint32_t i, uint32_t j) {
                return static_cast<double>(e.rgb[3 * (size_t{j} * e.w + i) + c]);
              };
              sum[c] += (1 - ty) * ((1 - tx) * at(xa, ya) + tx * at(xb, ya)) +
                        ty * ((1 - tx) * at(xa, yb) + tx * at(xb, yb));
            }
          }
        }
        const size_t t = out->texel_index(face, x, y);
        for (int c = 0; c < 3; ++c) out->color[3 * t + c] = static_cast<float>(sum[c] / (ss * ss));
        double u, v;
        equirect_from_direction(direction_from_texel(face, x, y, n), e.w, e.h, &u, &v);
        out->depth[t] = e.depth[size_t{clamp_row(std::floor(v))} * e.w + wrap(std::floor(u))];
      }
    }
  }
}

}  // namespace

Status ingest_equirect(const std::filesystem::path& manifest_path,
                       const std::filesystem::path& out_dir, const IngestOptions& options,
                       IngestReport* report) {
  const std::string source = manifest_path.string();
  if (options.supersample < 1 || options.supersample > 8) {
    return Status(ErrorId::kInvalidArgument,
                  "supersample " + std::to_string(options.supersample) + " is outside 1..8");
  }
  CALF_ASSIGN_OR_RETURN(std::string text, read_small_file(manifest_path));
  CALF_ASSIGN_OR_RETURN(CaptureManifest input, parse_equirect_manifest(text, source));
  const std::filesystem::path dir = manifest_path.parent_path();
  // The first image decides the face size (and every other image must match it).
  Equirect image;
  CALF_RETURN_IF_ERROR(load(dir / capture_file_name(input, 0, 0), &image));
  CaptureManifest m = input;
  m.generator = "calf-ingest";
  m.file_pattern = kDefaultFilePattern;
  m.face_size =
      options.face_size
          ? options.face_size
          : std::max<uint32_t>(1, static_cast<uint32_t>(std::lround(image.w / std::numbers::pi)));
  CALF_ASSIGN_OR_RETURN(CaptureSetWriter writer, CaptureSetWriter::create(out_dir, m));
  ViewFrame frame;
  frame.resize(m.face_size, false);
  for (uint32_t v = 0; v < m.viewpoints.size(); ++v) {
    for (uint32_t f = 0; f < m.frame_count; ++f) {
      Status s;
      if (v != 0 || f != 0) s = load(dir / capture_file_name(input, v, f), &image);
      if (s.ok()) {
        resample(image, m.face_size, options.supersample, &frame);
        s = writer.write(v, f, frame);
      }
      if (!s.ok()) {
        writer.abandon();
        return s;
      }
    }
  }
  if (Status s = writer.finish(); !s.ok()) {
    writer.abandon();
    return s;
  }
  if (report) {
    *report = {static_cast<uint32_t>(m.viewpoints.size()), m.frame_count, m.face_size, 0};
  }
  return Status::Ok();
}

}  // namespace calf::capture
