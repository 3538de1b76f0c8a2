// Capture-set reader and writer (format/CAPTURE.md, "Images").
#include "calf/capture/capture_set.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <system_error>

#include "calf/format/files.h"
#include "calf/format/log_depth.h"
#include "exr_io.h"

namespace calf::capture {

namespace {

// The largest finite half; colour above it would turn into +inf in the file.
constexpr float kHalfMax = 65504.0f;
// Half rounding of two weights that sum to 1 may exceed 1 by a few ulps.
constexpr float kWeightSlack = 2e-3f;

const char* const kMaterialChannels[3] = {"material.reflect", "material.refract", "material.ior"};
const char* const kCoverageChannels[3] = {"coverage.near", "coverage.far", "coverage.mask"};

std::string texel_text(const ViewFrame& f, size_t index) {
  size_t n = f.face_size;
  size_t face = index / (n * n);
  size_t y = index / n % n;
  size_t x = index % n;
  return std::string("face ") + cube_face_name(cube_face_from_index(static_cast<int>(face))) +
         " texel (" + std::to_string(x) + ", " + std::to_string(y) + ")";
}

std::string value_text(float v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", static_cast<double>(v));
  return buf;
}

}  // namespace

double coverage_tolerance(uint32_t face_size) {
  return std::min(4.0 / std::max(face_size, 1u), 0.05);
}

void ViewFrame::resize(uint32_t size, bool with_material, bool with_coverage) {
  face_size = size;
  has_material = with_material;
  has_coverage = with_coverage;
  color.resize(texel_count() * 3);
  depth.resize(texel_count());
  material.resize(with_material ? texel_count() * 3 : 0);
  coverage.resize(with_coverage ? texel_count() * 3 : 0);
}

Status validate_view_frame(const ViewFrame& f, std::string_view context) {
  std::string ctx(context);
  const size_t n = f.texel_count();
  if (f.color.size() != 3 * n || f.depth.size() != n ||
      f.material.size() != (f.has_material ? 3 * n : 0) ||
      f.coverage.size() != (f.has_coverage ? 3 * n : 0)) {
    return Status(ErrorId::kCaptureWriterMisuse,
                  ctx + ": buffer sizes do not match face size " + std::to_string(f.face_size));
  }
  for (size_t i = 0; i < n; ++i) {
    float z = f.depth[i];
    if (classify_depth(z) == DepthClass::kInvalid) {
      return Status(ErrorId::kCaptureDepthPixel, ctx + ": " + texel_text(f, i) + ": depth " +
                                                     value_text(z) +
                                                     " (expected > 0, or +inf for sky)");
    }
    for (int c = 0; c < 3; ++c) {
      float v = f.color[3 * i + c];
      if (!(v >= 0 && v <= kHalfMax)) {
        return Status(ErrorId::kCaptureColourPixel,
                      ctx + ": " + texel_text(f, i) + ": colour channel " + "RGB"[c] + " is " +
                          value_text(v) + " (expected finite, >= 0 and <= 65504)");
      }
    }
    if (f.has_material) {
      float rfl = f.material[3 * i], rfr = f.material[3 * i + 1], ior = f.material[3 * i + 2];
      bool weights_ok =
          rfl >= 0 && rfl <= 1 && rfr >= 0 && rfr <= 1 && rfl + rfr <= 1 + kWeightSlack;
      if (!weights_ok || !(std::isfinite(ior) && ior > 0)) {
        return Status(ErrorId::kCaptureMaterialPixel,
                      ctx + ": " + texel_text(f, i) + ": material (" + value_text(rfl) + ", " +
                          value_text(rfr) + ", " + value_text(ior) +
                          ") (expected weights in [0, 1] summing to <= 1 and IOR > 0)");
      }
    }
    if (f.has_coverage) {
      float near = f.coverage[3 * i], far = f.coverage[3 * i + 1], mask = f.coverage[3 * i + 2];
      if (!(near >= 0 && near <= 1 && far >= 0 && far <= 1 && near + far <= 1 + kWeightSlack) ||
          !(mask >= 0 && mask <= 65535 && mask == std::floor(mask))) {
        return Status(ErrorId::kCaptureImageFormat,
                      ctx + ": " + texel_text(f, i) + ": coverage (near " + value_text(near) +
                          ", far " + value_text(far) + ", mask " + value_text(mask) +
                          ") (expected shares in [0, 1] summing to <= 1, a mask 0..65535)");
      }
    }
  }
  return Status::Ok();
}

Expected<std::string> read_small_file(const std::filesystem::path& path,
                                      std::string_view what_if_missing) {
  // istreambuf_iterator would let libstdc++'s filebuf throw on a directory (EISDIR); a regular
  // file check first, then istream::read, which turns read errors into badbit.
  // A directory or FIFO is refused by stat, before an open could block.
  std::error_code ec;
  const std::filesystem::file_status st = std::filesystem::status(path, ec);
  const bool regular = std::filesystem::is_regular_file(st);
  std::ifstream in;
  if (regular) in.open(path, std::ios::binary);
  if (!regular || !in) {
    std::string why = ": cannot open";
    if (std::filesystem::exists(st) && !regular) {
      why += std::string(" (") +
             (std::filesystem::is_directory(st) ? "a directory"
              : std::filesystem::is_fifo(st)    ? "a FIFO"
                                                : "not a regular file") +
             ")";
    }
    return Status(ErrorId::kFileOpen, path.string() + why + std::string(what_if_missing));
  }
  std::string text;
  char buffer[1 << 14];
  while (in.read(buffer, sizeof buffer) || in.gcount() > 0) {
    text.append(buffer, static_cast<size_t>(in.gcount()));
  }
  if (in.bad()) return Status(ErrorId::kFileRead, path.string() + ": read failed");
  return text;
}

Status write_file_atomically(const std::filesystem::path& path, std::string_view bytes) {
  // The output rules, temporary name and cleanup on a signal are files::TempFile's.
  CALF_ASSIGN_OR_RETURN(files::TempFile temp, files::TempFile::create(path.string()));
  CALF_RETURN_IF_ERROR(
      temp.write(std::span(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size())));
  return temp.commit(/*sync=*/false);
}

// ---- reader ------------------------------------------------------------------------------------

Expected<CaptureSetReader> CaptureSetReader::open(const std::filesystem::path& directory,
                                                  uint64_t max_image_pixels) {
  std::filesystem::path manifest_path = directory / kManifestFileName;
  CALF_ASSIGN_OR_RETURN(
      std::string text,
      read_small_file(manifest_path, " (not a capture set, or an incomplete one)"));
  CALF_ASSIGN_OR_RETURN(CaptureManifest m, parse_manifest(text, manifest_path.string()));
  CALF_RETURN_IF_ERROR(
      check_image_budget(manifest_path.string() + ": face size " + std::to_string(m.face_size),
                         m.face_size, m.face_size, max_image_pixels, 6));
  return CaptureSetReader(directory, std::move(m));
}

std::filesystem::path CaptureSetReader::image_path(uint32_t view, uint32_t frame) const {
  return directory_ / capture_file_name(manifest_, view, frame);
}

Status CaptureSetReader::check_files() const {
  for (uint32_t v = 0; v < manifest_.viewpoints.size(); ++v) {
    for (uint32_t f = 0; f < manifest_.frame_count; ++f) {
      std::error_code ec;
      std::filesystem::path p = image_path(v, f);
      const std::string where =
          " (view " + std::to_string(v) + ", frame " + std::to_string(f) + ")";
      // Missing is E135; a directory or FIFO under an image's name is E002 "not a regular file".
      if (Status s = files::check_regular_file(p.string()); !s.ok()) {
        if (!std::filesystem::exists(p, ec))
          return Status(ErrorId::kCaptureFileMissing, p.string() + ": missing" + where);
        return Status(s.id(), s.message() + where);
      }
    }
  }
  return Status::Ok();
}

Status CaptureSetReader::read(uint32_t view, uint32_t frame, ViewFrame* out) const {
  const CaptureManifest& m = manifest_;
  if (view >= m.viewpoints.size() || frame >= m.frame_count) {
    return Status(ErrorId::kCaptureIndex,
                  "view " + std::to_string(view) + ", frame " + std::to_string(frame) +
                      " is outside the capture set (" + std::to_string(m.viewpoints.size()) +
                      " views, " + std::to_string(m.frame_count) + " frames)");
  }
  const std::filesystem::path path = image_path(view, frame);
  const std::string name = path.string();
  CALF_ASSIGN_OR_RETURN(detail::ExrReader exr, detail::ExrReader::open(path));
  const uint32_t n = m.face_size;
  if (exr.width() != n || exr.height() != 6 * n) {
    return Status(ErrorId::kCaptureImageFormat,
                  name + ": image is " + std::to_string(exr.width()) + " x " +
                      std::to_string(exr.height()) + ", expected " + std::to_string(n) + " x " +
                      std::to_string(6 * n) + " (six faces of face_size " + std::to_string(n) +
                      " stacked vertically)");
  }
  int idx[10];
  const char* const required[4] = {"R", "G", "B", "Z"};
  for (int c = 0; c < 4; ++c) {
    idx[c] = exr.channel(required[c]);
    if (idx[c] < 0) {
      return Status(ErrorId::kCaptureImageFormat,
                    name + ": channel '" + required[c] + "' is missing");
    }
  }
  // The optional channel groups, each present exactly when its manifest flag says so.
  struct OptionalChannels {
    const char* const* names;  // 3 channels, at idx[first ... first + 2]
    int first;
    bool wanted;
    const char* wanted_wording;    // what the manifest says when the group is on ...
    const char* unwanted_wording;  // ... and when it is off
  };
  const OptionalChannels groups[2] = {
      {kMaterialChannels, 4, m.material, "says material", "says \"material\": false"},
      {kCoverageChannels, 7, m.coverage, "says coverage", "does not say \"coverage\": true"}};
  for (const OptionalChannels& g : groups) {
    for (int c = 0; c < 3; ++c) {
      idx[g.first + c] = exr.channel(g.names[c]);
      if (g.wanted && idx[g.first + c] < 0) {
        return Status(ErrorId::kCaptureImageFormat, name + ": channel '" + g.names[c] +
                                                        "' is missing (the manifest " +
                                                        g.wanted_wording + ")");
      }
      if (!g.wanted && idx[g.first + c] >= 0) {
        return Status(ErrorId::kCaptureImageFormat, name + ": has channel '" + g.names[c] +
                                                        "' but the manifest " + g.unwanted_wording);
      }
    }
  }
  for (int c = 0; c < 4; ++c) CALF_RETURN_IF_ERROR(exr.require_float(idx[c]));
  for (const OptionalChannels& g : groups) {
    if (!g.wanted) continue;
    for (int c = g.first; c < g.first + 3; ++c) CALF_RETURN_IF_ERROR(exr.require_float(idx[c]));
  }
  if (out->face_size != n || out->has_material != m.material || out->has_coverage != m.coverage ||
      out->depth.size() != out->texel_count()) {
    out->resize(n, m.material, m.coverage);
  }
  // One face at a time keeps the decode buffer at 1/6 of the image.
  const size_t nch = static_cast<size_t>(exr.channel_count());
  const size_t face_texels = static_cast<size_t>(n) * n;
  std::vector<float> rows;
  for (uint32_t face = 0; face < 6; ++face) {
    CALF_RETURN_IF_ERROR(exr.read_rows(face * n, (face + 1) * n, &rows));
    const size_t base = face * face_texels;
    for (size_t i = 0; i < face_texels; ++i) {
      const float* px = &rows[i * nch];
      for (int c = 0; c < 3; ++c) out->color[3 * (base + i) + c] = px[idx[c]];
      out->depth[base + i] = px[idx[3]];
      if (m.material) {
        for (int c = 0; c < 3; ++c) out->material[3 * (base + i) + c] = px[idx[4 + c]];
      }
      if (m.coverage) {
        for (int c = 0; c < 3; ++c) out->coverage[3 * (base + i) + c] = px[idx[7 + c]];
      }
    }
  }
  return validate_view_frame(*out, name);
}

// ---- writer ------------------------------------------------------------------------------------

CaptureSetWriter::CaptureSetWriter(std::filesystem::path directory, CaptureManifest manifest)
    : directory_(std::move(directory)), manifest_(std::move(manifest)) {
  written_.assign(manifest_.viewpoints.size() * manifest_.frame_count, false);
}

Expected<CaptureSetWriter> CaptureSetWriter::create(const std::filesystem::path& directory,
                                                    CaptureManifest manifest) {
  CALF_RETURN_IF_ERROR(validate_manifest(manifest));
  std::error_code ec;
  std::filesystem::create_directories(directory, ec);
  if (ec || !std::filesystem::is_directory(directory, ec)) {
    return Status(ErrorId::kFileWrite, directory.string() + ": cannot create directory" +
                                           (ec ? ": " + ec.message() : ""));
  }
  // A stale manifest would make a half-rewritten set look complete. What is there must be a
  // regular file (or nothing): a FIFO or link of that name is refused, not removed (files.h).
  CALF_RETURN_IF_ERROR(files::check_output_file((directory / kManifestFileName).string()));
  std::filesystem::remove(directory / kManifestFileName, ec);
  if (ec) {
    return Status(ErrorId::kFileWrite, (directory / kManifestFileName).string() +
                                           ": cannot remove the old manifest: " + ec.message());
  }
  return CaptureSetWriter(directory, std::move(manifest));
}

Status CaptureSetWriter::write(uint32_t view, uint32_t frame, const ViewFrame& data) {
  const CaptureManifest& m = manifest_;
  if (finished_) return Status(ErrorId::kCaptureWriterMisuse, "write() after finish()");
  if (view >= m.viewpoints.size() || frame >= m.frame_count) {
    return Status(ErrorId::kCaptureIndex, "view " + std::to_string(view) + ", frame " +
                                              std::to_string(frame) +
                                              " is outside the manifest's counts");
  }
  const std::filesystem::path path = directory_ / capture_file_name(m, view, frame);
  if (data.face_size != m.face_size || data.has_material != m.material ||
      data.has_coverage != m.coverage) {
    return Status(ErrorId::kCaptureWriterMisuse,
                  path.string() + ": view-frame has face size " + std::to_string(data.face_size) +
                      (data.has_material ? " with" : " without") + " material," +
                      (data.has_coverage ? " with" : " without") + " coverage; the manifest says " +
                      std::to_string(m.face_size) + (m.material ? " with" : " without") +
                      " material," + (m.coverage ? " with" : " without") + " coverage");
  }
  const size_t slot = static_cast<size_t>(view) * m.frame_count + frame;
  if (written_[slot]) {
    return Status(ErrorId::kCaptureWriterMisuse, path.string() + ": written twice");
  }
  CALF_RETURN_IF_ERROR(validate_view_frame(data, path.string()));
  const uint32_t n = m.face_size;
  std::vector<detail::ExrChannelOut> channels = {
      {"R", true, data.color.data() + 0, 3},
      {"G", true, data.color.data() + 1, 3},
      {"B", true, data.color.data() + 2, 3},
      {"Z", false, data.depth.data(), 1},
  };
  if (m.material) {
    for (int c = 0; c < 3; ++c) {
      channels.push_back({kMaterialChannels[c], true, data.material.data() + c, 3});
    }
  }
  if (m.coverage) {
    for (int c = 0; c < 3; ++c) {
      channels.push_back({kCoverageChannels[c], c < 2, data.coverage.data() + c, 3});
    }
  }
  CALF_RETURN_IF_ERROR(detail::write_exr(path, n, 6 * n, channels));
  written_[slot] = true;
  return Status::Ok();
}

Status CaptureSetWriter::finish() {
  if (finished_) return Status(ErrorId::kCaptureWriterMisuse, "finish() called twice");
  for (size_t slot = 0; slot < written_.size(); ++slot) {
    if (!written_[slot]) {
      return Status(ErrorId::kCaptureWriterMisuse,
                    "finish(): view " + std::to_string(slot / manifest_.frame_count) + ", frame " +
                        std::to_string(slot % manifest_.frame_count) + " was never written");
    }
  }
  CALF_RETURN_IF_ERROR(
      write_file_atomically(directory_ / kManifestFileName, serialize_manifest(manifest_)));
  finished_ = true;
  return Status::Ok();
}

void CaptureSetWriter::abandon() {
  for (size_t slot = 0; slot < written_.size(); ++slot) {
    if (!written_[slot]) continue;
    uint32_t view = static_cast<uint32_t>(slot / manifest_.frame_count);
    uint32_t frame = static_cast<uint32_t>(slot % manifest_.frame_count);
    std::error_code ignored;
    std::filesystem::remove(directory_ / capture_file_name(manifest_, view, frame), ignored);
    written_[slot] = false;
  }
}

}  // namespace calf::capture
