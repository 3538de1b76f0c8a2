// Where images enter calf (internal to the capture layer): the size rule every image reader
// applies to a header before it decodes a pixel, and the PNG reader (libpng, called directly so
// that its errors become Status values and never reach stderr, and so that the header is checked
// before a row buffer exists), and the OpenEXR header walk that runs before OpenEXR sees a file or
// buffer. Other formats (JPEG) are checked by OpenImageIO's open(); all of them then pass
// check_image_size.
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "calf/capture/image_budget.h"
#include "calf/format/status.h"

namespace calf::capture::detail {

// The largest side of an image calf decodes (SCENE.md, CAPTURE.md).
inline constexpr uint32_t kMaxImageSide = 16384;

// What a caller knows about an image before any pixel of it is decoded.
struct ImageExpect {
  uint32_t width = 0, height = 0;                     // the size the caller needs; 0 x 0 = any size
  ErrorId wrong_size = ErrorId::kCaptureImageFormat;  // the id when the size is not that
  const char* expected_by = "expected";               // who expects it, for that message
  ErrorId undecodable = ErrorId::kCaptureImageFormat;  // the id for bytes that do not decode
  uint64_t max_pixels = kDefaultMaxImagePixels;        // the budget (image_budget.h)
  bool allow_16_bit = false;  // PNG: 16-bit samples are reduced to 8 bits, else refused
};

// The rule: `width` x `height` (from a header) is 1..kMaxImageSide per side (else
// `undecodable`), is the expected size when one is given (else `wrong_size`, naming both) and
// fits the budget (else E012).
Status check_image_size(const std::string& name, int64_t width, int64_t height,
                        const ImageExpect& expect);

// A PNG decoded to 8 bits per sample, channels as OpenImageIO names them: Y, Y A, R G B or
// R G B A (palettes and tRNS colour keys expanded to RGB / RGBA; 1-, 2- and 4-bit grey to 8).
struct Png8 {
  uint32_t width = 0, height = 0, channels = 0;
  std::vector<uint8_t> pixels;  // width * height * channels, rows from the top
};

// The channel names of a Png8 with `channels` channels.
std::vector<std::string> png_channel_names(uint32_t channels);

// True when `head` starts with the PNG signature.
bool has_png_signature(std::span<const uint8_t> head);
bool has_png_signature(const std::filesystem::path& path);

// Reads the PNG file at `path` / in `bytes` (`name` for messages). Before any pixel buffer is
// allocated the chunks are walked: the header's size passes check_image_size and the image data
// present must be able to inflate to the rows it declares (deflate expands at most 1032:1), so a
// file of a few bytes declaring 16384 x 16384 is refused at once. libpng's errors and warnings
// are returned as `expect.undecodable` with libpng's message; nothing is printed.
Status read_png8(const std::filesystem::path& path, const ImageExpect& expect, Png8* out);
Status decode_png8(std::span<const uint8_t> bytes, const std::string& name,
                   const ImageExpect& expect, Png8* out);

// The largest side of an OpenEXR image calf reads: a capture set's images are N x 6N.
inline constexpr int64_t kMaxExrSide = 6 * int64_t{kMaxImageSide};
// The most channels an OpenEXR header may declare, and the most bytes one chunk of scanlines
// may need uncompressed (OpenEXR allocates its buffers by that when it opens a file).
inline constexpr uint32_t kMaxExrChannels = 1024;
inline constexpr uint64_t kMaxExrChunkBytes = uint64_t{1} << 28;

// What an OpenEXR header declares.
struct ExrHeader {
  int64_t width = 0, height = 0;  // the data window's
  uint32_t channels = 0;
};

// True when `head` starts with the OpenEXR magic number 76 2f 31 01.
bool has_exr_signature(std::span<const uint8_t> head);
bool has_exr_signature(const std::filesystem::path& path);

// Walks the header of the OpenEXR file at `path` / in `bytes` before OpenEXR reads it, and
// returns `undecodable` naming the file and field unless it is a single-part scanline OpenEXR 2
// image whose every attribute fits in the bytes left (strings in a string vector, a preview's
// pixels in its attribute), with a dataWindow of 1..kMaxExrSide per side, 1..kMaxExrChannels
// channels of UINT, HALF or FLOAT, a chunk of scanlines of at most kMaxExrChunkBytes, and room
// for its line-offset table. Only the header is read. The caller then applies check_image_size
// (or its own size rule) to out->width x out->height.
Status check_exr_header(const std::filesystem::path& path, ErrorId undecodable, ExrHeader* out);
Status check_exr_header(std::span<const uint8_t> bytes, const std::string& name,
                        ErrorId undecodable, ExrHeader* out);

}  // namespace calf::capture::detail
