// The swatch kind's layout (the test build's kind, swatch_kind.h): the track header is the timing
// fields alone; stream 0 is the versioned index, stream 1 one chunk per frame (first_frame = the
// frame, frame_count = 1) holding that frame's colour.
//
//   index chunk:  u32 layout_version (1), u32 flags (0)
//   colour chunk: u8 r, u8 g, u8 b (sRGB-free: the values / 255 are the linear colour)
#pragma once

#include <cstdint>
#include <iterator>
#include <span>
#include <string>

#include "calf/format/container_fields.h"
#include "calf/format/container_types.h"
#include "calf/format/status.h"

namespace calf::container {

#define CALF_SWATCH_STREAMS(X) X(kIndex, 0, "index") X(kColour, 1, "colour")
enum class SwatchStream : uint16_t { CALF_SWATCH_STREAMS(CALF_STREAM_ENUM) };

struct SwatchTrackHeader {
  static constexpr TrackKind kKind = TrackKind::kSwatch;
  static constexpr const char* kStreamNames[] = {CALF_SWATCH_STREAMS(CALF_STREAM_NAME)};
  uint32_t frame_count = 1;
  uint32_t fps_numerator = 24;
  uint32_t fps_denominator = 1;
  template <class Self, class V>
  static constexpr void fields(Self& s, V& v) {
    CALF_TRACK_TIMING_FIELDS(s, v);
  }
};
static_assert(std::size(SwatchTrackHeader::kStreamNames) ==
              static_cast<size_t>(SwatchStream::kColour) + 1);

}  // namespace calf::container

namespace calf::swatch {

inline constexpr uint32_t kLayoutVersion = 1;

struct IndexChunk {
  uint32_t layout_version = kLayoutVersion;
  uint32_t flags = 0;
  template <class Self, class V>
  static constexpr void fields(Self& s, V& v) {
    v(s.layout_version, "layout_version", container::Range{kLayoutVersion, kLayoutVersion});
    v(s.flags, "flags", container::Range{0, 0});
  }
};

struct ColourChunk {
  uint8_t r = 0, g = 0, b = 0;
  template <class Self, class V>
  static constexpr void fields(Self& s, V& v) {
    v(s.r, "r");
    v(s.g, "g");
    v(s.b, "b");
  }
};

// Reads a whole record of type T from `raw`: too short, a value out of range or bytes left over
// are kInvalidArgument (the test kind takes no error id of its own), its message starting with
// `what`.
template <class T>
Expected<T> parse(std::span<const uint8_t> raw, const std::string& what) {
  T x;
  container::FieldReader r(raw, ErrorId::kInvalidArgument, ErrorId::kInvalidArgument, what,
                           ErrorId::kInvalidArgument);
  CALF_RETURN_IF_ERROR(container::read_fields(x, r));
  if (r.remaining() != 0)
    return Status(ErrorId::kInvalidArgument,
                  what + ": " + std::to_string(r.remaining()) + " bytes after the fields");
  return x;
}

}  // namespace calf::swatch
