#include "image_input.h"

#include <png.h>

#include <algorithm>
#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <memory>
#include <set>
#include <system_error>
#include <utility>

#include <OpenImageIO/fmath.h>

namespace calf::capture {

Status check_image_budget(std::string_view what, uint64_t width, uint64_t height,
                          uint64_t max_pixels, uint64_t count) {
  // width, height <= 2^32 and count <= 6 in every caller: no overflow in 64 bits.
  const uint64_t pixels = width * height * count;
  if (pixels <= max_pixels) return Status::Ok();
  std::string need = std::to_string(width) + " x " + std::to_string(height);
  if (count > 1) need = std::to_string(count) + " x " + need;
  return Status(ErrorId::kImageBudget,
                std::string(what) + ": " + need + " = " + std::to_string(pixels) +
                    " pixels, more than the image budget of " + std::to_string(max_pixels) +
                    " (raise it with --max-image-pixels)");
}

namespace detail {

Status check_image_size(const std::string& name, int64_t width, int64_t height,
                        const ImageExpect& expect) {
  if (width < 1 || height < 1 || width > kMaxImageSide || height > kMaxImageSide) {
    return Status(expect.undecodable, name + ": " + std::to_string(width) + " x " +
                                          std::to_string(height) + " is empty or larger than " +
                                          std::to_string(kMaxImageSide) + " x " +
                                          std::to_string(kMaxImageSide));
  }
  if ((expect.width != 0 || expect.height != 0) &&
      (width != expect.width || height != expect.height)) {
    return Status(expect.wrong_size, name + ": the image is " + std::to_string(width) + " x " +
                                         std::to_string(height) + " but " + expect.expected_by +
                                         " " + std::to_string(expect.width) + " x " +
                                         std::to_string(expect.height));
  }
  return check_image_budget(name, static_cast<uint64_t>(width), static_cast<uint64_t>(height),
                            expect.max_pixels);
}

std::vector<std::string> png_channel_names(uint32_t channels) {
  switch (channels) {
    case 1:
      return {"Y"};
    case 2:
      return {"Y", "A"};
    case 3:
      return {"R", "G", "B"};
    default:
      return {"R", "G", "B", "A"};
  }
}

namespace {

constexpr unsigned char kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};

// Deflate's largest expansion: a 258-byte match coded in 2 bits is 1032:1.
constexpr uint64_t kMaxInflateRatio = 1032;

// The bytes of an image, from memory or from a file, read at any offset.
class ImageBytes {
 public:
  explicit ImageBytes(std::span<const uint8_t> bytes) : bytes_(bytes), size_(bytes.size()) {}
  ImageBytes(std::FILE* file, uint64_t size) : file_(file), size_(size) {}
  uint64_t size() const { return size_; }
  // Copies [offset, offset + n) into `out`; false when the bytes end first.
  bool read_at(uint64_t offset, void* out, size_t n) {
    if (offset > size_ || n > size_ - offset) return false;
    if (!file_) {
      std::memcpy(out, bytes_.data() + offset, n);
      return true;
    }
    return std::fseek(file_, static_cast<long>(offset), SEEK_SET) == 0 &&
           std::fread(out, 1, n, file_) == n;
  }
  // libpng's sequential reads, from `position_`.
  bool read_next(void* out, size_t n) {
    if (!read_at(position_, out, n)) return false;
    position_ += n;
    return true;
  }

 private:
  std::span<const uint8_t> bytes_;
  std::FILE* file_ = nullptr;
  uint64_t size_ = 0;
  uint64_t position_ = 0;
};

uint32_t be32(const uint8_t* p) {
  return uint32_t{p[0]} << 24 | uint32_t{p[1]} << 16 | uint32_t{p[2]} << 8 | p[3];
}

// The chunk walk before decoding: IHDR's size and format, and the bytes of image data present.
Status check_png_chunks(ImageBytes& bytes, const std::string& name, const ImageExpect& expect) {
  const auto bad = [&](const std::string& why) {
    return Status(expect.undecodable, name + ": " + why);
  };
  uint8_t head[8 + 8 + 13];
  if (!bytes.read_at(0, head, sizeof head) || std::memcmp(head, kSignature, 8) != 0 ||
      be32(head + 8) != 13 || std::memcmp(head + 12, "IHDR", 4) != 0) {
    return bad("not a PNG file (no PNG signature and IHDR chunk)");
  }
  const uint32_t width = be32(head + 16), height = be32(head + 20);
  const uint8_t depth = head[24], colour = head[25];
  int samples = 0;
  switch (colour) {
    case 0:
      samples = 1;
      break;  // grey
    case 2:
      samples = 3;
      break;  // RGB
    case 3:
      samples = 1;
      break;  // palette index
    case 4:
      samples = 2;
      break;  // grey + alpha
    case 6:
      samples = 4;
      break;  // RGBA
    default:
      return bad("PNG colour type " + std::to_string(colour) + " does not exist");
  }
  if (depth != 1 && depth != 2 && depth != 4 && depth != 8 && depth != 16) {
    return bad("PNG bit depth " + std::to_string(depth) + " does not exist");
  }
  CALF_RETURN_IF_ERROR(check_image_size(name, width, height, expect));
  if (depth == 16 && !expect.allow_16_bit) {
    return bad("a 16-bit PNG; calf reads 8-bit PNG (write 16-bit or float data as OpenEXR)");
  }
  // The image data present: the IDAT chunks' lengths (every chunk is 12 bytes plus its data).
  uint64_t idat = 0;
  for (uint64_t at = 8; at + 12 <= bytes.size();) {
    uint8_t chunk[8];
    if (!bytes.read_at(at, chunk, 8)) break;
    const uint64_t length = be32(chunk);
    if (std::memcmp(chunk + 4, "IDAT", 4) == 0) idat += length;
    if (std::memcmp(chunk + 4, "IEND", 4) == 0) break;
    at += 12 + length;
  }
  const uint64_t row_bytes = (uint64_t{width} * samples * depth + 7) / 8;
  const uint64_t pixel_bytes = row_bytes * height;
  if (pixel_bytes > idat * kMaxInflateRatio + 1024) {
    return bad(std::to_string(width) + " x " + std::to_string(height) + " needs " +
               std::to_string(pixel_bytes) + " bytes of pixels, more than its " +
               std::to_string(idat) + " bytes of image data can hold (truncated)");
  }
  return Status::Ok();
}

struct PngError {
  char message[200] = {};
};

void on_png_error(png_structp png, png_const_charp message) {
  auto* e = static_cast<PngError*>(png_get_error_ptr(png));
  std::snprintf(e->message, sizeof e->message, "%s", message ? message : "error");
  png_longjmp(png, 1);
}

void on_png_warning(png_structp, png_const_charp) {}  // warnings are not errors: ignored

void on_png_read(png_structp png, png_bytep out, size_t n) {
  if (!static_cast<ImageBytes*>(png_get_io_ptr(png))->read_next(out, n)) {
    png_error(png, "the file ends before its image data");
  }
}

// What the decode keeps across libpng's longjmp: everything it changes lives here, outside the
// frame that calls setjmp.
struct PngDecode {
  std::vector<uint8_t> wide;    // 16-bit rows before their reduction to 8 bits
  std::vector<png_bytep> rows;  // the row pointers of an interlaced image
  Png8* out = nullptr;
};

// The libpng calls, in a frame that holds no C++ object: a longjmp out of libpng lands in
// setjmp here and returns false with `error` set.
bool decode_with_libpng(ImageBytes* bytes, PngDecode* d, PngError* error) {
  png_structp png =
      png_create_read_struct(PNG_LIBPNG_VER_STRING, error, on_png_error, on_png_warning);
  if (!png) return false;
  png_infop info = png_create_info_struct(png);
  if (!info) {
    png_destroy_read_struct(&png, nullptr, nullptr);
    return false;
  }
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_read_struct(&png, &info, nullptr);
    return false;
  }
  png_set_read_fn(png, bytes, on_png_read);
  png_set_user_limits(png, kMaxImageSide, kMaxImageSide);
  png_read_info(png, info);
  png_set_expand(png);  // palette -> RGB, grey < 8 bits -> 8, tRNS -> alpha
  const bool sixteen = png_get_bit_depth(png, info) == 16;
  if (sixteen) png_set_swap(png);  // native byte order for the reduction below
  const int passes = png_set_interlace_handling(png);
  png_read_update_info(png, info);
  Png8& out = *d->out;
  out.width = png_get_image_width(png, info);
  out.height = png_get_image_height(png, info);
  out.channels = png_get_channels(png, info);
  const size_t samples = size_t{out.width} * out.channels;
  out.pixels.resize(samples * out.height);
  if (passes > 1 || !sixteen) {
    // Interlaced images need all their rows at once; 8-bit rows go straight to the output.
    const size_t row_bytes = samples * (sixteen ? 2 : 1);
    uint8_t* base = out.pixels.data();
    if (sixteen) {
      d->wide.resize(row_bytes * out.height);
      base = d->wide.data();
    }
    d->rows.resize(out.height);
    for (uint32_t y = 0; y < out.height; ++y) d->rows[y] = base + size_t{y} * row_bytes;
    png_read_image(png, d->rows.data());
    if (sixteen) {
      OIIO::convert_type(reinterpret_cast<const uint16_t*>(d->wide.data()), out.pixels.data(),
                         samples * out.height);
    }
  } else {
    // 16-bit, not interlaced: one row at a time, reduced as OpenImageIO reduces it.
    d->wide.resize(samples * 2);
    for (uint32_t y = 0; y < out.height; ++y) {
      png_read_row(png, d->wide.data(), nullptr);
      OIIO::convert_type(reinterpret_cast<const uint16_t*>(d->wide.data()),
                         out.pixels.data() + size_t{y} * samples, samples);
    }
  }
  png_destroy_read_struct(&png, &info, nullptr);
  return true;
}

Status decode(ImageBytes& bytes, const std::string& name, const ImageExpect& expect, Png8* out) {
  CALF_RETURN_IF_ERROR(check_png_chunks(bytes, name, expect));
  PngDecode d;
  d.out = out;
  PngError error;
  if (!decode_with_libpng(&bytes, &d, &error)) {
    *out = Png8{};
    return Status(expect.undecodable,
                  name + ": cannot be decoded: " +
                      (error.message[0] ? std::string(error.message) : "out of memory in libpng"));
  }
  return Status::Ok();
}

// The OpenEXR header walk (the file layout of openexr.com's "OpenEXR File Layout"): the magic
// number, the version field, then attributes (name NUL, type NUL, 4-byte little-endian size,
// value) up to an empty name. OpenEXR allocates what a header declares before it checks it
// against the bytes present (a string attribute declaring 2^31 bytes was a 2 GB allocation for a
// 512-byte image), so every size is checked here first.

constexpr uint8_t kExrMagic[4] = {0x76, 0x2f, 0x31, 0x01};

// Version field flags (the low byte is the version, 2).
constexpr uint32_t kExrTiled = 0x200, kExrLongNames = 0x400, kExrNonImage = 0x800,
                   kExrMultiPart = 0x1000;

// The value size of the fixed-size attribute types (OpenEXR reads that many bytes whatever the
// size field says, so a header whose size differs is read differently by OpenEXR than walked
// here); 0 for types of any size.
int32_t exr_fixed_size(const std::string& type) {
  static const std::pair<const char*, int32_t> kSizes[] = {
      {"box2i", 16},      {"box2f", 16},    {"float", 4},    {"double", 8},         {"int", 4},
      {"v2i", 8},         {"v2f", 8},       {"v2d", 16},     {"v3i", 12},           {"v3f", 12},
      {"v3d", 24},        {"m33f", 36},     {"m33d", 72},    {"m44f", 64},          {"m44d", 128},
      {"compression", 1}, {"lineOrder", 1}, {"envmap", 1},   {"deepImageState", 1}, {"rational", 8},
      {"keycode", 28},    {"timecode", 8},  {"tiledesc", 9}, {"chromaticities", 32}};
  for (const auto& [name, size] : kSizes) {
    if (type == name) return size;
  }
  return 0;
}

int32_t le32(const uint8_t* p) {
  return static_cast<int32_t>(uint32_t{p[0]} | uint32_t{p[1]} << 8 | uint32_t{p[2]} << 16 |
                              uint32_t{p[3]} << 24);
}

class ExrWalk {
 public:
  ExrWalk(ImageBytes& bytes, const std::string& name, ErrorId id)
      : bytes_(bytes), name_(name), id_(id) {}

  Status walk(ExrHeader* out) {
    uint8_t head[8];
    if (!bytes_.read_at(0, head, 8)) return bad("not an OpenEXR file (shorter than its header)");
    if (std::memcmp(head, kExrMagic, 4) != 0) {
      return bad("not an OpenEXR file (its first bytes are not 76 2f 31 01)");
    }
    const auto version = static_cast<uint32_t>(le32(head + 4));
    if ((version & 0xff) != 2 ||
        (version & ~uint32_t{0xff | kExrTiled | kExrLongNames | kExrNonImage | kExrMultiPart})) {
      return bad("OpenEXR version field " + std::to_string(version) + " is not version 2");
    }
    if (version & (kExrTiled | kExrNonImage | kExrMultiPart)) {
      return bad(std::string("a ") +
                 (version & kExrMultiPart  ? "multi-part"
                  : version & kExrNonImage ? "deep"
                                           : "tiled") +
                 " OpenEXR file; calf reads single-part scanline OpenEXR (version field " +
                 std::to_string(version) + ")");
    }
    at_ = 8;
    bool have_window = false, have_channels = false;
    int32_t window[4] = {0, 0, 0, 0};
    int compression = -1;
    uint64_t pixel_bytes = 0;  // the bytes of one pixel of every channel
    std::set<std::string> names;
    for (;;) {
      std::string attribute, type;
      CALF_RETURN_IF_ERROR(read_name(&attribute));
      if (attribute.empty()) break;
      CALF_RETURN_IF_ERROR(read_name(&type));
      uint8_t size_bytes[4];
      if (!bytes_.read_at(at_, size_bytes, 4)) return bad("the header ends in an attribute");
      at_ += 4;
      const int32_t size = le32(size_bytes);
      const uint64_t left = bytes_.size() - at_;
      if (size < 0 || static_cast<uint64_t>(size) > left) {
        return bad("header attribute '" + attribute + "' (" + type + ") declares " +
                   std::to_string(size) + " bytes, more than the " + std::to_string(left) +
                   " bytes left in the file");
      }
      if (const int32_t fixed = exr_fixed_size(type); fixed != 0 && size != fixed) {
        return bad("header attribute '" + attribute + "' (" + type + ") has " +
                   std::to_string(size) + " bytes; the type has " + std::to_string(fixed));
      }
      if (!names.insert(attribute).second) {
        return bad("header attribute '" + attribute + "' appears twice");
      }
      const uint64_t value = at_, end = at_ + static_cast<uint64_t>(size);
      if (attribute == "dataWindow") {
        if (type != "box2i" || size != 16) return bad("dataWindow is not a box2i");
        uint8_t box[16];
        if (!bytes_.read_at(value, box, 16)) return bad("the header ends in dataWindow");
        for (int i = 0; i < 4; ++i) window[i] = le32(box + 4 * i);
        have_window = true;
      } else if (attribute == "compression") {
        uint8_t c = 0;
        if (type != "compression" || size != 1 || !bytes_.read_at(value, &c, 1)) {
          return bad("compression is not a compression attribute");
        }
        compression = c;
      } else if (attribute == "channels") {
        if (type != "chlist") return bad("channels is not a chlist");
        CALF_RETURN_IF_ERROR(read_channels(value, end, &out->channels, &pixel_bytes));
        have_channels = true;
      } else if (attribute == "type") {
        // Single-part files may name their part type; only a scanline image is read.
        std::string part(static_cast<size_t>(std::min<int32_t>(size, 32)), '\0');
        if (!bytes_.read_at(value, part.data(), part.size())) return bad("the header ends");
        if (type != "string" || part != "scanlineimage") {
          return bad("part type '" + part + "'; calf reads single-part scanline OpenEXR");
        }
      }
      if (type == "preview") CALF_RETURN_IF_ERROR(check_preview(attribute, value, size));
      if (type == "stringvector") CALF_RETURN_IF_ERROR(check_strings(attribute, value, end));
      at_ = end;
    }
    if (!have_window) return bad("the header has no dataWindow");
    const int64_t w = int64_t{window[2]} - window[0] + 1, h = int64_t{window[3]} - window[1] + 1;
    if (w < 1 || h < 1 || w > kMaxExrSide || h > kMaxExrSide) {
      return bad("data window " + std::to_string(w) + " x " + std::to_string(h) +
                 " is empty or larger than any calf image (" + std::to_string(kMaxExrSide) +
                 " per side)");
    }
    // Scanlines per chunk by compression (NONE, RLE, ZIPS: 1; ZIP, PXR24: 16; PIZ, B44, B44A,
    // DWAA: 32; DWAB and anything newer: at most 256).
    static const int kLines[] = {1, 1, 1, 16, 32, 16, 32, 32, 32, 256};
    const int64_t lines = compression >= 0 && compression < 10 ? kLines[compression] : 256;
    // OpenEXR sizes its line-offset table by the rows declared (8 bytes a chunk, which the file
    // must hold) and a chunk's buffers by its width and channels.
    const uint64_t chunks = static_cast<uint64_t>((h + lines - 1) / lines);
    if (at_ + 8 * chunks > bytes_.size()) {
      return bad(std::to_string(h) + " rows need " + std::to_string(chunks) +
                 " chunk offsets, more than the file's " + std::to_string(bytes_.size()) +
                 " bytes hold");
    }
    if (!have_channels || out->channels == 0) return bad("the header has no channels");
    const uint64_t chunk_bytes = static_cast<uint64_t>(w) * pixel_bytes * std::min(lines, h);
    if (chunk_bytes > kMaxExrChunkBytes) {
      return bad(std::to_string(out->channels) + " channels of " + std::to_string(w) +
                 " pixels in chunks of " + std::to_string(std::min(lines, h)) + " rows need " +
                 std::to_string(chunk_bytes) + " bytes a chunk, more than " +
                 std::to_string(kMaxExrChunkBytes));
    }
    out->width = w;
    out->height = h;
    return Status::Ok();
  }

 private:
  Status bad(const std::string& why) const { return Status(id_, name_ + ": " + why); }

  // A NUL-terminated name at at_ (at most 255 bytes, the long-name limit).
  Status read_name(std::string* out) {
    out->clear();
    for (;;) {
      char c = 0;
      if (!bytes_.read_at(at_, &c, 1)) return bad("the header ends in an attribute name");
      ++at_;
      if (c == '\0') return Status::Ok();
      if (out->size() >= 255) return bad("a header name longer than 255 bytes");
      out->push_back(c);
    }
  }

  // The channel list in [at, end): name NUL, pixel type, pLinear and 3 reserved bytes, x and y
  // sampling; an empty name ends it.
  Status read_channels(uint64_t at, uint64_t end, uint32_t* count, uint64_t* pixel_bytes) {
    *count = 0;
    *pixel_bytes = 0;
    for (;;) {
      size_t length = 0;
      for (char c = 1; c != '\0'; ++length) {
        if (at + length >= end || !bytes_.read_at(at + length, &c, 1)) {
          return bad("the channel list runs past its attribute");
        }
        if (length > 255) return bad("a channel name longer than 255 bytes");
      }
      at += length;
      if (length == 1) return Status::Ok();  // the empty name
      uint8_t fields[16];
      if (at + 16 > end || !bytes_.read_at(at, fields, 16)) {
        return bad("the channel list runs past its attribute");
      }
      at += 16;
      const int32_t pixel_type = le32(fields);
      if (pixel_type < 0 || pixel_type > 2) {
        return bad("a channel of pixel type " + std::to_string(pixel_type) +
                   " (UINT 0, HALF 1 and FLOAT 2 exist)");
      }
      if (++*count > kMaxExrChannels) {
        return bad("more than " + std::to_string(kMaxExrChannels) + " channels");
      }
      *pixel_bytes += pixel_type == 1 ? 2 : 4;
    }
  }

  // A preview image: width, height, then 4 bytes a pixel, exactly the attribute's size.
  Status check_preview(const std::string& attribute, uint64_t at, int32_t size) {
    uint8_t wh[8];
    if (size < 8 || !bytes_.read_at(at, wh, 8)) return bad("preview '" + attribute + "' is cut");
    const auto w = static_cast<uint32_t>(le32(wh)), h = static_cast<uint32_t>(le32(wh + 4));
    if (uint64_t{w} * h * 4 + 8 != static_cast<uint64_t>(size)) {
      return bad("preview '" + attribute + "' declares " + std::to_string(w) + " x " +
                 std::to_string(h) + " pixels in " + std::to_string(size) + " bytes");
    }
    return Status::Ok();
  }

  // A string vector: 4-byte sizes each followed by that many bytes, within the attribute.
  Status check_strings(const std::string& attribute, uint64_t at, uint64_t end) {
    while (at < end) {
      uint8_t n[4];
      if (at + 4 > end || !bytes_.read_at(at, n, 4)) {
        return bad("string vector '" + attribute + "' runs past its attribute");
      }
      at += 4;
      const int32_t length = le32(n);
      if (length < 0 || static_cast<uint64_t>(length) > end - at) {
        return bad("string vector '" + attribute + "' declares a string of " +
                   std::to_string(length) + " bytes, more than its " + std::to_string(end - at) +
                   " bytes left");
      }
      at += static_cast<uint64_t>(length);
    }
    return Status::Ok();
  }

  ImageBytes& bytes_;
  const std::string& name_;
  ErrorId id_;
  uint64_t at_ = 0;
};

}  // namespace

bool has_png_signature(std::span<const uint8_t> head) {
  return head.size() >= 8 && std::memcmp(head.data(), kSignature, 8) == 0;
}

bool has_png_signature(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  uint8_t head[8] = {};
  in.read(reinterpret_cast<char*>(head), 8);
  return in.gcount() == 8 && has_png_signature(head);
}

Status read_png8(const std::filesystem::path& path, const ImageExpect& expect, Png8* out) {
  const std::string name = path.string();
  std::error_code ec;
  const uint64_t size = std::filesystem::file_size(path, ec);
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> file(std::fopen(name.c_str(), "rb"),
                                                       &std::fclose);
  if (ec || !file) return Status(ErrorId::kFileOpen, name + ": cannot be opened");
  ImageBytes bytes(file.get(), size);
  return decode(bytes, name, expect, out);
}

Status decode_png8(std::span<const uint8_t> bytes, const std::string& name,
                   const ImageExpect& expect, Png8* out) {
  ImageBytes source(bytes);
  return decode(source, name, expect, out);
}

bool has_exr_signature(std::span<const uint8_t> head) {
  return head.size() >= 4 && std::memcmp(head.data(), kExrMagic, 4) == 0;
}

bool has_exr_signature(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  uint8_t head[4] = {};
  in.read(reinterpret_cast<char*>(head), 4);
  return in.gcount() == 4 && has_exr_signature(head);
}

Status check_exr_header(const std::filesystem::path& path, ErrorId undecodable, ExrHeader* out) {
  const std::string name = path.string();
  std::error_code ec;
  const uint64_t size = std::filesystem::file_size(path, ec);
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> file(std::fopen(name.c_str(), "rb"),
                                                       &std::fclose);
  if (ec || !file) return Status(undecodable, name + ": cannot be read");
  ImageBytes bytes(file.get(), size);
  *out = ExrHeader{};
  return ExrWalk(bytes, name, undecodable).walk(out);
}

Status check_exr_header(std::span<const uint8_t> bytes, const std::string& name,
                        ErrorId undecodable, ExrHeader* out) {
  ImageBytes source(bytes);
  *out = ExrHeader{};
  return ExrWalk(source, name, undecodable).walk(out);
}

}  // namespace detail
}  // namespace calf::capture
