// OpenEXR reading and writing through OpenImageIO for capture sets and ground-truth images
// (internal). OIIO and OpenEXR exceptions stop here and become Status values.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <OpenImageIO/imageio.h>

#include "calf/format/status.h"

namespace calf::capture::detail {

// One channel to write: `data[i * stride]` is pixel i (row-major from the top row).
struct ExrChannelOut {
  const char* name;
  bool half;  // half float, else 32-bit float
  const float* data;
  size_t stride;
};

// Writes a single-part scanline EXR (ZIP compression, no extra attributes, so that the bytes
// depend on the pixels only) to a temporary file beside `path`, then renames it into place.
Status write_exr(const std::filesystem::path& path, uint32_t width, uint32_t height,
                 const std::vector<ExrChannelOut>& channels);

// An open EXR (or any OIIO-readable image) with the named channels located.
class ExrReader {
 public:
  // Opens `path`; E135 when it does not exist, E136 when OIIO cannot decode it.
  static Expected<ExrReader> open(const std::filesystem::path& path);

  uint32_t width() const { return width_; }
  uint32_t height() const { return height_; }
  // The index of a channel by exact name, or -1.
  int channel(const std::string& name) const;
  int channel_count() const { return static_cast<int>(names_.size()); }
  // The channel names, in file order (for messages naming what an image has).
  const std::vector<std::string>& names() const { return names_; }
  // Ok when channel `index` stores HALF or FLOAT samples, the only types format/CAPTURE.md
  // allows; E136 otherwise (the image library would normalise a UINT channel, so that depth 3
  // read back as ~7e-10: a misread, not an error, unless refused here).
  Status require_float(int index) const;
  // Rows [y0, y1) of all channels as float, interleaved (channel_count() floats per pixel).
  // y0 < y1 <= height().
  Status read_rows(uint32_t y0, uint32_t y1, std::vector<float>* out);

 private:
  ExrReader() = default;
  std::string path_;
  std::unique_ptr<OIIO::ImageInput> input_;
  uint32_t width_ = 0, height_ = 0;
  std::vector<std::string> names_;
  std::vector<OIIO::TypeDesc> formats_;  // per channel
  std::vector<unsigned char> native_;    // read_rows' file-format rows, reused between calls
};

}  // namespace calf::capture::detail
