// The on-disk structures of a calf container, version 1 (format/SPEC.md is the normative text;
// this header is its executable form). Each structure declares its fields once (see
// container_fields.h); the section of SPEC.md that defines it is named beside it.
//
// File layout, all little-endian:
//
//   [0, 64)                         FileHeader (identifier, version, sizes, counts, checksum)
//   [64, directory_offset)          chunks: stored bytes of chunk 0, 1, ... in index order, each
//                                   starting at the next multiple of 16, zero padding between
//   [directory_offset, file_size)   directory: metadata, track records, chunk index, checksum
//
// Every byte is covered by a check: the header by its checksum, every chunk by its XXH3-64,
// the directory by its checksum, padding by being zero and of canonical length, the file's end
// by file_size.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "calf/format/container_fields.h"
#include "calf/format/track_kinds.h"

namespace calf::container {

// ---- Identifier and version (SPEC.md "Identifier", "Header") ----

// «CALF 1»\r\n\x1A\n: a non-ASCII first byte catches 7-bit transfers, CR LF catches CR/LF
// conversion, ^Z stops DOS `type`, the final LF catches LF->CRLF conversion (as PNG and KTX2).
inline constexpr std::array<uint8_t, 12> kIdentifier = {0xAB, 'C',  'A',  'L',  'F',  ' ',
                                                        '1',  0xBB, 0x0D, 0x0A, 0x1A, 0x0A};
inline constexpr uint16_t kVersionMajor = 1;  // a reader refuses any other major version
// Minor versions add what a 1.0 reader may ignore, or announce a must-understand addition with a
// required_features bit. 1.1 defines bit 0 (a compressed directory); a writer writes minor 1 only
// when it sets that bit, so a file with a plain directory is byte for byte a 1.0 file.
inline constexpr uint16_t kVersionMinor = 1;
// 1.2: a lightfield track may hold a coverage stream (stream tag 5, SPEC §11.1.11), which 1.0 and
// 1.1 readers skip; a writer writes minor 2 only for a file that holds one.
inline constexpr uint16_t kVersionMinorCoverage = 2;
// 1.3: a lightfield track may hold AV1 colour (colour format 12, SPEC §11.1.12), which earlier
// decoders refuse as a colour format they lack; a writer writes minor 3 only for such a file.
inline constexpr uint16_t kVersionMinorAv1 = 3;
// 1.4: a lightfield track may hold HDR AV1 colour (colour format 13), which 1.3 decoders refuse
// as a colour format they lack; a writer writes minor 4 only for such a file.
inline constexpr uint16_t kVersionMinorAv1Hdr = 4;
// 1.5: a lightfield track may hold AV1 colour of 4:4:4 pictures (colour formats 14 and 15, the
// AV1 High profile), which 1.4 decoders refuse as a colour format they lack; a writer writes
// minor 5 only for such a file.
inline constexpr uint16_t kVersionMinorAv1Chroma444 = 5;
inline constexpr uint64_t kHeaderSize = 64;
inline constexpr uint64_t kAlignment = 16;  // chunk offsets and the directory offset
// Must-understand feature bits (SPEC.md "Header"). Bit 0 (1.1): the directory is its body's size
// and one zstd frame of the body (SPEC.md §4.1 "Compressed directory"). Any other set bit in
// FileHeader::required_features is refused with kContainerRequiredFeature.
inline constexpr uint32_t kFeatureCompressedDirectory = 1u << 0;
inline constexpr uint32_t kKnownRequiredFeatures = kFeatureCompressedDirectory;
// Chunk flags: bits 0-7 are must-understand (none known in 1.0), bits 8-15 optional.
inline constexpr uint16_t kChunkRequiredFlagsMask = 0x00FF;
inline constexpr uint16_t kKnownChunkRequiredFlags = 0;

// ---- Limits (SPEC.md "Limits"): exceeding one is kContainerLimit ----
inline constexpr uint32_t kMaxTracks = 256;
inline constexpr uint32_t kMaxChunks = 1u << 22;  // 4,194,304 chunks, 256 MiB of index
inline constexpr uint32_t kMaxMetadataEntries = 4096;
inline constexpr uint32_t kMaxMetadataKeySize = 256;       // bytes
inline constexpr uint32_t kMaxMetadataBytes = 1u << 20;    // all keys + values together
inline constexpr uint32_t kMaxTrackHeaderSize = 1u << 16;  // bytes per track header blob
inline constexpr uint64_t kMaxRawChunkSize = 1ull << 30;   // 1 GiB decompressed per chunk
inline constexpr uint32_t kMaxLzmaDictionary = 64u << 20;  // LZMA2 dictionary a reader accepts
inline constexpr uint32_t kMaxFrames = 1u << 24;
inline constexpr uint32_t kMaxViews = 1u << 16;
inline constexpr uint32_t kMaxDimension = 16384;  // face, cell, tile, atlas side (px)

// ---- Enumerations ----

// Supercompression of a chunk's stored bytes (SPEC.md "Supercompression").
enum class Compression : uint16_t { kNone = 0, kZstd = 1, kLzma2 = 2 };
inline constexpr uint16_t kCompressionCount = 3;
const char* compression_name(Compression c);  // "none", "zstd", "lzma2", "unknown"

// Track kinds and their names: track_kinds.h (the registry list); each kind's header, stream
// tags and chunk layout: format/<kind>_layout.h; the per-kind tables: track_registry.h.

// Pixel formats named by track headers (SPEC.md "Pixel formats"). The container does not
// range-check them: a decoder refuses a format it lacks, calf-info prints its number.
enum class PixelFormat : uint16_t {
  kNone = 0,
  kRgba8 = 1,
  kRgba16f = 2,
  kR16 = 3,
  kBc1 = 4,
  kBc4 = 5,
  kBc5 = 6,
  kBc6h = 7,
  kBc7 = 8,
  kRg8 = 9,
  kR16Predicted = 10,  // depth only: r16 codes as spatial-prediction residuals (SPEC §11.1.8)
  kR16PredictedMasked = 11,  // depth only: r16p, P-frames' changed texels only (SPEC §11.1.9)
  kAv1 = 12,     // colour only: per cell one AV1 stream in GOP chunks (SPEC §11.1.12); 1.3
  kAv1Hdr = 13,  // colour only: AV1 of 10-bit codes of half floats on a curve (§11.1.12); 1.4
  kAv1Chroma444 = 14,     // colour only: av1 with 4:4:4 pictures (§11.1.12); 1.5
  kAv1HdrChroma444 = 15,  // colour only: av1hdr with 4:4:4 pictures (§11.1.12); 1.5
};
const char* pixel_format_name(uint16_t format);

// ---- Header (SPEC.md "Header"): 64 bytes at offset 0 ----
struct FileHeader {
  std::array<uint8_t, 12> identifier = kIdentifier;
  uint16_t version_major = kVersionMajor;
  uint16_t version_minor = 0;      // the writer sets kVersionMinor with a compressed directory
  uint32_t required_features = 0;  // must-understand bits
  uint32_t optional_features = 0;  // bits a reader may ignore
  uint64_t file_size = 0;          // the whole file, bytes
  uint64_t directory_offset = 0;   // multiple of 16, >= 64
  uint64_t directory_size = 0;     // directory_offset + directory_size == file_size
  uint32_t chunk_count = 0;
  uint32_t track_count = 0;
  uint64_t checksum = 0;  // XXH3-64 (seed 0) of bytes [0, 56)

  template <class Self, class V>
  static constexpr void fields(Self& s, V& v) {
    v(s.identifier, "identifier");
    v(s.version_major, "version_major");
    v(s.version_minor, "version_minor");
    v(s.required_features, "required_features");
    v(s.optional_features, "optional_features");
    v(s.file_size, "file_size");
    v(s.directory_offset, "directory_offset");
    v(s.directory_size, "directory_size");
    v(s.chunk_count, "chunk_count", Range{0, kMaxChunks});
    v(s.track_count, "track_count", Range{0, kMaxTracks});
    v(s.checksum, "checksum");
  }
};
static_assert(fixed_size<FileHeader>() == kHeaderSize);
inline constexpr uint64_t kHeaderChecksumOffset = kHeaderSize - 8;

// ---- Directory (SPEC.md "Directory") ----

// The directory starts with the number of metadata pairs.
struct MetadataCount {
  uint32_t count = 0;
  template <class Self, class V>
  static constexpr void fields(Self& s, V& v) {
    v(s.count, "metadata_count", Range{0, kMaxMetadataEntries});
  }
};

// A compressed directory (required feature bit 0) starts with the size of its body: the
// metadata, track records and chunk entries of a plain directory, without its checksum.
struct DirectoryBodySize {
  uint64_t size = 0;
  template <class Self, class V>
  static constexpr void fields(Self& s, V& v) {
    v(s.size, "directory_body_size");
  }
};

// The directory ends with its XXH3-64 (seed 0) over all its bytes before these 8.
struct Checksum {
  uint64_t value = 0;
  template <class Self, class V>
  static constexpr void fields(Self& s, V& v) {
    v(s.value, "directory_checksum");
  }
};

// One metadata pair: UTF-8 key (no NUL) and UTF-8 value; keys strictly increasing bytewise.
struct MetadataEntry {
  std::string key;
  std::string value;
  template <class Self, class V>
  static constexpr void fields(Self& s, V& v) {
    v(s.key, "key", Range{1, kMaxMetadataKeySize});
    v(s.value, "value", Range{0, kMaxMetadataBytes});
  }
};

// One track: its kind, flags and a kind-specific header blob (the structures below).
struct TrackRecord {
  uint16_t kind = 0;
  uint16_t flags = 0;
  std::vector<uint8_t> header;
  template <class Self, class V>
  static constexpr void fields(Self& s, V& v) {
    v(s.kind, "kind", Range{1, UINT16_MAX});
    v(s.flags, "flags");
    v(s.header, "header", Range{0, kMaxTrackHeaderSize});
  }
};

// The addressing keys of a chunk: what a codec needs to find a chunk without reading others.
// Their meaning per track kind is in SPEC.md; a key a kind does not use is 0.
struct ChunkKeys {
  uint16_t track = 0;        // index into the track table
  uint16_t stream = 0;       // stream tag, opaque per track kind (colour, depth, ...)
  uint32_t view = 0;         // viewpoint
  uint32_t face = 0;         // cube face (GL order) or other per-view subdivision
  uint32_t region = 0;       // cell / tile group / object
  uint32_t layer = 0;        // layer / level / part
  uint32_t first_frame = 0;  // first frame the chunk serves
  uint32_t frame_count = 0;  // frames it serves (0 = not frame-bound)
  bool operator==(const ChunkKeys&) const = default;
};

// One chunk index entry, 64 bytes.
struct ChunkEntry {
  uint64_t offset = 0;       // of the stored bytes in the file
  uint64_t stored_size = 0;  // bytes in the file
  uint64_t raw_size = 0;     // bytes after decompression
  uint64_t hash = 0;         // XXH3-64 (seed 0) of the stored bytes
  uint16_t compression = 0;  // Compression
  uint16_t flags = 0;        // bits 0-7 must-understand, 8-15 optional; 0 in 1.0
  ChunkKeys keys;
  template <class Self, class V>
  static constexpr void fields(Self& s, V& v) {
    v(s.offset, "offset");
    v(s.stored_size, "stored_size");
    v(s.raw_size, "raw_size", Range{0, kMaxRawChunkSize});
    v(s.hash, "hash");
    v(s.compression, "compression");
    v(s.flags, "flags");
    v(s.keys.track, "track");
    v(s.keys.stream, "stream");
    v(s.keys.view, "view");
    v(s.keys.face, "face");
    v(s.keys.region, "region");
    v(s.keys.layer, "layer");
    v(s.keys.first_frame, "first_frame");
    v(s.keys.frame_count, "frame_count");
  }
};
static_assert(fixed_size<ChunkEntry>() == 64);

// ---- Track headers (SPEC.md §6.1, §11): each kind's header is declared in its layout header
// (lightfield_layout.h, tiles_layout.h, surfels_layout.h, mesh_layout.h). Fields are only ever
// appended; a reader accepts a longer blob (a later minor version) and ignores the bytes it does
// not know ----

// The timing every track kind starts with.
#define CALF_TRACK_TIMING_FIELDS(s, v)                       \
  v(s.frame_count, "frame_count", Range{1, kMaxFrames});     \
  v(s.fps_numerator, "fps_numerator", Range{1, UINT32_MAX}); \
  v(s.fps_denominator, "fps_denominator", Range{1, UINT32_MAX})

// Encodes a track header blob (kContainerWriterMisuse when a field is out of range).
template <class H>
Expected<std::vector<uint8_t>> encode_track_header(const H& h) {
  std::vector<uint8_t> blob;
  CALF_RETURN_IF_ERROR(write_fields(h, blob, track_kind_name(static_cast<uint16_t>(H::kKind))));
  return blob;
}

// Decodes a track header blob: too short or a value below its minimum is kContainerTrackHeader,
// above its maximum kContainerLimit. Trailing bytes (fields of a later minor version) are ignored.
template <class H>
Expected<H> decode_track_header(std::span<const uint8_t> blob, const std::string& context) {
  H h;
  FieldReader r(blob, ErrorId::kContainerTrackHeader, ErrorId::kContainerTrackHeader, context);
  CALF_RETURN_IF_ERROR(read_fields(h, r));
  return h;
}

// True if `s` is well-formed UTF-8 (no overlongs, no surrogates, <= U+10FFFF).
bool is_valid_utf8(std::string_view s);

}  // namespace calf::container
