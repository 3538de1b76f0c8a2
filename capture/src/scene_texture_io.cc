#include <cstring>
#include <memory>
#include <string>

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include "calf/capture/scene_file.h"
#include "calf/format/files.h"
#include "image_input.h"
#include "scene_file_internal.h"

namespace calf::capture {
namespace {

std::string oiio_error(const std::string& fallback) {
  std::string e = OIIO::geterror();
  return e.empty() ? fallback : e;
}

// Spreads `nch` 8-bit channels into RGBA by SCENE.md "Texture" (grey spreads to RGB, alpha is
// opaque when the image has none); `rgba` may be `raw` itself when nch is 4.
void spread_to_rgba(const uint8_t* raw, int nch, size_t pixels, uint8_t* rgba) {
  if (nch == 4) {
    if (raw != rgba) std::memcpy(rgba, raw, pixels * 4);
    return;
  }
  for (size_t i = 0; i < pixels; ++i) {
    const uint8_t* p = &raw[i * static_cast<size_t>(nch)];
    uint8_t* q = &rgba[i * 4];
    q[0] = p[0];
    q[1] = nch >= 3 ? p[1] : p[0];
    q[2] = nch >= 3 ? p[2] : p[0];
    q[3] = nch >= 4 ? p[3] : nch == 2 ? p[1] : 255;
  }
}

// The texture rule of every image: its header's size (at most 16384 x 16384, within the budget)
// before any pixel is decoded.
detail::ImageExpect texture_expect(uint64_t max_pixels) {
  detail::ImageExpect expect;
  expect.wrong_size = ErrorId::kSceneFileTexture;
  expect.undecodable = ErrorId::kSceneFileTexture;
  expect.max_pixels = max_pixels;
  expect.allow_16_bit = true;
  return expect;
}

// A decoded PNG as a texture: RGBA images keep their buffer, others spread into a new one.
void texture_from_png(detail::Png8&& image, SceneTexture* t) {
  t->width = image.width;
  t->height = image.height;
  const size_t pixels = size_t{image.width} * image.height;
  if (image.channels == 4) {
    t->rgba = std::move(image.pixels);
    return;
  }
  t->rgba.resize(pixels * 4);
  spread_to_rgba(image.pixels.data(), static_cast<int>(image.channels), pixels, t->rgba.data());
}

// Decodes the image `name` (read through `proxy` when given, else from the file of that name)
// with OpenImageIO: formats other than PNG. `exr`: the bytes are OpenEXR whose header passed
// check_exr_header, and only OpenImageIO's OpenEXR reader may see them (its open() would hand
// bytes its first choice refuses to every other format reader in turn).
Status decode_image(const std::string& name, OIIO::Filesystem::IOProxy* proxy, bool exr,
                    uint64_t max_pixels, SceneTexture* t) {
  try {
    // Unassociated alpha: the bytes of the file, not colour premultiplied by alpha.
    OIIO::ImageSpec config;
    config.attribute("oiio:UnassociatedAlpha", 1);
    // The readers of OpenImageIO 2.4 take the proxy from the configuration, not the argument.
    if (proxy) config.attribute("oiio:ioproxy", OIIO::TypeDesc::PTR, &proxy);
    std::unique_ptr<OIIO::ImageInput> in;
    if (exr) {
      in = OIIO::ImageInput::create("openexr");
      OIIO::ImageSpec spec;
      if (in && !in->open(name, spec, config)) in.reset();
    } else {
      in = OIIO::ImageInput::open(name, &config, proxy);
    }
    if (!in) return Status(ErrorId::kSceneFileTexture, name + ": " + oiio_error("cannot decode"));
    const OIIO::ImageSpec& spec = in->spec();
    CALF_RETURN_IF_ERROR(
        detail::check_image_size(name, spec.width, spec.height, texture_expect(max_pixels)));
    if (spec.nchannels < 1) {
      return Status(ErrorId::kSceneFileTexture, name + ": an image without channels");
    }
    const int nch = std::min(spec.nchannels, 4);  // channels past RGBA are never read
    const size_t pixels = static_cast<size_t>(spec.width) * static_cast<size_t>(spec.height);
    t->rgba.resize(pixels * 4);
    std::vector<uint8_t> raw;
    if (nch != 4) raw.resize(pixels * static_cast<size_t>(nch));
    uint8_t* target = nch == 4 ? t->rgba.data() : raw.data();
    if (!in->read_image(0, 0, 0, nch, OIIO::TypeDesc::UINT8, target)) {
      t->rgba.clear();
      return Status(ErrorId::kSceneFileTexture, name + ": " + oiio_error("cannot decode"));
    }
    t->width = static_cast<uint32_t>(spec.width);
    t->height = static_cast<uint32_t>(spec.height);
    spread_to_rgba(target, nch, pixels, t->rgba.data());
  } catch (const std::exception& e) {
    return Status(ErrorId::kSceneFileTexture, name + ": " + e.what());
  }
  return Status::Ok();
}

}  // namespace

Status scene_internal::write_png(const std::filesystem::path& path, const SceneTexture& t) {
  const std::string final_name = path.string();
  // The output rules, temporary name and cleanup on a signal are files::TempFile's.
  CALF_ASSIGN_OR_RETURN(files::TempFile temp, files::TempFile::create(final_name));
  temp.close_fd();  // OIIO opens the file by name
  try {
    std::unique_ptr<OIIO::ImageOutput> out = OIIO::ImageOutput::create("png");
    if (!out) return Status(ErrorId::kFileWrite, final_name + ": " + oiio_error("no PNG writer"));
    OIIO::ImageSpec spec(static_cast<int>(t.width), static_cast<int>(t.height), 4,
                         OIIO::TypeDesc::UINT8);
    spec.attribute("oiio:UnassociatedAlpha", 1);  // the pixels are not premultiplied
    bool ok =
        out->open(temp.temp_path(), spec) && out->write_image(OIIO::TypeDesc::UINT8, t.rgba.data());
    ok = out->close() && ok;
    if (!ok) return Status(ErrorId::kFileWrite, final_name + ": " + oiio_error("write failed"));
  } catch (const std::exception& e) {
    return Status(ErrorId::kFileWrite, final_name + ": " + e.what());
  }
  return temp.commit(/*sync=*/false);
}

Status read_texture_image(const std::filesystem::path& path, SceneTexture* texture,
                          uint64_t max_image_pixels) {
  if (detail::has_png_signature(path)) {
    detail::Png8 image;
    CALF_RETURN_IF_ERROR(detail::read_png8(path, texture_expect(max_image_pixels), &image));
    texture_from_png(std::move(image), texture);
    return Status::Ok();
  }
  const bool exr = detail::has_exr_signature(path) || path.extension() == ".exr";
  if (exr) {
    detail::ExrHeader header;
    CALF_RETURN_IF_ERROR(detail::check_exr_header(path, ErrorId::kSceneFileTexture, &header));
    CALF_RETURN_IF_ERROR(detail::check_image_size(path.string(), header.width, header.height,
                                                  texture_expect(max_image_pixels)));
  }
  return decode_image(path.string(), nullptr, exr, max_image_pixels, texture);
}

Status decode_texture_image(std::span<const uint8_t> bytes, std::string_view format_hint,
                            std::string_view name, SceneTexture* texture,
                            uint64_t max_image_pixels) {
  if (detail::has_png_signature(bytes)) {
    detail::Png8 image;
    CALF_RETURN_IF_ERROR(detail::decode_png8(bytes, std::string(name) + " (png)",
                                             texture_expect(max_image_pixels), &image));
    texture_from_png(std::move(image), texture);
    return Status::Ok();
  }
  // OpenImageIO picks its reader by the name's extension; the magic numbers of the formats
  // models embed win over a hint that may be wrong or empty.
  std::string ext(format_hint);
  if (bytes.size() >= 8 && std::memcmp(bytes.data(), "\x89PNG\r\n\x1a\n", 8) == 0) {
    ext = "png";
  } else if (bytes.size() >= 3 && bytes[0] == 0xff && bytes[1] == 0xd8 && bytes[2] == 0xff) {
    ext = "jpg";
  } else if (detail::has_exr_signature(bytes)) {
    ext = "exr";
  }
  if (ext.empty() || ext.find_first_of("./\\") != std::string::npos) {
    return Status(ErrorId::kSceneFileTexture,
                  std::string(name) + ": an image of unknown format (not PNG or JPEG, no hint)");
  }
  // OpenEXR by its magic number or its hint: the header walked first, in the bytes given.
  const bool exr = ext == "exr";
  if (exr) {
    const std::string label = std::string(name) + " (exr)";
    detail::ExrHeader header;
    CALF_RETURN_IF_ERROR(
        detail::check_exr_header(bytes, label, ErrorId::kSceneFileTexture, &header));
    CALF_RETURN_IF_ERROR(detail::check_image_size(label, header.width, header.height,
                                                  texture_expect(max_image_pixels)));
  }
  OIIO::Filesystem::IOMemReader reader(bytes.data(), bytes.size());
  Status s = decode_image("embedded." + ext, &reader, exr, max_image_pixels, texture);
  if (s.ok()) return s;
  return Status(s.id(), std::string(name) + " (" + ext + "): " + s.message());
}

}  // namespace calf::capture
