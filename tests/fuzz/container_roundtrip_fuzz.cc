// Fuzz target: writer -> reader round trip driven by the input bytes. The input is cut into
// chunks whose keys and supercompression come from its bytes (the directory form from its size);
// the clip is written twice (must give identical bytes: determinism) and read back (every chunk
// must decode to its input, and verify must find nothing).
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <vector>

#include "calf/format/container.h"

namespace {

void check(bool ok) {
  if (!ok) std::abort();  // a fuzz finding: the round trip property broke
}

std::vector<uint8_t> write_clip(const uint8_t* data, size_t size,
                                std::vector<std::vector<uint8_t>>* raws) {
  using namespace calf::container;
  std::vector<uint8_t> file;
  // Both directory forms: plain (1.0) for odd sizes, compressed (1.1) for even ones.
  auto w = Writer::create(
      memory_sink(&file),
      CompressionOptions{.zstd_level = 1, .lzma_preset = 0, .compress_directory = size % 2 == 0});
  check(w.ok());
  check(w->add_track(LightfieldTrackHeader{}).ok());
  check(w->add_track(0x1234, 0, std::vector<uint8_t>(data, data + std::min<size_t>(size, 8))).ok());
  check(w->set_metadata("k", "v").ok());
  size_t pos = 0;
  while (pos + 2 <= size) {
    const uint8_t control = data[pos];
    const size_t n = std::min<size_t>(data[pos + 1] * 4u, size - pos - 2);
    pos += 2;
    raws->emplace_back(data + pos, data + pos + n);
    ChunkKeys k;
    k.track = control & 1;
    k.stream = control >> 4;
    k.view = control;
    auto id = w->add_chunk(k, raws->back(), static_cast<Compression>((control >> 1) % 3));
    check(id.ok());
    pos += n;
  }
  check(w->finish().ok());
  return file;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace calf::container;
  std::vector<std::vector<uint8_t>> raws, raws2;
  const auto a = write_clip(data, size, &raws);
  const auto b = write_clip(data, size, &raws2);
  check(a == b);
  auto r = Reader::open(memory_source(std::span<const uint8_t>(a)));
  check(r.ok());
  check(r->chunks().size() == raws.size());
  for (uint32_t i = 0; i < raws.size(); ++i) {
    auto raw = r->read_chunk(i);
    check(raw.ok() && *raw == raws[i]);
  }
  check(r->verify().empty());
  return 0;
}
