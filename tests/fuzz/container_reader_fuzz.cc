// Fuzz target: the container reader on arbitrary bytes. Opens them as a .calf file, reads every
// chunk that is small enough, verifies, queries. Any crash, sanitizer report or hang is a bug;
// errors are expected. Seeded from the conformance suite (valid and malformed files).
#include <cstddef>
#include <cstdint>

#include "calf/format/container.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace calf::container;
  auto r = Reader::open(memory_source(std::span<const uint8_t>(data, size)));
  if (!r.ok()) return 0;
  // Raw sizes up to kMaxRawChunkSize are legal, but a fuzzer input claiming 1 GiB of zeros would
  // only measure memset: cap what we decompress per input.
  uint64_t budget = 64u << 20;
  std::vector<uint8_t> scratch, out;
  for (uint32_t i = 0; i < r->chunks().size(); ++i) {
    const ChunkEntry& e = r->chunks()[i];
    if (e.raw_size > budget) continue;
    budget -= e.raw_size;
    out.resize(e.raw_size);
    (void)r->read_chunk_into(i, out, scratch).ok();
  }
  if (budget > 0 && r->chunks().size() < 256) (void)r->verify(8).size();
  ChunkQuery q;
  q.track = 0;
  q.frame = 1;
  (void)r->find_chunks(q).size();
  (void)r->find_metadata("title");
  (void)r->read_chunk(static_cast<uint32_t>(r->chunks().size())).ok();  // out of range
  return 0;
}
