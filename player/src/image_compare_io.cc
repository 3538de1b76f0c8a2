// Image files for quality measurements: sRGB PNGs of frames, error heat maps, EXR frames.
// OpenImageIO exceptions stop here; every file is written whole (temporary file, then rename).
#include <cmath>
#include <string>
#include <vector>

#include <OpenImageIO/imageio.h>

#include "calf/format/colour.h"
#include "calf/format/files.h"
#include "calf/player/contact_sheet.h"
#include "calf/player/image_compare.h"

namespace calf::player {

namespace {

// Writes 8-bit RGB pixels (row-major from the top row) as a PNG to `path` through a temporary
// file beside it (files::TempFile: the output rules and the cleanup on a signal).
Status write_rgb8_png_file(const std::filesystem::path& path, uint32_t width, uint32_t height,
                           const std::vector<uint8_t>& pixels) {
  const std::string final_name = path.string();
  CALF_ASSIGN_OR_RETURN(files::TempFile temp, files::TempFile::create(final_name));
  temp.close_fd();  // OIIO opens the file by name
  try {
    // By format name, not by file name: the temporary file's name ends in a counter.
    std::unique_ptr<OIIO::ImageOutput> out = OIIO::ImageOutput::create("png");
    if (!out) {
      std::string e = OIIO::geterror();
      return Status(ErrorId::kFileWrite,
                    final_name + ": no PNG writer" + (e.empty() ? "" : ": " + e));
    }
    OIIO::ImageSpec spec(static_cast<int>(width), static_cast<int>(height), 3,
                         OIIO::TypeDesc::UINT8);
    // No time stamp or software name: the bytes depend on the pixels only.
    if (!out->open(temp.temp_path(), spec)) {
      std::string e = out->geterror();
      return Status(ErrorId::kFileWrite, final_name + ": " + (e.empty() ? "cannot open" : e));
    }
    bool ok = out->write_image(OIIO::TypeDesc::UINT8, pixels.data());
    std::string e = ok ? "" : out->geterror();
    ok = out->close() && ok;
    if (!ok) {
      return Status(ErrorId::kFileWrite, final_name + ": " + (e.empty() ? "write failed" : e));
    }
  } catch (const std::exception& ex) {
    return Status(ErrorId::kFileWrite, final_name + ": " + ex.what());
  }
  return temp.commit(/*sync=*/false);
}

}  // namespace

Status write_png(const std::filesystem::path& path, const RgbImageRef& image) {
  const size_t n = size_t{image.width} * image.height;
  if (n == 0 || image.rgb.size() < 3 * n) {
    return Status(ErrorId::kImageCompare, path.string() +
                                              ": the image is empty or its buffer is "
                                              "shorter than its size");
  }
  std::vector<uint8_t> pixels(3 * n);
  for (size_t i = 0; i < 3 * n; ++i) pixels[i] = srgb8_from_linear(image.rgb[i]);
  return write_rgb8_png_file(path, image.width, image.height, pixels);
}

Status write_png_rgb8(const std::filesystem::path& path, const Rgb8Image& image) {
  const size_t n = size_t{image.width} * image.height;
  if (n == 0 || image.rgb.size() < 3 * n) {
    return Status(ErrorId::kImageCompare, path.string() +
                                              ": the image is empty or its buffer is "
                                              "shorter than its size");
  }
  return write_rgb8_png_file(path, image.width, image.height, image.rgb);
}

Status write_heat_map_png(const std::filesystem::path& path, const RgbImageRef& a,
                          const RgbImageRef& b, double full_scale) {
  if (!(full_scale > 0 && full_scale <= 1)) {
    return Status(ErrorId::kImageCompareOption, path.string() + ": heat-map full scale " +
                                                    std::to_string(full_scale) +
                                                    " is outside (0, 1]");
  }
  Expected<std::vector<float>> errors = error_map(a, b);
  if (!errors.ok()) return std::move(errors).status().with_context(path.string());
  std::vector<uint8_t> pixels(3 * errors->size());
  for (size_t i = 0; i < errors->size(); ++i) {
    const std::array<uint8_t, 3> c = heat_colour((*errors)[i] / full_scale);
    for (int ch = 0; ch < 3; ++ch) pixels[3 * i + ch] = c[ch];
  }
  return write_rgb8_png_file(path, a.width, a.height, pixels);
}

Status write_exr(const std::filesystem::path& path, const RenderedImage& image) {
  capture::PerspectiveImage p;
  p.width = image.width;
  p.height = image.height;
  p.color = image.color;
  p.depth = image.depth;
  return capture::write_perspective_image(path, p);
}

}  // namespace calf::player
