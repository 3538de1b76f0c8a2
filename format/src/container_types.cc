// Names of the container's enumerations and the UTF-8 check of metadata (track kind and stream
// names: track_registry.cc).
#include "calf/format/container_types.h"

namespace calf::container {

const char* compression_name(Compression c) {
  switch (c) {
    case Compression::kNone:
      return "none";
    case Compression::kZstd:
      return "zstd";
    case Compression::kLzma2:
      return "lzma2";
  }
  return "unknown";
}

const char* pixel_format_name(uint16_t format) {
  static const char* kNames[] = {"none", "rgba8",  "rgba16f", "r16",       "bc1",  "bc4",
                                 "bc5",  "bc6h",   "bc7",     "rg8",       "r16p", "r16pm",
                                 "av1",  "av1hdr", "av1-444", "av1hdr-444"};
  return format < sizeof kNames / sizeof kNames[0] ? kNames[format] : "unknown";
}

bool is_valid_utf8(std::string_view s) {
  size_t i = 0;
  while (i < s.size()) {
    const auto c = static_cast<uint8_t>(s[i]);
    if (c < 0x80) {
      ++i;
      continue;
    }
    size_t n;
    uint32_t cp;
    if ((c & 0xE0) == 0xC0) {
      n = 1;
      cp = c & 0x1F;
    } else if ((c & 0xF0) == 0xE0) {
      n = 2;
      cp = c & 0x0F;
    } else if ((c & 0xF8) == 0xF0) {
      n = 3;
      cp = c & 0x07;
    } else
      return false;
    if (s.size() - i <= n) return false;
    for (size_t k = 1; k <= n; ++k) {
      const auto cc = static_cast<uint8_t>(s[i + k]);
      if ((cc & 0xC0) != 0x80) return false;
      cp = (cp << 6) | (cc & 0x3F);
    }
    static const uint32_t kMin[] = {0, 0x80, 0x800, 0x10000};
    if (cp < kMin[n] || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) return false;
    i += n + 1;
  }
  return true;
}

}  // namespace calf::container
