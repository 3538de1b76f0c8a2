#include "ingest_image.h"

#include <cstring>
#include <fstream>
#include <memory>
#include <system_error>

#include <OpenImageIO/imageio.h>

#include "calf/format/colour.h"
#include "calf/format/files.h"
#include "exr_io.h"

namespace calf::capture::detail {
namespace {

bool is_constant(const std::string& name) {
  return name == kConstantZero || name == kConstantOne;
}

std::string channel_list(const std::vector<std::string>& names) {
  std::string out;
  for (const std::string& n : names) out += (out.empty() ? "" : ", ") + n;
  return out.empty() ? "none" : out;
}

Status missing(ErrorId id, const std::string& path, const std::string& name,
               const std::vector<std::string>& has) {
  return Status(id, path + ": has no channel '" + name + "' (it has " + channel_list(has) + ")");
}

bool has_png_signature(const std::filesystem::path& path) {
  static const unsigned char kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  std::ifstream in(path, std::ios::binary);
  unsigned char head[8] = {};
  in.read(reinterpret_cast<char*>(head), 8);
  return in.gcount() == 8 && std::memcmp(head, kSignature, 8) == 0;
}

Status read_png(const std::filesystem::path& path, const std::vector<std::string>& names,
                const std::vector<PngSamples>& png, ErrorId missing_channel, NamedPlanes* out) {
  const std::string p = path.string();
  try {
    std::unique_ptr<OIIO::ImageInput> in = OIIO::ImageInput::create("png");
    OIIO::ImageSpec config;
    // Alpha is read as written, never (un)premultiplied into the colour (DESIGN.md, OIIO notes).
    config.attribute("oiio:UnassociatedAlpha", 1);
    OIIO::ImageSpec opened;
    if (!in || !in->open(p, opened, config)) {
      return Status(ErrorId::kCaptureImageFormat, p + ": not a readable PNG");
    }
    const OIIO::ImageSpec& spec = in->spec();
    if (spec.format != OIIO::TypeDesc::UINT8) {
      return Status(ErrorId::kCaptureImageFormat,
                    p + ": a " + std::string(spec.format.c_str()) +
                        " PNG; calf reads 8-bit PNG (write 16-bit or float data as OpenEXR)");
    }
    if (spec.width <= 0 || spec.height <= 0 || spec.width > 16384 || spec.height > 16384) {
      return Status(ErrorId::kCaptureImageFormat, p + ": image size outside 1..16384");
    }
    const size_t w = static_cast<size_t>(spec.width), h = static_cast<size_t>(spec.height);
    const size_t nch = static_cast<size_t>(spec.nchannels);
    std::vector<std::string> has(spec.channelnames.begin(), spec.channelnames.end());
    has.resize(nch);
    std::vector<unsigned char> pixels(w * h * nch);
    if (!in->read_image(0, 0, 0, static_cast<int>(nch), OIIO::TypeDesc::UINT8, pixels.data())) {
      return Status(ErrorId::kCaptureImageFormat, p + ": cannot be decoded");
    }
    out->width = static_cast<uint32_t>(w);
    out->height = static_cast<uint32_t>(h);
    out->planes.assign(names.size(), {});
    for (size_t k = 0; k < names.size(); ++k) {
      std::vector<float>& plane = out->planes[k];
      plane.assign(w * h, names[k] == kConstantOne ? 1.0f : 0.0f);
      if (is_constant(names[k])) continue;
      size_t c = 0;
      while (c < nch && has[c] != names[k]) ++c;
      if (c == nch) return missing(missing_channel, p, names[k], has);
      const bool srgb = png[k] == PngSamples::kSrgbColour;
      for (size_t i = 0; i < w * h; ++i) {
        const uint8_t byte = pixels[i * nch + c];
        plane[i] = srgb ? linear_from_srgb8(byte) : byte / 255.0f;
      }
    }
  } catch (const std::exception& e) {
    return Status(ErrorId::kCaptureImageFormat, p + ": " + e.what());
  }
  return Status::Ok();
}

}  // namespace

Status read_named_planes(const std::filesystem::path& path, const std::vector<std::string>& names,
                         const std::vector<PngSamples>& png, ErrorId missing_channel,
                         NamedPlanes* out) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) {
    return Status(ErrorId::kCaptureFileMissing, path.string() + ": no such file");
  }
  CALF_RETURN_IF_ERROR(files::check_regular_file(path.string()));
  if (has_png_signature(path)) return read_png(path, names, png, missing_channel, out);
  CALF_ASSIGN_OR_RETURN(ExrReader reader, ExrReader::open(path));
  std::vector<int> index(names.size(), -1);
  for (size_t k = 0; k < names.size(); ++k) {
    if (is_constant(names[k])) continue;
    index[k] = reader.channel(names[k]);
    if (index[k] < 0) return missing(missing_channel, path.string(), names[k], reader.names());
    CALF_RETURN_IF_ERROR(reader.require_float(index[k]));
  }
  const size_t w = reader.width(), h = reader.height();
  if (w > 16384 || h > 16384) {
    return Status(ErrorId::kCaptureImageFormat, path.string() + ": image size outside 1..16384");
  }
  std::vector<float> rows;
  CALF_RETURN_IF_ERROR(reader.read_rows(0, static_cast<uint32_t>(h), &rows));
  const size_t nch = static_cast<size_t>(reader.channel_count());
  out->width = static_cast<uint32_t>(w);
  out->height = static_cast<uint32_t>(h);
  out->planes.assign(names.size(), {});
  for (size_t k = 0; k < names.size(); ++k) {
    std::vector<float>& plane = out->planes[k];
    plane.assign(w * h, names[k] == kConstantOne ? 1.0f : 0.0f);
    if (index[k] < 0) continue;
    for (size_t i = 0; i < w * h; ++i) plane[i] = rows[i * nch + static_cast<size_t>(index[k])];
  }
  return Status::Ok();
}

}  // namespace calf::capture::detail
