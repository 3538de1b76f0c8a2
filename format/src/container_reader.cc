// The container reader. open() trusts nothing: every count, offset and length is checked
// against the documented limits and the real file size before it sizes an allocation or a read
// (OpenEXR's CVE-2020-15306 came from trusting a stored count). Checks run in SPEC.md's order,
// so that a given damage always reports the same error id.
#include <algorithm>

#include "calf/format/container.h"

namespace calf::container {
namespace {

uint64_t align_up(uint64_t v) {
  return (v + kAlignment - 1) & ~(kAlignment - 1);
}

// Explains an identifier mismatch; text-mode transfers have recognisable fingerprints.
Status identifier_error(std::span<const uint8_t> got) {
  std::string why = "the file does not start with the calf identifier";
  if (got.size() >= 10 && got[0] == 0xAB && got[7] == 0xBB) {
    if (got[8] == 0x0A)
      why += " (CR LF became LF: a text-mode transfer damaged it)";
    else if (got[8] == 0x0D && got[9] == 0x0D)
      why += " (LF became CR LF: a text-mode transfer damaged it)";
  } else if (got.size() >= 1 && got[0] == 0x2B) {
    why += " (the first byte lost its high bit: a 7-bit transfer damaged it)";
  }
  return Status(ErrorId::kContainerIdentifier, why);
}

}  // namespace

Reader::Reader(Reader&&) noexcept = default;
Reader& Reader::operator=(Reader&&) noexcept = default;
Reader::~Reader() = default;

Expected<Reader> Reader::open(const std::string& path) {
  CALF_ASSIGN_OR_RETURN(auto source, open_file_source(path));  // its errors name the path
  Expected<Reader> r = open(std::move(source));
  if (!r.ok()) return std::move(r).status().with_context(path);
  return r;
}

Expected<Reader> Reader::open(std::unique_ptr<ByteSource> source) {
  Reader r;
  r.source_ = std::move(source);
  CALF_RETURN_IF_ERROR(r.load());
  return r;
}

Status Reader::load() {
  const uint64_t real_size = source_->size();
  // 1. Identifier, then the header's presence: a prefix of a good file is "truncated".
  std::array<uint8_t, kHeaderSize> head{};
  const size_t have = static_cast<size_t>(std::min<uint64_t>(real_size, kHeaderSize));
  CALF_RETURN_IF_ERROR(source_->read_at(0, std::span(head).first(have)));
  const size_t id_have = std::min<size_t>(have, kIdentifier.size());
  if (!std::equal(head.begin(), head.begin() + id_have, kIdentifier.begin()))
    return identifier_error(std::span(head).first(id_have));
  if (real_size < kHeaderSize)
    return Status(ErrorId::kContainerTruncated,
                  cat("the file has ", real_size, " bytes, the header alone needs ", kHeaderSize));
  // 2. Checksum before any field is believed.
  const uint64_t want = load_le(head.data() + kHeaderChecksumOffset, 8);
  const uint64_t got = hash64(std::span(head).first(kHeaderChecksumOffset));
  if (want != got)
    return Status(ErrorId::kContainerHeaderChecksum,
                  cat("header checksum is ", got, ", the header says ", want));
  // 3. Version and must-understand features, before fields whose meaning they could change.
  const uint16_t major = static_cast<uint16_t>(load_le(head.data() + 12, 2));
  if (major != kVersionMajor)
    return Status(ErrorId::kContainerVersion,
                  cat("version ", major, ".", load_le(head.data() + 14, 2),
                      " is not supported (this reader reads ", kVersionMajor, ".x)"));
  const uint32_t required = static_cast<uint32_t>(load_le(head.data() + 16, 4));
  if (required & ~kKnownRequiredFeatures)
    return Status(ErrorId::kContainerRequiredFeature,
                  cat("header required_features has unknown must-understand bits 0x", std::hex,
                      required & ~kKnownRequiredFeatures));
  FieldReader hr(head, ErrorId::kContainerTruncated, ErrorId::kContainerDirectoryFormat, "header");
  CALF_RETURN_IF_ERROR(read_fields(header_, hr));  // counts above their limits: kContainerLimit
  const FileHeader& h = header_;
  // 4. The file's size against the header's.
  if (real_size < h.file_size)
    return Status(ErrorId::kContainerTruncated,
                  cat("the file has ", real_size, " bytes, its header declares ", h.file_size));
  if (real_size > h.file_size)
    return Status(
        ErrorId::kContainerFileSize,
        cat("the file has ", real_size, " bytes, its header declares only ", h.file_size));
  // 5. The directory's place and size, bounded before it is allocated. A plain directory is
  // its body and checksum; a compressed one (1.1) the body's size, a zstd frame and checksum.
  const bool compressed = (h.required_features & kFeatureCompressedDirectory) != 0;
  const uint64_t min_body =
      4 + uint64_t{h.track_count} * 8 + uint64_t{h.chunk_count} * fixed_size<ChunkEntry>();
  const uint64_t max_body = min_body + uint64_t{kMaxMetadataEntries} * 8 + kMaxMetadataBytes +
                            uint64_t{h.track_count} * kMaxTrackHeaderSize;
  const uint64_t min_dir = compressed ? 16 : min_body + 8;
  const uint64_t max_dir =
      compressed ? 16 + stored_bound(max_body, Compression::kZstd) : max_body + 8;
  if (h.directory_offset < kHeaderSize || h.directory_offset % kAlignment != 0 ||
      h.directory_offset > h.file_size || h.directory_size != h.file_size - h.directory_offset ||
      h.directory_size < min_dir)
    return Status(ErrorId::kContainerDirectoryRange,
                  cat("directory at offset ", h.directory_offset, " with ", h.directory_size,
                      " bytes does not end a ", h.file_size, "-byte file on a 16-byte boundary",
                      compressed ? std::string(" with room for its body size and checksum")
                                 : cat(" with room for ", h.track_count, " tracks and ",
                                       h.chunk_count, " chunks")));
  if (h.directory_size > max_dir)
    return Status(ErrorId::kContainerLimit,
                  cat("directory of ", h.directory_size, " bytes exceeds its limit ", max_dir));
  std::vector<uint8_t> dir(h.directory_size);
  CALF_RETURN_IF_ERROR(source_->read_at(h.directory_offset, dir));
  const auto checked = std::span<const uint8_t>(dir).first(dir.size() - 8);
  const uint64_t dir_want = load_le(dir.data() + checked.size(), 8);
  if (hash64(checked) != dir_want)
    return Status(
        ErrorId::kContainerDirectoryChecksum,
        cat("directory checksum is ", hash64(checked), ", the directory says ", dir_want));
  std::span<const uint8_t> body = checked;
  std::vector<uint8_t> unpacked;
  if (compressed) {
    const uint64_t body_size = load_le(dir.data(), 8);
    if (body_size < min_body)
      return Status(ErrorId::kContainerDirectoryRange,
                    cat("compressed directory body of ", body_size, " bytes has no room for ",
                        h.track_count, " tracks and ", h.chunk_count, " chunks"));
    if (body_size > max_body)
      return Status(ErrorId::kContainerLimit, cat("compressed directory body of ", body_size,
                                                  " bytes exceeds its limit ", max_body));
    unpacked.resize(body_size);
    Status st = decompress_chunk(checked.subspan(8), Compression::kZstd, unpacked);
    if (!st.ok()) return std::move(st).with_context("compressed directory");
    body = unpacked;
  }
  directory_body_size_ = body.size();
  // 6. Directory entries.
  FieldReader dr(body, ErrorId::kContainerDirectoryFormat, ErrorId::kContainerDirectoryFormat,
                 "directory");
  MetadataCount mc;
  CALF_RETURN_IF_ERROR(read_fields(mc, dr));
  metadata_.resize(mc.count);  // <= kMaxMetadataEntries, checked by its Range
  uint64_t meta_bytes = 0;
  for (uint32_t i = 0; i < mc.count; ++i) {
    MetadataEntry& m = metadata_[i];
    CALF_RETURN_IF_ERROR(read_fields(m, dr));
    meta_bytes += m.key.size() + m.value.size();
    if (meta_bytes > kMaxMetadataBytes)
      return Status(ErrorId::kContainerLimit,
                    cat("metadata exceeds ", kMaxMetadataBytes, " bytes at entry ", i));
    if (m.key.find('\0') != std::string::npos || !is_valid_utf8(m.key) || !is_valid_utf8(m.value))
      return Status(ErrorId::kContainerMetadata,
                    cat("metadata entry ", i, ": key or value is not UTF-8 or the key holds NUL"));
    if (i > 0 && !(metadata_[i - 1].key < m.key))
      return Status(ErrorId::kContainerMetadata,
                    cat("metadata entry ", i, ": key '", m.key, "' does not follow '",
                        metadata_[i - 1].key, "' in strictly increasing order"));
  }
  tracks_.resize(h.track_count);
  for (uint32_t i = 0; i < h.track_count; ++i) {
    Track& t = tracks_[i];
    t.id = static_cast<uint16_t>(i);
    CALF_RETURN_IF_ERROR(read_fields(t.record, dr));
    const std::string context = cat("track ", i, " (", track_kind_name(t.record.kind), ")");
    CALF_ASSIGN_OR_RETURN(t.header, read_track_header(t.record.kind, t.record.header, context));
    t.known = !std::holds_alternative<std::monostate>(t.header);
    if (!t.known && (t.record.flags & kTrackRequired))
      return Status(ErrorId::kContainerTrackKind,
                    cat("track ", i, " has kind ", t.record.kind,
                        ", unknown to this reader, and is marked must-understand"));
    // An unknown optional track: kept as bytes, skipped by codecs.
  }
  chunks_.resize(h.chunk_count);  // <= kMaxChunks; min_body proved the bytes exist
  for (uint32_t i = 0; i < h.chunk_count; ++i) {
    dr.set_context(cat("chunk ", i));
    CALF_RETURN_IF_ERROR(read_fields(chunks_[i], dr));
  }
  if (dr.remaining() != 0)
    return Status(ErrorId::kContainerDirectoryFormat,
                  cat("directory has ", dr.remaining(), " bytes left over after its last entry"));
  return check_chunks();
}

// Each chunk's fields against its track, its scheme and the canonical layout: chunk 0 at 64,
// each next one at the 16-byte boundary after the previous, the directory after the last.
// Overlaps and gaps are thereby impossible, and every padding byte has a known place.
Status Reader::check_chunks() {
  uint64_t expected = kHeaderSize;
  const uint64_t area_end = header_.directory_offset;
  for (size_t i = 0; i < chunks_.size(); ++i) {
    const ChunkEntry& e = chunks_[i];
    auto fail = [&](ErrorId id, const std::string& m) {
      return Status(id, cat("chunk ", i, ": ", m));
    };
    if (e.keys.track >= tracks_.size())
      return fail(ErrorId::kContainerChunkTrack,
                  cat("track ", e.keys.track, " does not exist (", tracks_.size(), " tracks)"));
    if (e.compression >= kCompressionCount)
      return fail(ErrorId::kContainerCompression,
                  cat("supercompression ", e.compression, " is unknown"));
    if (e.flags & kChunkRequiredFlagsMask & ~kKnownChunkRequiredFlags)
      return fail(ErrorId::kContainerRequiredFeature,
                  cat("flags 0x", std::hex, e.flags, " set unknown must-understand bits"));
    const auto c = static_cast<Compression>(e.compression);
    if ((c == Compression::kNone && e.stored_size != e.raw_size) ||
        e.stored_size > stored_bound(e.raw_size, c))
      return fail(ErrorId::kContainerChunkSize,
                  cat("stored length ", e.stored_size, " is impossible for ", e.raw_size,
                      " raw bytes with ", compression_name(c)));
    if (e.offset < kHeaderSize || e.offset > area_end || e.stored_size > area_end - e.offset)
      return fail(ErrorId::kContainerChunkRange,
                  cat("offset ", e.offset, " + stored length ", e.stored_size,
                      " lies outside the chunk area [", kHeaderSize, ", ", area_end, ")"));
    if (e.offset != expected)
      return fail(ErrorId::kContainerChunkLayout,
                  cat("offset ", e.offset, " is not the canonical ", expected,
                      " (chunks are contiguous in index order, 16-byte aligned)"));
    expected = align_up(e.offset + e.stored_size);
  }
  if (expected != area_end)
    return Status(ErrorId::kContainerChunkLayout, cat("the chunk area ends at ", expected,
                                                      " but the directory starts at ", area_end));
  return Status::Ok();
}

const std::string* Reader::find_metadata(std::string_view key) const {
  auto it = std::lower_bound(metadata_.begin(), metadata_.end(), key,
                             [](const MetadataEntry& m, std::string_view k) { return m.key < k; });
  return it != metadata_.end() && it->key == key ? &it->value : nullptr;
}

std::vector<uint32_t> Reader::find_chunks(const ChunkQuery& q) const {
  std::vector<uint32_t> ids;
  for (size_t i = 0; i < chunks_.size(); ++i) {
    const ChunkKeys& k = chunks_[i].keys;
    if ((q.track && *q.track != k.track) || (q.stream && *q.stream != k.stream) ||
        (q.view && *q.view != k.view) || (q.face && *q.face != k.face) ||
        (q.region && *q.region != k.region) || (q.layer && *q.layer != k.layer))
      continue;
    if (q.frame && (*q.frame < k.first_frame || *q.frame - k.first_frame >= k.frame_count))
      continue;
    ids.push_back(static_cast<uint32_t>(i));
  }
  return ids;
}

Status Reader::read_stored_into(uint32_t id, std::span<uint8_t> out) const {
  if (id >= chunks_.size())
    return Status(ErrorId::kContainerChunkId,
                  cat("chunk ", id, " does not exist (", chunks_.size(), " chunks)"));
  const ChunkEntry& e = chunks_[id];
  if (out.size() != e.stored_size)
    return Status(ErrorId::kContainerBufferSize, cat("chunk ", id, ": buffer of ", out.size(),
                                                     " bytes for ", e.stored_size, " stored"));
  CALF_RETURN_IF_ERROR(source_->read_at(e.offset, out).with_context(cat("chunk ", id)));
  const uint64_t got = hash64(out);
  if (got != e.hash)
    return Status(ErrorId::kContainerChunkHash,
                  cat("chunk ", id, ": stored bytes hash to ", got, ", the index says ", e.hash));
  return Status::Ok();
}

Expected<std::vector<uint8_t>> Reader::read_stored(uint32_t id) const {
  if (id >= chunks_.size()) return read_stored_into(id, {});  // the error
  std::vector<uint8_t> out(chunks_[id].stored_size);          // validated against the file at open
  CALF_RETURN_IF_ERROR(read_stored_into(id, out));
  return out;
}

Status Reader::read_chunk_into(uint32_t id, std::span<uint8_t> out,
                               std::vector<uint8_t>& scratch) const {
  if (id >= chunks_.size()) return read_stored_into(id, {});  // the error
  const ChunkEntry& e = chunks_[id];
  if (out.size() != e.raw_size)
    return Status(ErrorId::kContainerBufferSize,
                  cat("chunk ", id, ": buffer of ", out.size(), " bytes for ", e.raw_size, " raw"));
  const auto c = static_cast<Compression>(e.compression);
  if (c == Compression::kNone) return read_stored_into(id, out);
  scratch.resize(e.stored_size);
  CALF_RETURN_IF_ERROR(read_stored_into(id, scratch));
  return decompress_chunk(scratch, c, out).with_context(cat("chunk ", id));
}

Status Reader::read_chunk_into(uint32_t id, std::span<uint8_t> out) const {
  std::vector<uint8_t> scratch;
  return read_chunk_into(id, out, scratch);
}

Expected<std::vector<uint8_t>> Reader::read_chunk(uint32_t id) const {
  if (id >= chunks_.size()) return read_stored_into(id, {});  // the error
  std::vector<uint8_t> out(chunks_[id].raw_size);  // <= kMaxRawChunkSize, checked at open
  CALF_RETURN_IF_ERROR(read_chunk_into(id, out));
  return out;
}

std::vector<Status> Reader::verify(size_t max_problems) const {
  std::vector<Status> problems;
  std::vector<uint8_t> raw, scratch;
  auto add = [&](Status s) {
    if (!s.ok() && problems.size() < max_problems) problems.push_back(std::move(s));
  };
  for (uint32_t i = 0; i < chunks_.size() && problems.size() < max_problems; ++i) {
    const ChunkEntry& e = chunks_[i];
    raw.resize(e.raw_size);
    add(read_chunk_into(i, raw, scratch));
    // The padding after the chunk: fewer than 16 bytes, all zero.
    const uint64_t end = e.offset + e.stored_size;
    uint8_t pad[kAlignment];
    const auto pad_span = std::span<uint8_t>(pad, align_up(end) - end);
    Status st = source_->read_at(end, pad_span);
    if (!st.ok()) {
      add(st.with_context(cat("padding after chunk ", i)));
      continue;
    }
    for (size_t k = 0; k < pad_span.size(); ++k)
      if (pad[k] != 0)
        add(Status(ErrorId::kContainerPadding, cat("padding byte at offset ", end + k,
                                                   " after chunk ", i, " is ", pad[k], ", not 0")));
  }
  return problems;
}

}  // namespace calf::container
