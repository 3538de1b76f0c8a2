// Decode cost of a clip's depth stream (predicted depth must not make decoding much
// slower than raw16): for every depth chunk of the first lightfield track, the time to
// decompress its stored bytes (zstd / LZMA2, held in memory: no file I/O), then the time to turn
// every rectangle into GPU-ready codes (lf::parse_region_chunk + lf::region_rect_gpu_bytes: the
// byte-plane interleave for r16, the inverse prediction for r16p), and a memcpy of those codes as
// the floor. Median of --repeat runs, one thread. Prints markdown, one row per clip.
//
//   bench-depth_decode --clip A.calf [--clip B.calf ...] [--repeat 7]
#include <algorithm>
#include <chrono>
#include <cstring>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include "calf/format/container.h"
#include "calf/format/container_codec.h"
#include "calf/format/grid.h"
#include "calf/format/lightfield_layout.h"

namespace {

using namespace calf;

double now_ms() {
  return std::chrono::duration<double, std::milli>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

struct DepthChunk {
  std::vector<uint8_t> stored, raw;
  container::Compression compression{};
  uint32_t frame_count = 0, width = 0, height = 0;
};

int run(const std::string& path, int repeat) {
  auto r = container::Reader::open(path);
  if (!r.ok()) {
    fmt::print(stderr, "{}\n", r.status().to_string());
    return 1;
  }
  const container::LightfieldTrackHeader* h = nullptr;
  uint16_t track = 0;
  for (const auto& t : r->tracks()) {
    if ((h = std::get_if<container::LightfieldTrackHeader>(&t.header)) != nullptr) {
      track = t.id;
      break;
    }
  }
  if (h == nullptr) {
    fmt::print(stderr, "{}: no lightfield track\n", path);
    return 1;
  }
  auto coding = lf::depth_coding(h->depth_format);
  auto grid = FaceGrid::with_cell_size(h->face_size, h->depth_region_size);
  if (!coding.ok() || !grid.ok()) {
    fmt::print(stderr, "{}: {}\n", path,
               (coding.ok() ? grid.status() : coding.status()).to_string());
    return 1;
  }
  std::vector<DepthChunk> chunks;
  uint64_t stored = 0, raw = 0, texels = 0;
  const auto& entries = r->chunks();
  for (uint32_t id = 0; id < entries.size(); ++id) {
    const auto& e = entries[id];
    if (e.keys.track != track ||
        e.keys.stream != static_cast<uint16_t>(container::LightfieldStream::kDepth)) {
      continue;
    }
    DepthChunk c;
    auto s = r->read_stored(id);
    auto rect = grid->cell_rect(e.keys.region);
    if (!s.ok() || !rect.ok()) {
      fmt::print(stderr, "{}: chunk {} unreadable\n", path, id);
      return 1;
    }
    c.stored = std::move(*s);
    c.raw.resize(e.raw_size);
    c.compression = static_cast<container::Compression>(e.compression);
    c.frame_count = e.keys.frame_count;
    c.width = rect->width;
    c.height = rect->height;
    stored += e.stored_size;
    raw += e.raw_size;
    chunks.push_back(std::move(c));
  }
  std::vector<double> t_dec, t_codes, t_copy;
  std::vector<uint8_t> out, source, sink;
  std::vector<uint16_t> tile;  // little-endian host assumed, as the GPU bytes are
  for (int rep = 0; rep < repeat; ++rep) {
    double t0 = now_ms();
    for (DepthChunk& c : chunks) {
      if (!container::decompress_chunk(c.stored, c.compression, c.raw).ok()) {
        fmt::print(stderr, "{}: decompression failed\n", path);
        return 1;
      }
    }
    double t1 = now_ms();
    uint64_t n = 0;
    for (const DepthChunk& c : chunks) {
      auto p = lf::parse_region_chunk(c.raw, c.frame_count, c.width, c.height, *coding, "depth");
      if (!p.ok()) {
        fmt::print(stderr, "{}: {}\n", path, p.status().to_string());
        return 1;
      }
      // r16pm's P-frame rectangles read the tile state: the codes of the frame before, kept
      // here as the decoders keep them (a copy in and out of every rectangle, as theirs).
      const bool masked = *coding == lf::RegionCoding::kR16PredictedMasked;
      if (masked) tile.assign(size_t{c.width} * c.height, 0);
      for (size_t i = 0; i < p->rects.size(); ++i) {
        const lf::RegionRect& rr = p->rects[i];
        if (masked && lf::region_rect_reads_state(*p, i)) {
          out.resize(size_t{rr.w} * rr.h * 2);
          for (uint32_t y = 0; y < rr.h; ++y)
            std::memcpy(&out[size_t{y} * rr.w * 2], &tile[size_t{rr.y + y} * c.width + rr.x],
                        size_t{rr.w} * 2);
        }
        lf::region_rect_gpu_bytes(*p, i, out);
        if (masked) {
          for (uint32_t y = 0; y < rr.h; ++y)
            std::memcpy(&tile[size_t{rr.y + y} * c.width + rr.x], &out[size_t{y} * rr.w * 2],
                        size_t{rr.w} * 2);
        }
        n += out.size();
      }
    }
    double t2 = now_ms();
    texels = n / 2;
    t_dec.push_back(t1 - t0);
    t_codes.push_back(t2 - t1);
    source.resize(n, 1);
    sink.resize(n);
    const double t3 = now_ms();
    std::memcpy(sink.data(), source.data(), n);
    t_copy.push_back(now_ms() - t3);
  }
  const double dec = median(t_dec), codes = median(t_codes), copy = median(t_copy);
  fmt::print("| {} | {} | {} | {} | {} | {} | {:.2f} | {:.2f} | {:.2f} | {:.3f} | {:.0f} |\n", path,
             container::pixel_format_name(h->depth_format), chunks.size(), texels, stored, raw, dec,
             codes, dec + codes, copy, texels / ((dec + codes) * 1e3));
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Depth stream decode time per clip: decompression, then codes (r16 / r16p / r16pm)"};
  std::vector<std::string> clips;
  int repeat = 7;
  app.add_option("--clip", clips, "a .calf with a lightfield track (repeatable)")->required();
  app.add_option("--repeat", repeat, "runs per clip; the median is printed (default 7)")
      ->check(CLI::Range(1, 1000));
  CLI11_PARSE(app, argc, argv);
  fmt::print(
      "| clip | depth format | chunks | texels decoded | stored bytes | raw bytes | decompress ms "
      "| "
      "codes ms | total ms | memcpy ms | Mtexel/s |\n|---|---|---:|---:|---:|---:|---:|---:|---:|"
      "---:|---:|\n");
  int rc = 0;
  for (const auto& c : clips) rc |= run(c, repeat);
  return rc;
}
