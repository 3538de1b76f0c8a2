// The calf container: a Writer that streams chunks into a .calf file and a Reader that opens
// one and reads any chunk by id (format/SPEC.md; on-disk structures in container_types.h).
//
// Writing (deterministic: the same calls give the same bytes, whatever the thread count):
//
//   CALF_ASSIGN_OR_RETURN(Writer w, Writer::create("clip.calf"));
//   CALF_ASSIGN_OR_RETURN(uint16_t lf, w.add_track(LightfieldTrackHeader{...}));
//   w.set_metadata("encoder", "calf-encode 0.1");
//   CALF_ASSIGN_OR_RETURN(uint32_t id, w.add_chunk({.track = lf, .stream = 1}, raw, zstd));
//   ... (or compress_chunk() on worker threads, then add_stored_chunk() in a fixed order)
//   CALF_RETURN_IF_ERROR(w.finish());   // directory + header; the file appears whole, or never
//
// Reading (thread-safe after open: read_* are const and use pread):
//
//   CALF_ASSIGN_OR_RETURN(Reader r, Reader::open("clip.calf"));
//   for (uint32_t id : r.find_chunks({.track = 0, .stream = 1, .view = 3}))
//     CALF_RETURN_IF_ERROR(r.read_chunk_into(id, buffer_of_raw_size));
//
// open() reads the 64-byte header and the directory only, and checks every count, offset and
// length against limits and the real file size before allocating anything sized by them.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "calf/format/container_codec.h"
#include "calf/format/container_io.h"
#include "calf/format/container_types.h"
#include "calf/format/status.h"
#include "calf/format/track_registry.h"

namespace calf::container {

// A track as the reader sees it. `header` holds the decoded kind-specific header for every kind
// of the registry (track_kinds.h); an unknown (optional) kind is kept as `std::monostate` with
// `known == false`, and its chunks stay readable as bytes, but codecs skip it.
struct Track {
  uint16_t id = 0;
  TrackRecord record;
  bool known = false;
  TrackHeader header;
};

// A chunk filter for Reader::find_chunks: unset keys match anything.
struct ChunkQuery {
  std::optional<uint16_t> track, stream;
  std::optional<uint32_t> view, face, region, layer;
  std::optional<uint32_t> frame;  // chunks whose [first_frame, first_frame + frame_count) hold it
};

class Reader {
 public:
  // Opens a file (through a pread source) or any ByteSource. Errors, in the order checked:
  // kFileOpen, kContainerIdentifier, kContainerTruncated (shorter than the header or than
  // file_size), kContainerHeaderChecksum, kContainerVersion, kContainerRequiredFeature,
  // kContainerFileSize, kContainerLimit (counts), kContainerDirectoryRange,
  // kContainerDirectoryChecksum, a compressed directory's body size and frame
  // (kContainerDirectoryRange, kContainerLimit, kContainerDecompress), then per directory entry
  // kContainerDirectoryFormat, kContainerMetadata, kContainerTrackKind, kContainerTrackHeader,
  // kContainerLimit and per chunk kContainerChunkTrack, kContainerCompression,
  // kContainerRequiredFeature, kContainerChunkSize, kContainerChunkRange, kContainerChunkLayout.
  // Every error of the path
  // overload names the path exactly once ("clip.calf: ..."), so a command prints it as it is.
  static Expected<Reader> open(const std::string& path);
  static Expected<Reader> open(std::unique_ptr<ByteSource> source);

  Reader(Reader&&) noexcept;
  Reader& operator=(Reader&&) noexcept;
  ~Reader();

  const FileHeader& header() const { return header_; }
  const std::vector<Track>& tracks() const { return tracks_; }
  const std::vector<MetadataEntry>& metadata() const { return metadata_; }
  const std::vector<ChunkEntry>& chunks() const { return chunks_; }
  // Bytes of the directory's body (metadata, track records, chunk index) as parsed: equal to
  // directory_size - 8 for a plain directory, the decompressed size for a compressed one.
  uint64_t directory_body_size() const { return directory_body_size_; }
  // The value for `key`, or nullptr.
  const std::string* find_metadata(std::string_view key) const;
  // Ids of the chunks matching `q`, in index order.
  std::vector<uint32_t> find_chunks(const ChunkQuery& q) const;

  // The stored bytes of chunk `id`, hash verified (kContainerChunkId, kContainerChunkHash,
  // kContainerTruncated / kFileRead if the file changed under us).
  Expected<std::vector<uint8_t>> read_stored(uint32_t id) const;
  // The same into a caller buffer of exactly stored_size bytes (kContainerBufferSize otherwise).
  Status read_stored_into(uint32_t id, std::span<uint8_t> out) const;
  // The raw (decompressed) bytes of chunk `id`: hash verified, then decompressed
  // (kContainerDecompress, kContainerLimit on an LZMA2 dictionary above the limit).
  Expected<std::vector<uint8_t>> read_chunk(uint32_t id) const;
  // The same into a caller buffer of exactly raw_size bytes. A compressed chunk's stored bytes
  // go to `scratch` (resized as needed, reusable across calls); an uncompressed chunk is read
  // straight into `out`.
  Status read_chunk_into(uint32_t id, std::span<uint8_t> out, std::vector<uint8_t>& scratch) const;
  Status read_chunk_into(uint32_t id, std::span<uint8_t> out) const;

  // Full verification of what open() did not read: every chunk's hash and decompression, and
  // every padding byte. Returns every problem found (empty when the file is good), each with
  // the chunk or offset at fault. `max_problems` bounds the list.
  std::vector<Status> verify(size_t max_problems = 1000) const;

 private:
  Reader() = default;
  Status load();
  Status check_chunks();

  std::unique_ptr<ByteSource> source_;
  FileHeader header_;
  std::vector<Track> tracks_;
  std::vector<MetadataEntry> metadata_;
  std::vector<ChunkEntry> chunks_;
  uint64_t directory_body_size_ = 0;
};

class Writer {
 public:
  // Writes `path` through a temporary file renamed into place by finish().
  static Expected<Writer> create(const std::string& path, CompressionOptions options = {});
  // Writes into any sink (e.g. memory_sink()).
  static Expected<Writer> create(std::unique_ptr<ByteSink> sink, CompressionOptions options = {});

  Writer(Writer&&) noexcept;
  Writer& operator=(Writer&&) noexcept;
  // Without a successful finish(), the temporary file is removed: nothing is written.
  ~Writer();

  // Adds a track; returns its id (0, 1, ... in call order). `flags` bit 0 (kTrackRequired) tells
  // readers that do not know `kind` to refuse the file rather than skip the track.
  Expected<uint16_t> add_track(uint16_t kind, uint16_t flags, std::vector<uint8_t> header);
  template <class H>
  Expected<uint16_t> add_track(const H& header, uint16_t flags = kTrackRequired) {
    CALF_ASSIGN_OR_RETURN(auto blob, encode_track_header(header));
    return add_track(static_cast<uint16_t>(H::kKind), flags, std::move(blob));
  }
  // Replaces a track's header blob (facts known only at the end, e.g. the frame count).
  Status set_track_header(uint16_t track, std::vector<uint8_t> header);
  template <class H>
  Status set_track_header(uint16_t track, const H& header) {
    CALF_ASSIGN_OR_RETURN(auto blob, encode_track_header(header));
    return set_track_header(track, std::move(blob));
  }
  // Sets a metadata pair (UTF-8, key 1..256 bytes without NUL); a later call replaces the value.
  // Pairs are written sorted by key, so call order does not change the bytes.
  Status set_metadata(std::string key, std::string value);

  // Compresses `raw` and appends it as the next chunk; returns its id (0, 1, ... in call order:
  // the call order is the file order, so call in a deterministic order).
  Expected<uint32_t> add_chunk(const ChunkKeys& keys, std::span<const uint8_t> raw,
                               Compression compression);
  // Appends an already compressed chunk (from compress_chunk(), possibly on another thread).
  Expected<uint32_t> add_stored_chunk(const ChunkKeys& keys, const StoredChunk& chunk);
  // Writes the directory, patches the header and commits. The writer is spent afterwards.
  Status finish();
  // Raises the header's version_minor to at least `minor`, for contents of a later minor version
  // that older readers skip (a lightfield coverage stream: kVersionMinorCoverage).
  void require_minor_version(uint16_t minor);

  uint32_t chunk_count() const;
  uint64_t bytes_written() const;

 private:
  struct State;
  explicit Writer(std::unique_ptr<State> state);
  std::unique_ptr<State> s_;
};

}  // namespace calf::container
