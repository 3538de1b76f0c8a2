// The crafted tiles, surfels and mesh conformance clips (tests/conformance/{tiles,surfels,mesh}/
// crafted_*, format/SPEC.md §11.2 – §11.4, §14): the committed files are what the generator
// (tests/conformance/tracks_crafted.h) derives, and they hold what tests/conformance/README.md
// says, counted here from the bytes by the SPEC's layouts. calf-verify --decode prints their
// committed hashes (ctest cli.calf_verify_decode_{tiles,surfels,mesh}_crafted_*), and the
// clean-room reader written from the SPEC alone prints them too (ctest conformance.clean_room_*).
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>
#include <string>
#include <vector>

#include "../conformance/block_census.h"
#include "../conformance/tracks_crafted.h"
#include "calf/format/container.h"

namespace calf::conformance::tracks_crafted {
namespace {

namespace fs = std::filesystem;

fs::path suite_dir(const std::string& folder) {
  const char* root = std::getenv("CALF_SOURCE_DIR");
  return fs::path(root ? root : ".") / "tests" / "conformance" / folder;
}

Bytes read_file(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

container::Reader open_clip(const std::string& folder, const std::string& name) {
  auto r = container::Reader::open((suite_dir(folder) / (name + ".calf")).string());
  EXPECT_TRUE(r.ok()) << name << ": " << r.status().to_string();
  return std::move(*r);
}

// With CALF_CONFORMANCE_WRITE=1 a clip that is not committed yet is written (never one that is:
// committed clips are frozen); its .hashes come from calf-verify --decode (README).
TEST(TracksCrafted, GeneratorReproducesTheCommittedClips) {
  const bool write = std::getenv("CALF_CONFORMANCE_WRITE") != nullptr;
  for (const Clip& c : clips()) {
    Expected<Bytes> made = c.make();
    ASSERT_TRUE(made.ok()) << c.name << ": " << made.status().to_string();
    const fs::path path = suite_dir(c.folder) / (c.name + ".calf");
    if (write && !fs::exists(path)) {
      std::ofstream(path, std::ios::binary)
          .write(reinterpret_cast<const char*>(made->data()),
                 static_cast<std::streamsize>(made->size()));
    }
    EXPECT_TRUE(*made == read_file(path)) << c.name << " differs from the generator's bytes";
  }
}

uint32_t u32_at(const Bytes& b, size_t at) {
  return b[at] | uint32_t{b[at + 1]} << 8 | uint32_t{b[at + 2]} << 16 | uint32_t{b[at + 3]} << 24;
}

// Every BC7 mode with every partition (modes 0-3, 7), rotation and index selection (4, 5), and
// the reserved mode, read from the atlas blocks by SPEC §11.1.10's bit layout; bands of 20 rows
// whose last holds 6 (a partial block row) and a 74-texel width (a partial block column).
TEST(TracksCrafted, TilesClipHasEveryBc7ModeAndPartialBlocks) {
  const container::Reader r = open_clip("tiles", "crafted_bc7_multi");
  ASSERT_EQ(r.tracks().size(), 3u);
  std::set<std::pair<int, int>> seen;  // (mode, partition / rotation + 4 index selection)
  std::vector<uint64_t> band_sizes;
  for (uint32_t id = 0; id < r.chunks().size(); ++id) {
    const auto& k = r.chunks()[id].keys;
    if (k.track != 1 || k.stream != 1) continue;
    auto raw = r.read_chunk(id);
    ASSERT_TRUE(raw.ok()) << raw.status().to_string();
    band_sizes.push_back(raw->size());
    add_bc7_shapes(raw->data(), raw->size(), seen);
  }
  EXPECT_EQ(seen.size(), 1u + 16 + 64 * 4 + 8 + 4 + 1);
  // 19 blocks per row: 5, 5, 5 and 2 block rows.
  EXPECT_EQ(band_sizes,
            (std::vector<uint64_t>{16 * 19 * 5, 16 * 19 * 5, 16 * 19 * 5, 16 * 19 * 2}));
}

// Several tracks of a kind, none of them track 0 but the first surfels track; optional chunk
// flags and zstd frames with a content checksum (Frame_Header_Descriptor 0xE4) in every clip.
TEST(TracksCrafted, ClipsHoldWhatTheyAreFor) {
  for (const Clip& c : clips()) {
    const container::Reader r = open_clip(c.folder, c.name);
    int flagged = 0, checksummed = 0;
    for (uint32_t id = 0; id < r.chunks().size(); ++id) {
      const auto& e = r.chunks()[id];
      flagged += e.flags != 0;
      if (e.compression == static_cast<uint16_t>(container::Compression::kZstd)) {
        auto stored = r.read_stored(id);
        ASSERT_TRUE(stored.ok());
        checksummed += (*stored)[4] == 0xE4;
      }
    }
    EXPECT_GT(flagged, 0) << c.name;
    EXPECT_GT(checksummed, 0) << c.name;
  }
  const container::Reader tiles = open_clip("tiles", "crafted_bc7_multi");
  EXPECT_EQ(std::get<container::TilesTrackHeader>(tiles.tracks()[2].header).tile_count, 0u);
  const container::Reader surfels = open_clip("surfels", "crafted_levels_multi");
  ASSERT_EQ(surfels.tracks().size(), 3u);
  EXPECT_EQ(surfels.tracks()[1].record.kind, 4);
  std::set<uint32_t> layers_of_0;
  for (const auto& e : surfels.chunks()) {
    if (e.keys.track == 0 && e.keys.stream == 1 && e.keys.region == 0) {
      layers_of_0.insert(e.keys.layer);
    }
  }
  EXPECT_EQ(layers_of_0, (std::set<uint32_t>{0, 1, 2}));
  const container::Reader mesh = open_clip("mesh", "crafted_layout2_multi");
  ASSERT_EQ(mesh.tracks().size(), 3u);
  for (uint32_t id = 0; id < mesh.chunks().size(); ++id) {
    const auto& k = mesh.chunks()[id].keys;
    if (k.track != 1 || k.stream != 0) continue;
    auto index = mesh.read_chunk(id);
    ASSERT_TRUE(index.ok());
    EXPECT_EQ(u32_at(*index, 0), 2u);  // layout 2
    // The prototypes' flags: every flag on prototype 0; an empty prototype 2.
    const size_t protos = 56 + 4 + 24 * size_t{u32_at(*index, 56)};
    EXPECT_EQ(u32_at(*index, protos + 4 + 8), 15u);
    EXPECT_EQ(u32_at(*index, protos + 4 + 40), 0u);
  }
}

}  // namespace
}  // namespace calf::conformance::tracks_crafted
