#include "ingest_image.h"

#include <algorithm>
#include <system_error>

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

Status read_png(const std::filesystem::path& path, const std::vector<std::string>& names,
                const std::vector<PngSamples>& png, ErrorId missing_channel,
                const ImageExpect& expect, NamedPlanes* out) {
  const std::string p = path.string();
  Png8 image;
  CALF_RETURN_IF_ERROR(read_png8(path, expect, &image));
  const size_t w = image.width, h = image.height, nch = image.channels;
  const std::vector<std::string> has = png_channel_names(image.channels);
  out->width = image.width;
  out->height = image.height;
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
      const uint8_t byte = image.pixels[i * nch + c];
      plane[i] = srgb ? linear_from_srgb8(byte) : byte / 255.0f;
    }
  }
  return Status::Ok();
}

}  // namespace

Status read_named_planes(const std::filesystem::path& path, const std::vector<std::string>& names,
                         const std::vector<PngSamples>& png, ErrorId missing_channel,
                         const ImageExpect& expect, NamedPlanes* out) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) {
    return Status(ErrorId::kCaptureFileMissing, path.string() + ": no such file");
  }
  CALF_RETURN_IF_ERROR(files::check_regular_file(path.string()));
  if (has_png_signature(path)) return read_png(path, names, png, missing_channel, expect, out);
  CALF_ASSIGN_OR_RETURN(ExrReader reader, ExrReader::open(path));
  CALF_RETURN_IF_ERROR(check_image_size(path.string(), reader.width(), reader.height(), expect));
  std::vector<int> index(names.size(), -1);
  for (size_t k = 0; k < names.size(); ++k) {
    if (is_constant(names[k])) continue;
    index[k] = reader.channel(names[k]);
    if (index[k] < 0) return missing(missing_channel, path.string(), names[k], reader.names());
    CALF_RETURN_IF_ERROR(reader.require_float(index[k]));
  }
  const size_t w = reader.width(), h = reader.height();
  const size_t nch = static_cast<size_t>(reader.channel_count());
  out->width = static_cast<uint32_t>(w);
  out->height = static_cast<uint32_t>(h);
  out->planes.assign(names.size(), {});
  for (size_t k = 0; k < names.size(); ++k) {
    out->planes[k].assign(w * h, names[k] == kConstantOne ? 1.0f : 0.0f);
  }
  // Strips of at most 2^22 samples, a multiple of 32 rows where that fits (every OpenEXR
  // compression's scanlines per chunk but DWAB's divide 32): the channels not asked for never
  // take more than one strip, however many the file has.
  const size_t fit = std::max<size_t>(1, (size_t{1} << 22) / std::max<size_t>(1, w * nch));
  const uint32_t strip =
      static_cast<uint32_t>(fit >= 32 ? std::min<size_t>(256, fit / 32 * 32) : fit);
  std::vector<float> rows;
  for (uint32_t y0 = 0; y0 < h; y0 += strip) {
    const uint32_t y1 = static_cast<uint32_t>(std::min<size_t>(h, size_t{y0} + strip));
    CALF_RETURN_IF_ERROR(reader.read_rows(y0, y1, &rows));
    const size_t first = size_t{y0} * w, count = size_t{y1 - y0} * w;
    for (size_t k = 0; k < names.size(); ++k) {
      if (index[k] < 0) continue;
      float* plane = out->planes[k].data() + first;
      const size_t c = static_cast<size_t>(index[k]);
      for (size_t i = 0; i < count; ++i) plane[i] = rows[i * nch + c];
    }
  }
  return Status::Ok();
}

}  // namespace calf::capture::detail
