// Test-only helpers for the container conformance suite (format/SPEC.md): the contents of the
// committed valid files, a way to take a file apart and reassemble it with edited fields
// (re-sealing checksums or not), and the malformed-corpus generator with the error id each file
// must produce. Header-only so both the generator and the tests include it; the runner
// (container_conformance_test.cc, RunnerXxx tests) reads only the committed data and manifest.
#pragma once

#include <xxhash.h>

#include <algorithm>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "calf/format/container.h"

namespace calf::container::corpus {

using Bytes = std::vector<uint8_t>;

// Raw bytes of chunk `i` of the generated valid files: a pattern a reader can re-derive.
inline Bytes pattern(uint32_t i, size_t size) {
  Bytes b(size);
  for (size_t j = 0; j < size; ++j)
    b[j] = static_cast<uint8_t>((i * 31 + j * j / 7 + j / 64) & 0xFF);
  return b;
}

inline constexpr size_t kFrozenSizes[] = {0, 1, 15, 16, 17, 100, 1000, 4000, 333, 2048};

// The frozen v1 file: every track kind, an unknown optional track (kind 0x7777), UTF-8 metadata,
// every supercompression, empty and odd-sized chunks (so there is padding). Written by the
// generator once and committed; it must read back forever. With `compressed_directory` the same
// contents in a 1.1 file whose directory is one zstd frame (valid/v1_1_compressed_directory).
inline Expected<Bytes> make_frozen_v1(bool compressed_directory = false) {
  Bytes file;
  CALF_ASSIGN_OR_RETURN(
      Writer w, Writer::create(memory_sink(&file),
                               CompressionOptions{.zstd_level = 3,
                                                  .lzma_preset = 1,
                                                  .compress_directory = compressed_directory}));
  LightfieldTrackHeader lf;
  lf.frame_count = 48;
  lf.fps_numerator = 24000;
  lf.fps_denominator = 1001;
  lf.view_count = 3;
  lf.face_size = 128;
  lf.cell_size = 64;
  lf.depth_region_size = 64;
  lf.colour_format = static_cast<uint16_t>(PixelFormat::kBc1);
  lf.depth_format = static_cast<uint16_t>(PixelFormat::kR16);
  CALF_RETURN_IF_ERROR(w.add_track(lf).status());
  TilesTrackHeader tiles;
  tiles.tile_count = 12;
  tiles.atlas_width = 256;
  tiles.atlas_height = 128;
  tiles.atlas_format = static_cast<uint16_t>(PixelFormat::kRgba8);
  CALF_RETURN_IF_ERROR(w.add_track(tiles).status());
  SurfelsTrackHeader surfels;
  surfels.object_count = 2;
  surfels.surfel_count = 5000;
  CALF_RETURN_IF_ERROR(w.add_track(surfels).status());
  MeshTrackHeader mesh;
  mesh.vertex_count = 300;
  mesh.triangle_count = 500;
  mesh.segment_count = 4;
  CALF_RETURN_IF_ERROR(w.add_track(mesh).status());
  CALF_RETURN_IF_ERROR(w.add_track(0x7777, 0, Bytes{'f', 'u', 't', 'u', 'r', 'e'}).status());
  CALF_RETURN_IF_ERROR(w.set_metadata("title", "frozen v1 \xe2\x80\x94 \xe2\x9c\x93"));
  CALF_RETURN_IF_ERROR(w.set_metadata("calf.conformance", "v1 frozen"));
  CALF_RETURN_IF_ERROR(w.set_metadata("empty", ""));
  for (uint32_t i = 0; i < std::size(kFrozenSizes); ++i) {
    ChunkKeys k;
    k.track = static_cast<uint16_t>(i % 5);
    k.stream = static_cast<uint16_t>(1 + i % 3);
    k.view = i % 3;
    k.face = i % 6;
    k.region = i * 7;
    k.layer = i % 2;
    k.first_frame = i * 4;
    k.frame_count = 4;
    CALF_RETURN_IF_ERROR(
        w.add_chunk(k, pattern(i, kFrozenSizes[i]), static_cast<Compression>(i % 3)).status());
  }
  CALF_RETURN_IF_ERROR(w.finish());
  return file;
}

// A file with no tracks and no chunks: the smallest valid file (64-byte header + 16-byte
// directory).
inline Expected<Bytes> make_empty() {
  Bytes file;
  CALF_ASSIGN_OR_RETURN(Writer w, Writer::create(memory_sink(&file),
                                                 CompressionOptions{.compress_directory = false}));
  CALF_RETURN_IF_ERROR(w.finish());
  return file;
}

// A file taken apart: its parsed structures and payload area, to be edited and reassembled.
struct Parts {
  FileHeader header;
  std::vector<MetadataEntry> metadata;
  std::vector<TrackRecord> tracks;
  std::vector<ChunkEntry> chunks;
  Bytes payload;  // bytes [64, directory_offset)
};

inline Parts take_apart(const Bytes& file) {
  auto r = Reader::open(memory_source(std::span<const uint8_t>(file)));
  Parts p;
  if (!r.ok()) return p;
  p.header = r->header();
  p.metadata = r->metadata();
  for (const auto& t : r->tracks()) p.tracks.push_back(t.record);
  p.chunks = r->chunks();
  p.payload.assign(file.begin() + kHeaderSize,
                   file.begin() + static_cast<std::ptrdiff_t>(p.header.directory_offset));
  return p;
}

// `bytes` as one zstd frame (RFC 8878) of Raw_Blocks, built by hand so that the corpus never
// depends on a compressor's version: Frame_Header_Descriptor 0xE0 (Single_Segment, an 8-byte
// Frame_Content_Size, no dictionary), `content_size` (normally bytes.size()), then blocks of at
// most 128 KiB, each with its 3-byte header (Last_Block, Block_Type 0, size). With
// `content_checksum` the descriptor is 0xE4 (Content_Checksum_flag) and the frame ends with the
// low 32 bits of XXH64(bytes, seed 0), little-endian.
inline Bytes raw_zstd_frame(std::span<const uint8_t> bytes, uint64_t content_size,
                            bool content_checksum = false) {
  Bytes f = {0x28, 0xB5, 0x2F, 0xFD, static_cast<uint8_t>(content_checksum ? 0xE4 : 0xE0)};
  for (int i = 0; i < 8; ++i) f.push_back(static_cast<uint8_t>(content_size >> (8 * i)));
  size_t at = 0;
  do {
    const size_t n = std::min<size_t>(bytes.size() - at, size_t{1} << 17);
    const bool last = at + n == bytes.size();
    const uint32_t header = (static_cast<uint32_t>(n) << 3) | (last ? 1u : 0u);
    for (int i = 0; i < 3; ++i) f.push_back(static_cast<uint8_t>(header >> (8 * i)));
    f.insert(f.end(), bytes.begin() + static_cast<std::ptrdiff_t>(at),
             bytes.begin() + static_cast<std::ptrdiff_t>(at + n));
    at += n;
  } while (at < bytes.size());
  if (content_checksum) {
    const auto sum = static_cast<uint32_t>(XXH64(bytes.data(), bytes.size(), 0));
    for (int i = 0; i < 4; ++i) f.push_back(static_cast<uint8_t>(sum >> (8 * i)));
  }
  return f;
}

// Serialises parts back into a file. Values outside their ranges are written as given.
// `reseal` recomputes the directory checksum and the header checksum; `fix_sizes` recomputes
// directory_size and file_size from what is written. When the header has the compressed
// directory bit, the body goes into a raw_zstd_frame after its size (`body_tail`, bytes a
// writer would never leave, is appended to the body first).
inline Bytes assemble(const Parts& p, bool reseal = true, bool fix_sizes = true,
                      Bytes body_tail = {}) {
  auto put = [](Bytes& out, const auto& s) {
    FieldWriter w(out);
    w.allow_out_of_range();
    std::remove_cvref_t<decltype(s)>::fields(s, w);
  };
  Bytes dir;
  put(dir, MetadataCount{static_cast<uint32_t>(p.metadata.size())});
  for (const auto& m : p.metadata) put(dir, m);
  for (const auto& t : p.tracks) put(dir, t);
  for (const auto& c : p.chunks) put(dir, c);
  dir.insert(dir.end(), body_tail.begin(), body_tail.end());
  if (p.header.required_features & kFeatureCompressedDirectory) {
    const uint64_t size = dir.size();
    Bytes packed;
    put(packed, DirectoryBodySize{size});
    const Bytes frame = raw_zstd_frame(dir, size);
    packed.insert(packed.end(), frame.begin(), frame.end());
    dir = std::move(packed);
  }
  put(dir, Checksum{reseal ? hash64(dir) : 0});
  FileHeader h = p.header;
  if (fix_sizes) {
    h.directory_offset = kHeaderSize + p.payload.size();
    h.directory_size = dir.size();
    h.file_size = h.directory_offset + h.directory_size;
  }
  Bytes file;
  put(file, h);
  if (reseal)
    store_le(file.data() + kHeaderChecksumOffset,
             hash64(std::span<const uint8_t>(file).first(kHeaderChecksumOffset)), 8);
  file.insert(file.end(), p.payload.begin(), p.payload.end());
  file.insert(file.end(), dir.begin(), dir.end());
  return file;
}

// Recomputes the header checksum of a file in place (after editing header bytes directly).
inline void reseal_header(Bytes& file) {
  store_le(file.data() + kHeaderChecksumOffset,
           hash64(std::span<const uint8_t>(file).first(kHeaderChecksumOffset)), 8);
}

// Recomputes the directory checksum of a file in place (after editing directory bytes directly).
inline void reseal_directory(Bytes& file) {
  const uint64_t at = load_le(file.data() + 32, 8);
  store_le(file.data() + file.size() - 8,
           hash64(std::span<const uint8_t>(file).subspan(at, file.size() - at - 8)), 8);
}

struct Malformed {
  std::string name;
  Bytes bytes;
  ErrorId expected;
};

// The malformed corpus, derived from a valid file (the frozen one) by byte edits only, so it
// does not change when a compressor library does. Each entry names the error a reader must
// report first (open() error, else the first problem verify() lists).
inline std::vector<Malformed> make_malformed(const Bytes& valid) {
  std::vector<Malformed> out;
  const Parts base = take_apart(valid);
  const uint64_t dir_at = base.header.directory_offset;
  auto add = [&out](std::string name, Bytes b, ErrorId id) {
    out.push_back({std::move(name), std::move(b), id});
  };
  auto truncated = [&](uint64_t n) {
    return Bytes(valid.begin(), valid.begin() + static_cast<std::ptrdiff_t>(n));
  };
  auto flipped = [&](uint64_t at, int bit) {
    Bytes b = valid;
    b[at] ^= static_cast<uint8_t>(1u << bit);
    return b;
  };
  auto edited = [&](auto&& edit, bool reseal = true) {
    Parts p = base;
    edit(p);
    return assemble(p, reseal);
  };
  // Truncation: inside the identifier and header, at every chunk start and mid-chunk, inside
  // the directory, one byte short.
  for (uint64_t n : {uint64_t{0}, uint64_t{7}, uint64_t{40}, uint64_t{63}})
    add("truncated_at_" + std::to_string(n), truncated(n), ErrorId::kContainerTruncated);
  for (size_t i = 0; i < base.chunks.size(); ++i) {
    const auto& c = base.chunks[i];
    add("truncated_chunk" + std::to_string(i) + "_start", truncated(c.offset),
        ErrorId::kContainerTruncated);
    if (c.stored_size > 1)
      add("truncated_chunk" + std::to_string(i) + "_middle",
          truncated(c.offset + c.stored_size / 2), ErrorId::kContainerTruncated);
  }
  add("truncated_directory_middle", truncated(dir_at + base.header.directory_size / 2),
      ErrorId::kContainerTruncated);
  add("truncated_last_byte", truncated(valid.size() - 1), ErrorId::kContainerTruncated);
  Bytes longer = valid;
  longer.push_back(0);
  add("trailing_byte", longer, ErrorId::kContainerFileSize);
  // Identifier damage, including what text-mode transfers do.
  add("identifier_bitflip", flipped(3, 0), ErrorId::kContainerIdentifier);
  Bytes crlf = valid;
  crlf.erase(crlf.begin() + 8);  // \r\n -> \n
  add("identifier_crlf_to_lf", crlf, ErrorId::kContainerIdentifier);
  Bytes seven = valid;
  seven[0] &= 0x7F;
  add("identifier_7bit", seven, ErrorId::kContainerIdentifier);
  // Single-bit flips in the header, the directory, a payload of each scheme, padding.
  add("header_bitflip_version", flipped(12, 1), ErrorId::kContainerHeaderChecksum);
  add("header_bitflip_file_size", flipped(24, 0), ErrorId::kContainerHeaderChecksum);
  add("header_bitflip_checksum", flipped(60, 7), ErrorId::kContainerHeaderChecksum);
  add("directory_bitflip_first", flipped(dir_at, 2), ErrorId::kContainerDirectoryChecksum);
  add("directory_bitflip_checksum", flipped(valid.size() - 1, 5),
      ErrorId::kContainerDirectoryChecksum);
  for (uint16_t scheme = 0; scheme < kCompressionCount; ++scheme) {
    for (const auto& c : base.chunks) {
      if (c.compression == scheme && c.stored_size > 0) {
        add(std::string("payload_bitflip_") + compression_name(Compression(scheme)),
            flipped(c.offset + c.stored_size / 2, 3), ErrorId::kContainerChunkHash);
        break;
      }
    }
  }
  for (size_t i = 0; i < base.chunks.size(); ++i) {
    const uint64_t end = base.chunks[i].offset + base.chunks[i].stored_size;
    if (end % kAlignment != 0) {
      add("padding_nonzero", flipped(end, 0), ErrorId::kContainerPadding);
      break;
    }
  }
  // Structural damage with valid checksums (what a buggy writer or an attacker makes).
  Bytes v2 = valid;
  v2[12] = 2;
  reseal_header(v2);
  add("version_2", v2, ErrorId::kContainerVersion);
  Bytes feat = valid;
  feat[19] = 0x80;  // bit 31: bit 0 is the compressed directory since 1.1
  reseal_header(feat);
  add("required_feature_unknown", feat, ErrorId::kContainerRequiredFeature);
  Bytes bigger = valid;
  store_le(bigger.data() + 24, valid.size() + 1000, 8);
  reseal_header(bigger);
  add("file_size_past_eof", bigger, ErrorId::kContainerTruncated);
  Bytes dir_past = valid;
  store_le(dir_past.data() + 32, uint64_t{1} << 40, 8);
  reseal_header(dir_past);
  add("directory_offset_past_eof", dir_past, ErrorId::kContainerDirectoryRange);
  Bytes many_chunks = valid;
  store_le(many_chunks.data() + 48, 0xFFFFFFFF, 4);
  reseal_header(many_chunks);
  add("chunk_count_huge", many_chunks, ErrorId::kContainerLimit);
  Bytes more_chunks = valid;
  store_le(more_chunks.data() + 48, base.chunks.size() + 1000, 4);
  reseal_header(more_chunks);
  add("chunk_count_past_eof", more_chunks, ErrorId::kContainerDirectoryRange);
  Bytes many_tracks = valid;
  store_le(many_tracks.data() + 52, kMaxTracks + 1, 4);
  reseal_header(many_tracks);
  add("track_count_huge", many_tracks, ErrorId::kContainerLimit);
  add("chunk_offset_past_eof", edited([](Parts& p) { p.chunks[3].offset = uint64_t{1} << 40; }),
      ErrorId::kContainerChunkRange);
  add("chunk_stored_past_eof", edited([](Parts& p) {
        p.chunks[1].raw_size = 1 << 20;  // a zstd chunk: a large stored length is plausible
        p.chunks[1].stored_size = stored_bound(1 << 20, Compression::kZstd);
      }),
      ErrorId::kContainerChunkRange);
  add("chunks_overlap", edited([](Parts& p) { p.chunks[4].offset = p.chunks[3].offset; }),
      ErrorId::kContainerChunkLayout);
  add("chunks_gap", edited([](Parts& p) {
        p.payload.insert(
            p.payload.begin() + static_cast<std::ptrdiff_t>(p.chunks[5].offset - kHeaderSize),
            kAlignment, 0);
        for (size_t i = 5; i < p.chunks.size(); ++i) p.chunks[i].offset += kAlignment;
      }),
      ErrorId::kContainerChunkLayout);
  add("chunk_misaligned", edited([](Parts& p) { p.chunks[2].offset += 1; }),
      ErrorId::kContainerChunkLayout);
  add("chunk_track_missing", edited([](Parts& p) { p.chunks[0].keys.track = 200; }),
      ErrorId::kContainerChunkTrack);
  add("chunk_compression_unknown", edited([](Parts& p) { p.chunks[0].compression = 9; }),
      ErrorId::kContainerCompression);
  add("chunk_flag_must_understand", edited([](Parts& p) { p.chunks[0].flags = 1; }),
      ErrorId::kContainerRequiredFeature);
  add("chunk_none_sizes_differ", edited([](Parts& p) { p.chunks[3].raw_size += 1; }),
      ErrorId::kContainerChunkSize);
  add("chunk_raw_size_huge", edited([](Parts& p) { p.chunks[1].raw_size = uint64_t{1} << 40; }),
      ErrorId::kContainerLimit);
  add("chunk_zstd_bad_content", edited([](Parts& p) {
        auto& c = p.chunks[7];  // zstd, 4000 raw bytes
        Bytes stored(p.payload.begin() + static_cast<std::ptrdiff_t>(c.offset - kHeaderSize),
                     p.payload.begin() +
                         static_cast<std::ptrdiff_t>(c.offset - kHeaderSize + c.stored_size));
        c.raw_size += 1;  // the frame declares 4000, the index 4001: hash fine, decode refused
        c.hash = hash64(stored);
      }),
      ErrorId::kContainerDecompress);
  add("chunk_lzma_bad_property", edited([](Parts& p) {
        auto& c = p.chunks[2];  // LZMA2
        p.payload[c.offset - kHeaderSize] = 0xFF;
        c.hash = hash64(
            std::span<const uint8_t>(p.payload).subspan(c.offset - kHeaderSize, c.stored_size));
      }),
      ErrorId::kContainerDecompress);
  add("chunk_lzma_dictionary_huge", edited([](Parts& p) {
        auto& c = p.chunks[2];
        p.payload[c.offset - kHeaderSize] = 30;  // 128 MiB dictionary
        c.hash = hash64(
            std::span<const uint8_t>(p.payload).subspan(c.offset - kHeaderSize, c.stored_size));
      }),
      ErrorId::kContainerLimit);
  add("track_kind_zero", edited([](Parts& p) { p.tracks[1].kind = 0; }),
      ErrorId::kContainerDirectoryFormat);
  add("track_unknown_must_understand", edited([](Parts& p) { p.tracks[4].flags = kTrackRequired; }),
      ErrorId::kContainerTrackKind);
  add("track_header_short", edited([](Parts& p) { p.tracks[0].header.resize(10); }),
      ErrorId::kContainerTrackHeader);
  add("track_face_size_zero",
      edited([](Parts& p) { store_le(p.tracks[0].header.data() + 16, 0, 4); }),
      ErrorId::kContainerTrackHeader);
  add("track_face_size_huge",
      edited([](Parts& p) { store_le(p.tracks[0].header.data() + 16, 1 << 20, 4); }),
      ErrorId::kContainerLimit);
  add("track_header_size_huge",
      edited([](Parts& p) { p.tracks[0].header.resize(kMaxTrackHeaderSize + 1); }),
      ErrorId::kContainerLimit);
  add("metadata_unsorted", edited([](Parts& p) { std::swap(p.metadata[0], p.metadata[1]); }),
      ErrorId::kContainerMetadata);
  add("metadata_not_utf8", edited([](Parts& p) { p.metadata[0].value = "\xc0\xaf"; }),
      ErrorId::kContainerMetadata);
  add("metadata_key_empty", edited([](Parts& p) { p.metadata[0].key.clear(); }),
      ErrorId::kContainerDirectoryFormat);
  return out;
}

// The compressed-directory cases (1.1, SPEC §4.1), derived from the committed
// valid/v1_1_compressed_directory.calf by byte edits and hand-built Raw_Block frames only.
inline std::vector<Malformed> make_malformed_compressed_directory(const Bytes& valid) {
  std::vector<Malformed> out;
  const Parts base = take_apart(valid);
  const uint64_t dir_at = base.header.directory_offset;
  auto add = [&out](std::string name, Bytes b, ErrorId id) {
    out.push_back({"zdir_" + std::move(name), std::move(b), id});
  };
  // The body's bounds from the header's counts (SPEC §9 step 7).
  const uint64_t min_body = 4 + 8 * uint64_t{base.header.track_count} +
                            uint64_t{fixed_size<ChunkEntry>()} * base.header.chunk_count;
  const uint64_t max_body = min_body + uint64_t{kMaxMetadataEntries} * 8 + kMaxMetadataBytes +
                            uint64_t{base.header.track_count} * kMaxTrackHeaderSize;
  Bytes flip = valid;
  flip[dir_at + 20] ^= 0x10;  // inside the zstd frame, checksum left as it was
  add("checksum", flip, ErrorId::kContainerDirectoryChecksum);
  Bytes shortdir(valid.begin(), valid.begin() + static_cast<std::ptrdiff_t>(dir_at));
  shortdir.insert(shortdir.end(), 15, 0);  // 7 bytes and a checksum: no room for the size
  store_le(shortdir.data() + 24, shortdir.size(), 8);
  store_le(shortdir.data() + 40, 15, 8);
  reseal_header(shortdir);
  reseal_directory(shortdir);
  add("too_short", shortdir, ErrorId::kContainerDirectoryRange);
  Bytes below = valid;
  store_le(below.data() + dir_at, min_body - 1, 8);
  reseal_directory(below);
  add("body_below_counts", below, ErrorId::kContainerDirectoryRange);
  Bytes above = valid;
  store_le(above.data() + dir_at, max_body + 1, 8);
  reseal_directory(above);
  add("body_above_limit", above, ErrorId::kContainerLimit);
  Bytes magic = valid;
  magic[dir_at + 8] ^= 0x01;  // the frame's first magic byte
  reseal_directory(magic);
  add("frame_magic", magic, ErrorId::kContainerDecompress);
  Bytes longer_size = valid;  // the size field one more than the frame holds
  store_le(longer_size.data() + dir_at, load_le(valid.data() + dir_at, 8) + 1, 8);
  reseal_directory(longer_size);
  add("body_size_mismatch", longer_size, ErrorId::kContainerDecompress);
  Bytes cut = valid;  // the frame's last byte removed
  cut.erase(cut.end() - 9);
  store_le(cut.data() + 24, cut.size(), 8);
  store_le(cut.data() + 40, cut.size() - dir_at, 8);
  reseal_header(cut);
  reseal_directory(cut);
  add("frame_truncated", cut, ErrorId::kContainerDecompress);
  add("raw_blocks_leftover_body_bytes", assemble(base, true, true, Bytes{0, 0, 0}),
      ErrorId::kContainerDirectoryFormat);
  add(
      "raw_blocks_chunk_track_missing",
      [&] {
        Parts p = base;
        p.chunks[0].keys.track = 200;
        return assemble(p);
      }(),
      ErrorId::kContainerChunkTrack);
  return out;
}

// The first error a reader reports for `file`: open()'s, else verify()'s first; ok if none.
inline Status first_error(std::span<const uint8_t> file) {
  auto r = Reader::open(memory_source(file));
  if (!r.ok()) return r.status();
  auto problems = r->verify(1);
  return problems.empty() ? Status::Ok() : problems[0];
}

}  // namespace calf::container::corpus
