// The tiles track's size and speed (format/SPEC.md §11.2) on a Seurat-sized synthetic set
// (tests/integration/synthetic_tiles.h: cells x cells tiles per cube face, each from an s x s
// texel rectangle; default 64 x 64 x 6 = 24,576 tiles, 49,152 triangles, 8 x 8 texels each in a
// 1024 x 1536 atlas). Per supercompression: the quads' bytes per tile (96 raw) beside the same
// floats unpredicted (plain binary32 compressed whole, the peer); per BC7 quality: the atlas's
// stored bits per texel, PSNR of the decoded atlas (RGBA), encode ms; decode ms of the whole
// track (open, quads, atlas to RGBA8). Median of --repeats runs for the timings.
//
//   bench-tiles_track_bench [--cells 64] [--texels 8] [--atlas-width 1024] [--repeats 3]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <vector>

#include <CLI/CLI.hpp>

#include "../integration/synthetic_tiles.h"
#include "calf/decoder/tiles_track.h"
#include "calf/encoder/tiles_encode.h"
#include "calf/format/container.h"

namespace {

using namespace calf;
using Clock = std::chrono::steady_clock;
using container::Compression;

double ms_since(Clock::time_point t) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"tiles track size and speed (SPEC §11.2)"};
  uint32_t cells = 64, texels = 8, width = 1024, repeats = 3;
  app.add_option("--cells", cells, "tiles per cube-face side (default 64)");
  app.add_option("--texels", texels, "texels per tile side (default 8)");
  app.add_option("--atlas-width", width, "atlas width (default 1024)");
  app.add_option("--repeats", repeats, "timing repeats (default 3)");
  CLI11_PARSE(app, argc, argv);
  const TileSet set = test::make_synthetic_tile_set(cells, texels, width, 1);
  std::printf("%zu tiles (%zu triangles), atlas %u x %u\n", set.tiles.size(), 2 * set.tiles.size(),
              set.atlas_width, set.atlas_height);

  // Peer: the tiles' 24 floats as they are, compressed whole.
  std::vector<uint8_t> plain;
  for (const Tile& t : set.tiles) {
    for (const TileCorner& c : t.corners) {
      const auto* p = reinterpret_cast<const uint8_t*>(c.position.data());
      plain.insert(plain.end(), p, p + 12);
      const auto* u = reinterpret_cast<const uint8_t*>(c.uvw.data());
      plain.insert(plain.end(), u, u + 12);
    }
  }
  std::printf("%-8s %-10s %12s %12s %12s %10s %12s %12s\n", "scheme", "atlas", "quads B/tile",
              "plain B/tile", "atlas bit/tx", "PSNR dB", "encode ms", "decode ms");
  for (Compression c : {Compression::kZstd, Compression::kLzma2}) {
    auto peer = container::compress_chunk(plain, c);
    const double peer_per_tile = static_cast<double>(peer->bytes.size()) / set.tiles.size();
    for (int q = -1; q <= 2; ++q) {
      encoder::TilesEncodeOptions o;
      o.supercompression = c;
      o.atlas_format = q < 0 ? encoder::TilesAtlasFormat::kRgba8 : encoder::TilesAtlasFormat::kBc7;
      o.bc7_quality = std::max(q, 0);
      o.threads = 1;
      std::vector<double> enc, dec;
      encoder::TilesEncodeStats stats;
      std::vector<uint8_t> file;
      for (uint32_t r = 0; r < repeats; ++r) {
        file.clear();
        auto w = container::Writer::create(container::memory_sink(&file));
        const auto t0 = Clock::now();
        if (!encoder::encode_tiles_track(set, o, &*w, &stats).ok() || !w->finish().ok()) return 1;
        enc.push_back(ms_since(t0));
        const auto t1 = Clock::now();
        auto reader =
            container::Reader::open(container::memory_source(std::span<const uint8_t>(file)));
        auto got = decoder::decode_tiles_track(*reader, 0);
        if (!got.ok()) return 1;
        dec.push_back(ms_since(t1));
      }
      std::printf("%-8s %-10s %12.2f %12.2f %12.3f %10.2f %12.0f %12.1f\n",
                  container::compression_name(c),
                  q < 0 ? "rgba8"
                        : (q == 0   ? "BC7 q0"
                           : q == 1 ? "BC7 q1"
                                    : "BC7 q2"),
                  static_cast<double>(stats.quads_stored) / stats.tiles, peer_per_tile,
                  8.0 * stats.atlas_stored / (double(set.atlas_width) * set.atlas_height),
                  stats.atlas_psnr_db, median(enc), median(dec));
    }
  }
  return 0;
}
