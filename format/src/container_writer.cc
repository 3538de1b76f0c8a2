// The container writer: header placeholder, chunks streamed in call order with zero padding to
// 16 bytes, then the directory, then the real header patched over the placeholder.
#include <algorithm>
#include <map>

#include "calf/format/container.h"

namespace calf::container {

struct Writer::State {
  std::unique_ptr<ByteSink> sink;
  CompressionOptions options;
  uint64_t position = 0;  // bytes appended so far
  std::vector<TrackRecord> tracks;
  std::map<std::string, std::string> metadata;  // sorted by key: deterministic order
  std::vector<ChunkEntry> chunks;
  bool finished = false;
  uint16_t minor_version = 0;  // the least minor version the file's contents ask for
  Status failed;               // a sink failure poisons the writer: the file could be inconsistent
};

namespace {

uint64_t align_up(uint64_t v) {
  return (v + kAlignment - 1) & ~(kAlignment - 1);
}

Status misuse(std::string message) {
  return Status(ErrorId::kContainerWriterMisuse, std::move(message));
}

}  // namespace

Writer::Writer(std::unique_ptr<State> state) : s_(std::move(state)) {}

void Writer::require_minor_version(uint16_t minor) {
  s_->minor_version = std::max(s_->minor_version, minor);
}
Writer::Writer(Writer&&) noexcept = default;
Writer& Writer::operator=(Writer&&) noexcept = default;
Writer::~Writer() = default;

Expected<Writer> Writer::create(const std::string& path, CompressionOptions options) {
  CALF_ASSIGN_OR_RETURN(auto sink, create_file_sink(path));
  return create(std::move(sink), options);
}

Expected<Writer> Writer::create(std::unique_ptr<ByteSink> sink, CompressionOptions options) {
  auto s = std::make_unique<State>();
  s->sink = std::move(sink);
  s->options = options;
  // The header is patched in finish(); until then its place holds zeros.
  const std::vector<uint8_t> placeholder(kHeaderSize, 0);
  CALF_RETURN_IF_ERROR(s->sink->append(placeholder));
  s->position = kHeaderSize;
  return Writer(std::move(s));
}

uint32_t Writer::chunk_count() const {
  return static_cast<uint32_t>(s_->chunks.size());
}
uint64_t Writer::bytes_written() const {
  return s_->position;
}

Expected<uint16_t> Writer::add_track(uint16_t kind, uint16_t flags, std::vector<uint8_t> header) {
  if (s_->finished) return misuse("add_track after finish");
  if (s_->tracks.size() >= kMaxTracks) return misuse(cat("more than ", kMaxTracks, " tracks"));
  TrackRecord t{kind, flags, std::move(header)};
  std::vector<uint8_t> probe;
  CALF_RETURN_IF_ERROR(write_fields(t, probe, cat("track ", s_->tracks.size())));
  s_->tracks.push_back(std::move(t));
  return static_cast<uint16_t>(s_->tracks.size() - 1);
}

Status Writer::set_track_header(uint16_t track, std::vector<uint8_t> header) {
  if (s_->finished) return misuse("set_track_header after finish");
  if (track >= s_->tracks.size()) return misuse(cat("track ", track, " does not exist"));
  if (header.size() > kMaxTrackHeaderSize)
    return misuse(cat("track header of ", header.size(), " bytes exceeds ", kMaxTrackHeaderSize));
  s_->tracks[track].header = std::move(header);
  return Status::Ok();
}

Status Writer::set_metadata(std::string key, std::string value) {
  if (s_->finished) return misuse("set_metadata after finish");
  if (key.empty() || key.size() > kMaxMetadataKeySize || key.find('\0') != std::string::npos ||
      !is_valid_utf8(key))
    return misuse(cat("metadata key '", key, "' is empty, longer than ", kMaxMetadataKeySize,
                      " bytes, holds NUL or is not UTF-8"));
  if (!is_valid_utf8(value)) return misuse(cat("metadata '", key, "': value is not UTF-8"));
  uint64_t total = key.size() + value.size();
  for (const auto& [k, v] : s_->metadata)
    if (k != key) total += k.size() + v.size();
  if (total > kMaxMetadataBytes)
    return misuse(cat("metadata exceeds ", kMaxMetadataBytes, " bytes"));
  if (!s_->metadata.count(key) && s_->metadata.size() >= kMaxMetadataEntries)
    return misuse(cat("more than ", kMaxMetadataEntries, " metadata entries"));
  s_->metadata[std::move(key)] = std::move(value);
  return Status::Ok();
}

Expected<uint32_t> Writer::add_chunk(const ChunkKeys& keys, std::span<const uint8_t> raw,
                                     Compression compression) {
  CALF_ASSIGN_OR_RETURN(StoredChunk stored, compress_chunk(raw, compression, s_->options));
  return add_stored_chunk(keys, stored);
}

Expected<uint32_t> Writer::add_stored_chunk(const ChunkKeys& keys, const StoredChunk& chunk) {
  if (s_->finished) return misuse("add_chunk after finish");
  CALF_RETURN_IF_ERROR(s_->failed);
  if (keys.track >= s_->tracks.size())
    return misuse(cat("chunk for track ", keys.track, ", which does not exist"));
  if (s_->chunks.size() >= kMaxChunks) return misuse(cat("more than ", kMaxChunks, " chunks"));
  const auto c = chunk.compression;
  if (static_cast<uint16_t>(c) >= kCompressionCount || chunk.raw_size > kMaxRawChunkSize ||
      chunk.bytes.size() > stored_bound(chunk.raw_size, c) ||
      (c == Compression::kNone && chunk.bytes.size() != chunk.raw_size))
    return misuse(cat("stored chunk (", compression_name(c), ", ", chunk.bytes.size(), " stored, ",
                      chunk.raw_size, " raw bytes) is inconsistent"));
  ChunkEntry e;
  e.offset = s_->position;  // already aligned: every append below ends aligned
  e.stored_size = chunk.bytes.size();
  e.raw_size = chunk.raw_size;
  e.hash = hash64(chunk.bytes);
  e.compression = static_cast<uint16_t>(c);
  e.keys = keys;
  // Write the chunk and its zero padding; a failing sink poisons the writer.
  static const uint8_t kZeros[kAlignment] = {};
  Status st = s_->sink->append(chunk.bytes);
  const uint64_t end = e.offset + e.stored_size;
  if (st.ok()) st = s_->sink->append(std::span<const uint8_t>(kZeros, align_up(end) - end));
  if (!st.ok()) {
    s_->failed = st;
    return st;
  }
  s_->position = align_up(end);
  s_->chunks.push_back(e);
  return static_cast<uint32_t>(s_->chunks.size() - 1);
}

Status Writer::finish() {
  if (s_->finished) return misuse("finish called twice");
  s_->finished = true;
  CALF_RETURN_IF_ERROR(s_->failed);
  // Directory body: metadata count + pairs, track records, chunk entries.
  std::vector<uint8_t> body;
  CALF_RETURN_IF_ERROR(
      write_fields(MetadataCount{static_cast<uint32_t>(s_->metadata.size())}, body));
  for (const auto& [k, v] : s_->metadata)
    CALF_RETURN_IF_ERROR(write_fields(MetadataEntry{k, v}, body, "metadata"));
  for (size_t i = 0; i < s_->tracks.size(); ++i)
    CALF_RETURN_IF_ERROR(write_fields(s_->tracks[i], body, cat("track ", i)));
  for (size_t i = 0; i < s_->chunks.size(); ++i)
    CALF_RETURN_IF_ERROR(write_fields(s_->chunks[i], body, cat("chunk ", i)));
  // Plain (1.0): the body itself. Compressed (1.1): its size and one zstd frame of it; the
  // chunk entries are regular (canonical offsets, repeating keys), so 64 bytes shrink to ~10.
  FileHeader h;
  std::vector<uint8_t> dir;
  if (s_->options.compress_directory) {
    // Always one zstd frame (SPEC §4.1), even where it is no smaller than the body.
    CompressionOptions zstd_frame = s_->options;
    zstd_frame.store_when_larger = false;
    CALF_ASSIGN_OR_RETURN(StoredChunk packed, compress_chunk(body, Compression::kZstd, zstd_frame));
    CALF_RETURN_IF_ERROR(write_fields(DirectoryBodySize{body.size()}, dir));
    dir.insert(dir.end(), packed.bytes.begin(), packed.bytes.end());
    h.version_minor = kVersionMinor;
    h.required_features |= kFeatureCompressedDirectory;
  } else {
    dir = std::move(body);
  }
  h.version_minor = std::max(h.version_minor, s_->minor_version);
  CALF_RETURN_IF_ERROR(write_fields(Checksum{hash64(dir)}, dir));
  h.directory_offset = s_->position;
  h.directory_size = dir.size();
  h.file_size = h.directory_offset + h.directory_size;
  h.chunk_count = static_cast<uint32_t>(s_->chunks.size());
  h.track_count = static_cast<uint32_t>(s_->tracks.size());
  std::vector<uint8_t> head;
  CALF_RETURN_IF_ERROR(write_fields(h, head, "header"));
  store_le(head.data() + kHeaderChecksumOffset,
           hash64(std::span<const uint8_t>(head).first(kHeaderChecksumOffset)), 8);
  CALF_RETURN_IF_ERROR(s_->sink->append(dir));
  CALF_RETURN_IF_ERROR(s_->sink->patch(0, head));
  s_->position = h.file_size;
  return s_->sink->commit();
}

}  // namespace calf::container
