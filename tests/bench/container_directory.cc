// What the directory costs a clip (container 1.1, format/SPEC.md §4.1; docs/ENCODER.md
// "Compressed directory"): each clip's stored chunks are written again through the Writer in
// memory, once with a plain 1.0 directory and once compressed, so the two files differ only in
// their directory; then each is opened --repeat times (Reader::open from memory: header,
// directory, its decompression and parse) and the fastest open is printed. The plain rewrite of a
// 1.0 clip is checked to be byte-identical to the clip itself. Prints markdown, one row per clip.
//
//   bench-container_directory --clip A.calf [--clip B.calf ...] [--repeat 30]
#include <algorithm>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include "bench_clock.h"
#include "calf/format/container.h"

namespace {

using namespace calf;
using namespace calf::container;

using bench::now_ms;
// `r`'s tracks, metadata and stored chunks written again with the given directory form.
Expected<std::vector<uint8_t>> rewrite(const Reader& r, bool compressed) {
  std::vector<uint8_t> file;
  CALF_ASSIGN_OR_RETURN(
      Writer w,
      Writer::create(memory_sink(&file), CompressionOptions{.compress_directory = compressed}));
  for (const Track& t : r.tracks())
    CALF_RETURN_IF_ERROR(w.add_track(t.record.kind, t.record.flags, t.record.header).status());
  for (const MetadataEntry& m : r.metadata()) CALF_RETURN_IF_ERROR(w.set_metadata(m.key, m.value));
  for (uint32_t i = 0; i < r.chunks().size(); ++i) {
    const ChunkEntry& e = r.chunks()[i];
    StoredChunk c;
    c.compression = static_cast<Compression>(e.compression);
    c.raw_size = e.raw_size;
    CALF_ASSIGN_OR_RETURN(c.bytes, r.read_stored(i));
    CALF_RETURN_IF_ERROR(w.add_stored_chunk(e.keys, c).status());
  }
  CALF_RETURN_IF_ERROR(w.finish());
  return file;
}

// The fastest of `repeat` opens of `file` from memory, in ms.
Expected<double> open_ms(const std::vector<uint8_t>& file, int repeat) {
  double best = 1e300;
  for (int k = 0; k < repeat; ++k) {
    const double t0 = now_ms();
    auto r = Reader::open(memory_source(std::span<const uint8_t>(file)));
    const double t = now_ms() - t0;
    CALF_RETURN_IF_ERROR(r.status());
    best = std::min(best, t);
  }
  return best;
}

int run(const std::string& path, int repeat) {
  auto fail = [&](const Status& s) {
    fmt::print(stderr, "bench-container_directory: {}\n", s.to_string());
    return 1;
  };
  auto r = Reader::open(path);
  if (!r.ok()) return fail(r.status());
  auto plain = rewrite(*r, false);
  if (!plain.ok()) return fail(plain.status().with_context(path));
  auto packed = rewrite(*r, true);
  if (!packed.ok()) return fail(packed.status().with_context(path));
  const bool was_plain = (r->header().required_features & kFeatureCompressedDirectory) == 0;
  if (was_plain && plain->size() != r->header().file_size) {
    fmt::print(stderr, "bench-container_directory: {}: the plain rewrite has {} bytes, not {}\n",
               path, plain->size(), r->header().file_size);
    return 1;
  }
  auto t_plain = open_ms(*plain, repeat);
  if (!t_plain.ok()) return fail(t_plain.status());
  auto t_packed = open_ms(*packed, repeat);
  if (!t_packed.ok()) return fail(t_packed.status());
  uint64_t stored = 0;
  for (const ChunkEntry& e : r->chunks()) stored += e.stored_size;
  const size_t n = r->chunks().size();
  // Per chunk: everything but the header and the stored bytes (entry, padding, metadata, tracks).
  auto per_chunk = [&](size_t size) {
    return n ? static_cast<double>(size - kHeaderSize - stored) / static_cast<double>(n) : 0.0;
  };
  fmt::print("| {} | {} | {} | {} | {} | {:.1f} % | {:.1f} → {:.1f} B | {:.2f} / {:.2f} ms |\n",
             path, n, stored, plain->size(), packed->size(),
             100.0 * (1.0 - static_cast<double>(packed->size()) / plain->size()),
             per_chunk(plain->size()), per_chunk(packed->size()), *t_plain, *t_packed);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "Each clip's size with a plain (1.0) and a compressed (1.1) directory, and its open time"};
  std::vector<std::string> clips;
  int repeat = 30;
  app.add_option("--clip", clips, "a .calf clip of any kind (repeatable)")->required();
  app.add_option("--repeat", repeat, "opens per form; the fastest is printed (default 30)")
      ->check(CLI::Range(1, 100000));
  CLI11_PARSE(app, argc, argv);
  fmt::print(
      "| clip | chunks | stored chunk bytes | 1.0 file | 1.1 file | smaller | index + padding per "
      "chunk | open 1.0 / 1.1 |\n|---|---:|---:|---:|---:|---:|---|---|\n");
  int rc = 0;
  for (const auto& c : clips) rc |= run(c, repeat);
  return rc;
}
