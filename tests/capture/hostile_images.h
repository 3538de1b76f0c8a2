// Small image files built byte by byte for the tests of the image budget and the header checks
// (tests/capture/image_input_test.cc, ingest_test.cc, the hostile_images tool of
// tests/cli/hostile_images.sh): PNGs whose header declares any size over a few bytes of data,
// valid PNGs in stored (uncompressed) deflate blocks, and OpenEXR headers without pixels or whose
// attributes declare more bytes than the file holds. Written from the PNG and OpenEXR
// specifications, not through the readers under test.
#pragma once

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

namespace calf::test {

inline void put_be32(std::string* s, uint32_t v) {
  for (int shift = 24; shift >= 0; shift -= 8) s->push_back(static_cast<char>(v >> shift));
}

inline void put_le32(std::string* s, uint32_t v) {
  for (int shift = 0; shift < 32; shift += 8) s->push_back(static_cast<char>(v >> shift));
}

// CRC-32 of ISO 3309 (PNG's chunk CRC), bit by bit.
inline uint32_t crc32(const std::string& bytes) {
  uint32_t c = 0xffffffffu;
  for (unsigned char b : bytes) {
    c ^= b;
    for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xedb88320u & (0u - (c & 1u)));
  }
  return c ^ 0xffffffffu;
}

// One PNG chunk: length, type, data, CRC of type and data.
inline std::string png_chunk(const std::string& type, const std::string& data) {
  std::string out;
  put_be32(&out, static_cast<uint32_t>(data.size()));
  const std::string body = type + data;
  out += body;
  put_be32(&out, crc32(body));
  return out;
}

// A zlib stream of `raw` in stored deflate blocks (no compression), with its Adler-32.
inline std::string zlib_stored(const std::string& raw) {
  std::string out = "\x78\x01";
  size_t at = 0;
  do {
    const size_t n = std::min<size_t>(65535, raw.size() - at);
    const bool last = at + n == raw.size();
    out.push_back(last ? '\x01' : '\x00');
    out.push_back(static_cast<char>(n & 0xff));
    out.push_back(static_cast<char>(n >> 8));
    out.push_back(static_cast<char>(~n & 0xff));
    out.push_back(static_cast<char>((~n >> 8) & 0xff));
    out.append(raw, at, n);
    at += n;
  } while (at < raw.size());
  uint32_t a = 1, b = 0;
  for (unsigned char c : raw) {
    a = (a + c) % 65521;
    b = (b + a) % 65521;
  }
  put_be32(&out, b << 16 | a);
  return out;
}

// A PNG of `width` x `height` (bit depth, colour type as in the IHDR chunk) whose one IDAT chunk
// holds `idat`; `before_idat` are further chunks (PLTE, tRNS).
inline std::string png_file(uint32_t width, uint32_t height, uint8_t depth, uint8_t colour,
                            const std::string& idat, const std::string& before_idat = "") {
  std::string ihdr;
  put_be32(&ihdr, width);
  put_be32(&ihdr, height);
  ihdr += static_cast<char>(depth);
  ihdr += static_cast<char>(colour);
  ihdr += std::string(3, '\0');  // deflate, adaptive filters, not interlaced
  return std::string("\x89PNG\r\n\x1a\n", 8) + png_chunk("IHDR", ihdr) + before_idat +
         png_chunk("IDAT", idat) + png_chunk("IEND", "");
}

// A PNG that declares `width` x `height` RGBA but holds only a few bytes of image data.
inline std::string png_declaring(uint32_t width, uint32_t height) {
  return png_file(width, height, 8, 6, zlib_stored(std::string(64, '\0')));
}

// An OpenEXR header of a single-part scanline file: `channels` (HALF) of `width` x `height`,
// `compression` (3 = ZIP), its line-offset table pointing every chunk at the table's end, and no
// pixel data.
inline std::string exr_header_only(uint32_t width, uint32_t height,
                                   const std::vector<std::string>& channels,
                                   uint8_t compression = 3) {
  std::string out("\x76\x2f\x31\x01\x02\x00\x00\x00", 8);
  const auto attribute = [&](const std::string& name, const std::string& type,
                             const std::string& value) {
    out += name + '\0' + type + '\0';
    put_le32(&out, static_cast<uint32_t>(value.size()));
    out += value;
  };
  std::string chlist;
  for (const std::string& c : channels) {
    chlist += c + '\0';
    put_le32(&chlist, 1);            // HALF
    chlist += std::string(4, '\0');  // pLinear, reserved
    put_le32(&chlist, 1);
    put_le32(&chlist, 1);
  }
  chlist += '\0';
  std::string box;
  for (uint32_t v : {0u, 0u, width - 1, height - 1}) put_le32(&box, v);
  std::string one_f, zero_2f;
  put_le32(&one_f, 0x3f800000u);
  zero_2f = std::string(8, '\0');
  attribute("channels", "chlist", chlist);
  attribute("compression", "compression", std::string(1, static_cast<char>(compression)));
  attribute("dataWindow", "box2i", box);
  attribute("displayWindow", "box2i", box);
  attribute("lineOrder", "lineOrder", std::string(1, '\0'));
  attribute("pixelAspectRatio", "float", one_f);
  attribute("screenWindowCenter", "v2f", zero_2f);
  attribute("screenWindowWidth", "float", one_f);
  out += '\0';
  const uint32_t lines = compression == 3 ? 16 : compression >= 4 && compression <= 8 ? 32 : 1;
  const uint64_t chunks = (uint64_t{height} + lines - 1) / lines;
  const uint64_t end = out.size() + 8 * chunks;
  for (uint64_t i = 0; i < chunks; ++i) {
    put_le32(&out, static_cast<uint32_t>(end));
    put_le32(&out, static_cast<uint32_t>(end >> 32));
  }
  return out;
}

// An OpenEXR header of one attribute (`name`, `type`, the 4-byte size `declared`, then `value`)
// after the magic number and the version field `version`, then the end of the header and 64
// zero bytes.
inline std::string exr_with(const std::string& name, const std::string& type, uint32_t declared,
                            const std::string& value, uint32_t version = 2) {
  std::string out("\x76\x2f\x31\x01", 4);
  put_le32(&out, version);
  out += name + '\0' + type + '\0';
  put_le32(&out, declared);
  out += value;
  out += '\0';
  return out + std::string(64, '\0');
}

// A Seurat manifest of two view groups (at x = -0.5 and 0.5) of six 90-degree face cameras of
// `size` x `size` pixels; every view's colour is `colour` (channels R G B, alpha CONSTANT_ONE),
// its depth `depth` (channel R, EYE_Z).
inline std::string seurat_manifest(uint32_t size, const std::string& colour,
                                   const std::string& depth, double focal = 1) {
  // Forward and up of each face; world_from_eye's columns are right, up, -forward.
  const double faces[6][6] = {{0, 0, -1, 0, 1, 0}, {0, 0, 1, 0, 1, 0},  {-1, 0, 0, 0, 1, 0},
                              {1, 0, 0, 0, 1, 0},  {0, -1, 0, 0, 0, 1}, {0, 1, 0, 0, 0, 1}};
  const auto num = [](double v) {
    char buf[40];
    std::snprintf(buf, sizeof buf, "%.17g", v);
    return std::string(buf);
  };
  std::string json = "{\"view_groups\": [";
  for (int g = 0; g < 2; ++g) {
    json += std::string(g ? ", " : "") + "{\"views\": [";
    for (int k = 0; k < 6; ++k) {
      const double* f = faces[k];
      const double fw[3] = {f[0], f[1], f[2]}, up[3] = {f[3], f[4], f[5]};
      const double right[3] = {fw[1] * up[2] - fw[2] * up[1], fw[2] * up[0] - fw[0] * up[2],
                               fw[0] * up[1] - fw[1] * up[0]};
      const double cx = g ? 0.5 : -0.5;
      const double w[16] = {right[0], up[0], -fw[0], cx,  right[1], up[1], -fw[1], 0,
                            right[2], up[2], -fw[2], 0.0, 0,        0,     0,      1};
      const double n = 0.05, fr = 100;
      const double c[16] = {
          focal, 0, 0,  0, 0, focal, 0, 0, 0, 0, (n + fr) / (n - fr), 2 * n * fr / (n - fr),
          0,     0, -1, 0};
      std::string cm = "[", wm = "[";
      for (int i = 0; i < 16; ++i) {
        cm += (i ? ", " : "") + num(c[i]);
        wm += (i ? ", " : "") + num(w[i]);
      }
      json += std::string(k ? ", " : "") +
              "{\"projective_camera\": {\"image_width\": " + std::to_string(size) +
              ", \"image_height\": " + std::to_string(size) + ", \"clip_from_eye_matrix\": " + cm +
              "], \"world_from_eye_matrix\": " + wm +
              "], \"depth_type\": \"EYE_Z\"}, \"depth_image_file\": {\"color\": {\"path\": \"" +
              colour +
              "\", \"channel_0\": \"R\", \"channel_1\": \"G\", \"channel_2\": \"B\", "
              "\"channel_alpha\": \"CONSTANT_ONE\"}, \"depth\": {\"path\": \"" +
              depth + "\", \"channel_0\": \"R\"}}}";
    }
    json += "]}";
  }
  return json + "]}\n";
}

}  // namespace calf::test
