// bench-colour_layout CLIP.calf ...: what lossless rearrangements of the BC6H / BC7 colour
// keyframe chunks (SPEC §11.1.5: 16-byte blocks in order) would save under per-chunk zstd, before
// any bitstream change is made for them (docs/ENCODER.md "Colour RDO"). Every colour chunk of the
// clip's lightfield track is decompressed and compressed again, on its own, as:
//   stored      the chunk's stored bytes (today's zstd-19 or whatever the clip holds)
//   zstd-19     the blocks as they are
//   zstd-22     the same at zstd's highest level
//   split-K     bytes 0..K-1 of every block, then bytes K..15 (K = 4, 8, 10, 12)
//   planes-16   byte k of every block, k = 0..15 (16 byte planes)
// and prints the totals. Only blocks of 16 bytes are measured; other colour formats are skipped.
#include <cstdio>
#include <string>
#include <vector>

#include "calf/format/container.h"
#include "calf/format/container_codec.h"
#include "calf/format/lightfield_layout.h"

namespace {

using namespace calf;

size_t zstd_bytes(const std::vector<uint8_t>& raw, int level) {
  container::CompressionOptions o;
  o.zstd_level = level;
  auto c = container::compress_chunk(raw, container::Compression::kZstd, o);
  return c.ok() ? c->bytes.size() : 0;
}

std::vector<uint8_t> split(const std::vector<uint8_t>& blocks, size_t k) {
  std::vector<uint8_t> out;
  out.reserve(blocks.size());
  for (size_t b = 0; b + 16 <= blocks.size(); b += 16)
    out.insert(out.end(), blocks.begin() + b, blocks.begin() + b + k);
  for (size_t b = 0; b + 16 <= blocks.size(); b += 16)
    out.insert(out.end(), blocks.begin() + b + k, blocks.begin() + b + 16);
  return out;
}

// Byte k of every block, k = 0..15: the layout's own byte planes (SPEC §11.1.5, rgba8).
std::vector<uint8_t> planes(const std::vector<uint8_t>& blocks) {
  std::vector<uint8_t> out;
  out.reserve(blocks.size());
  lf::append_planes(out, blocks, 16);
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: bench-colour_layout CLIP.calf ...\n");
    return 2;
  }
  std::printf(
      "| clip | chunks | raw | stored | zstd-19 | zstd-22 | split-4 | split-8 | split-10 | "
      "split-12 | planes-16 |\n|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
  for (int a = 1; a < argc; ++a) {
    auto r = container::Reader::open(argv[a]);
    if (!r.ok()) {
      std::fprintf(stderr, "%s: %s\n", argv[a], r.status().to_string().c_str());
      return 1;
    }
    size_t n = 0, raw = 0, stored = 0, z19 = 0, z22 = 0, s4 = 0, s8 = 0, s10 = 0, s12 = 0, p16 = 0;
    for (uint32_t id = 0; id < r->chunks().size(); ++id) {
      const container::ChunkEntry& e = r->chunks()[id];
      if (e.keys.stream != static_cast<uint16_t>(container::LightfieldStream::kColour)) continue;
      auto bytes = r->read_chunk(id);
      if (!bytes.ok()) {
        std::fprintf(stderr, "%s: %s\n", argv[a], bytes.status().to_string().c_str());
        return 1;
      }
      if (bytes->size() % 16 != 0) continue;
      ++n;
      raw += bytes->size();
      stored += e.stored_size;
      z19 += zstd_bytes(*bytes, 19);
      z22 += zstd_bytes(*bytes, 22);
      s4 += zstd_bytes(split(*bytes, 4), 19);
      s8 += zstd_bytes(split(*bytes, 8), 19);
      s10 += zstd_bytes(split(*bytes, 10), 19);
      s12 += zstd_bytes(split(*bytes, 12), 19);
      p16 += zstd_bytes(planes(*bytes), 19);
    }
    std::printf("| %s | %zu | %zu | %zu | %zu | %zu | %zu | %zu | %zu | %zu | %zu |\n", argv[a], n,
                raw, stored, z19, z22, s4, s8, s10, s12, p16);
  }
  return 0;
}
