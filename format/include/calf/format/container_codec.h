// Chunk hashing and supercompression (format/SPEC.md "Hashes", "Supercompression").
//
// These functions are pure and thread-safe: an encoder may compress chunks on any number of
// threads and hand the StoredChunks to the Writer in its own deterministic order; the bytes are
// the same whatever the thread count, because each chunk is compressed single-threaded with a
// fixed level.
//
//   none   stored == raw.
//   zstd   one regular zstd frame (RFC 8878), Frame_Content_Size == raw_size, Window_Size <= 128
//          MiB, no dictionary, exactly stored_size bytes; no zstd checksum written, one checked.
//   LZMA2  one property byte (the LZMA2 dictionary size, encoded as in .xz filter flags), then a
//          raw LZMA2 stream ending with its end marker, exactly stored_size bytes. The writer
//          shrinks the dictionary to the chunk (>= 4 KiB); a reader refuses > kMaxLzmaDictionary.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "calf/format/container_types.h"
#include "calf/format/status.h"

namespace calf::container {

// XXH3-64 with seed 0: every checksum and chunk hash of the container.
uint64_t hash64(std::span<const uint8_t> bytes);

// Compression levels. Fixed per clip: the same level gives the same bytes.
struct CompressionOptions {
  int zstd_level = 19;       // 1..22 (ZSTD_maxCLevel)
  uint32_t lzma_preset = 6;  // 0..9
  // The Writer stores the directory as one zstd frame at zstd_level (container 1.1, required
  // feature bit 0; SPEC.md §4.1 "Compressed directory"): 9-14 bytes per chunk instead of 64. False
  // writes a plain 1.0 directory, which 1.0 readers open.
  bool compress_directory = true;
  // compress_chunk stores a chunk as kNone when zstd / LZMA2 would make it no smaller (a short
  // chunk, or bytes that do not compress: SPEC §6.3 lets every chunk name its own scheme, and
  // every reader, 1.0 included, reads kNone). False keeps the requested scheme whatever it costs,
  // as the writers of the pinned 1.0 clips did.
  bool store_when_larger = true;
};

// A chunk ready for Writer::add_stored_chunk(): stored bytes, their scheme and raw length.
struct StoredChunk {
  Compression compression = Compression::kNone;
  uint64_t raw_size = 0;
  std::vector<uint8_t> bytes;
};

// The largest stored size `compress_chunk` can produce for `raw_size` bytes with `c`, and the
// largest a reader accepts for that raw size (a larger one is kContainerChunkSize). Use it to
// size a caller-owned stored buffer. Returns 0 for an unknown scheme.
uint64_t stored_bound(uint64_t raw_size, Compression c);

// Compresses `raw` with `c`. Errors: kContainerWriterMisuse (raw larger than kMaxRawChunkSize,
// unknown scheme, level out of range), kContainerCompressor (library failure).
Expected<StoredChunk> compress_chunk(std::span<const uint8_t> raw, Compression c,
                                     const CompressionOptions& options = {});

// Decompresses `stored` (scheme `c`) into `out`, whose size is the chunk's raw length; fails
// with kContainerDecompress unless the stored bytes are exactly one well-formed stream that
// decodes to exactly out.size() bytes, kContainerLimit for a zstd window or an LZMA2 dictionary
// above its limit, kContainerCompression for an unknown scheme.
Status decompress_chunk(std::span<const uint8_t> stored, Compression c, std::span<uint8_t> out);

}  // namespace calf::container
