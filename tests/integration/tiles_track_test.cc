// The tiles track end to end (format/SPEC.md §11.2): synthetic Seurat-shaped tile sets
// (synthetic_tiles.h) encoded by encode_tiles_track, decoded by TilesTrack and compared with the
// input: tiles and view region bit for bit (the quads are lossless binary32), the atlas exactly
// (rgba8) or within BC7's error (PSNR printed and pinned from both sides); determinism for any
// thread count and supercompression; bad input and damaged chunks give their ids; and the frozen
// conformance clips of tests/conformance/tiles/ still decode to their hashes.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

#include "calf/decoder/tiles_track.h"
#include "calf/decoder/tiles_verify.h"
#include "calf/encoder/tiles_encode.h"
#include "calf/format/container.h"
#include "synthetic_tiles.h"

namespace calf {
namespace {

using container::Compression;
using container::TilesStream;
using decoder::TilesTrack;
using encoder::TilesAtlasFormat;
using encoder::TilesEncodeOptions;

TilesEncodeOptions opts(TilesAtlasFormat f, Compression c = Compression::kZstd,
                        uint32_t threads = 1) {
  TilesEncodeOptions o;
  o.atlas_format = f;
  o.supercompression = c;
  o.threads = threads;
  return o;
}

std::vector<uint8_t> encode(const TileSet& set, const TilesEncodeOptions& options = {},
                            encoder::TilesEncodeStats* stats = nullptr) {
  std::vector<uint8_t> file;
  auto w = container::Writer::create(container::memory_sink(&file), options.levels);
  EXPECT_TRUE(w.ok());
  const Status st = encoder::encode_tiles_track(set, options, &*w, stats);
  EXPECT_TRUE(st.ok()) << st.to_string();
  EXPECT_TRUE(w->finish().ok());
  return file;
}

container::Reader open_reader(const std::vector<uint8_t>& file) {
  auto r = container::Reader::open(container::memory_source(std::span<const uint8_t>(file)));
  EXPECT_TRUE(r.ok()) << r.status().to_string();
  return std::move(*r);
}

double psnr(const std::vector<uint8_t>& a, const std::vector<uint8_t>& b) {
  double se = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    const double d = static_cast<double>(a[i]) - static_cast<double>(b[i]);
    se += d * d;
  }
  return se == 0 ? INFINITY : 10 * std::log10(255.0 * 255.0 * a.size() / se);
}

// Bit-for-bit equality of the tiles and the view region.
void expect_same_tiles(const TileSet& got, const TileSet& want) {
  EXPECT_EQ(got.view_volume, want.view_volume);
  ASSERT_EQ(got.tiles.size(), want.tiles.size());
  for (size_t t = 0; t < want.tiles.size(); ++t) {
    for (int k = 0; k < 4; ++k) {
      for (int c = 0; c < 3; ++c) {
        ASSERT_EQ(std::bit_cast<uint32_t>(got.tiles[t].corners[k].position[c]),
                  std::bit_cast<uint32_t>(want.tiles[t].corners[k].position[c]))
            << "tile " << t << " corner " << k;
        ASSERT_EQ(std::bit_cast<uint32_t>(got.tiles[t].corners[k].uvw[c]),
                  std::bit_cast<uint32_t>(want.tiles[t].corners[k].uvw[c]))
            << "tile " << t << " corner " << k;
      }
    }
  }
}

// 96 tiles of 16 x 16 texels in a 256 x 96 atlas.
TileSet medium_set() {
  return test::make_synthetic_tile_set(4, 16, 256, 11);
}

TEST(TilesTrack, RoundTripBc7WithinItsError) {
  const TileSet set = medium_set();
  ASSERT_EQ(set.tiles.size(), 96u);
  ASSERT_EQ(set.atlas_height, 96u);
  encoder::TilesEncodeStats stats;
  const auto file = encode(set, opts(TilesAtlasFormat::kBc7), &stats);
  const auto reader = open_reader(file);
  ASSERT_EQ(reader.tracks().size(), 1u);
  EXPECT_EQ(reader.tracks()[0].record.flags, container::kTrackRequired);
  auto track = TilesTrack::open(reader, 0);
  ASSERT_TRUE(track.ok()) << track.status().to_string();
  EXPECT_EQ(track->tile_count(), 96u);
  EXPECT_EQ(track->atlas_format(), tiles::kAtlasBc7);
  EXPECT_EQ(track->header().frame_count, 1u);
  TileSet got;
  ASSERT_TRUE(track->decode(&got).ok());
  expect_same_tiles(got, set);
  ASSERT_EQ(got.atlas_width, set.atlas_width);
  ASSERT_EQ(got.atlas_height, set.atlas_height);
  ASSERT_EQ(got.atlas_rgba.size(), set.atlas_rgba.size());
  const double db = psnr(set.atlas_rgba, got.atlas_rgba);
  std::printf(
      "BC7 atlas %ux%u: PSNR %.2f dB (RGBA), %llu stored bytes (%.3f bits per texel); "
      "quads %llu stored bytes (%.2f per tile, 96 raw)\n",
      set.atlas_width, set.atlas_height, db, static_cast<unsigned long long>(stats.atlas_stored),
      8.0 * stats.atlas_stored / (set.atlas_width * set.atlas_height),
      static_cast<unsigned long long>(stats.quads_stored),
      static_cast<double>(stats.quads_stored) / 96);
  EXPECT_NEAR(stats.atlas_psnr_db, db, 1e-9) << "the encoder's figure is what the decoder shows";
  // Two-sided pin (measured 40.24 dB at quality 1, 16 x 16 rectangles on the 4 x 4 block grid):
  // worse means the BC7 coding regressed; much better, tighten the pin.
  EXPECT_GT(db, 39.5);
  EXPECT_LT(db, 44.0);
  EXPECT_EQ(stats.quads_raw, 96u * 96u);
  EXPECT_EQ(stats.atlas_raw, 64u * 24u * 16u);  // 64 x 24 blocks of 16 bytes
  EXPECT_EQ(stats.atlas_bands, 1u);
  // The payload is the BC7 blocks; decode_tiles_track is open + decode.
  std::vector<uint8_t> payload;
  ASSERT_TRUE(track->atlas_payload(&payload).ok());
  EXPECT_EQ(payload.size(), stats.atlas_raw);
  auto again = decoder::decode_tiles_track(reader, 0);
  ASSERT_TRUE(again.ok());
  EXPECT_EQ(again->atlas_rgba, got.atlas_rgba);
  EXPECT_EQ(TilesTrack::open(reader, 1).status().id(), ErrorId::kInvalidArgument);
}

TEST(TilesTrack, RoundTripRgba8IsExactAcrossBands) {
  const TileSet set = test::make_synthetic_tile_set(2, 10, 62, 3);  // 62 x 40: 3 bands of 16
  ASSERT_EQ(set.atlas_height, 40u);
  TilesEncodeOptions o = opts(TilesAtlasFormat::kRgba8, Compression::kNone);
  o.band_rows = 16;
  encoder::TilesEncodeStats stats;
  const auto file = encode(set, o, &stats);
  EXPECT_EQ(stats.atlas_bands, 3u);
  EXPECT_TRUE(std::isinf(stats.atlas_psnr_db));
  const auto reader = open_reader(file);
  auto got = decoder::decode_tiles_track(reader, 0);
  ASSERT_TRUE(got.ok()) << got.status().to_string();
  expect_same_tiles(*got, set);
  EXPECT_EQ(got->atlas_rgba, set.atlas_rgba);
  // BC7 with the same bands (a partial block column at x = 60 and a last band of 8 rows). The
  // 10 x 10 rectangles straddle blocks, so a block mixes two tiles' colours and edges: measured
  // 35.46 dB (16 x 16 rectangles on the block grid: 40.2 dB above; Seurat sizes its textures in
  // whole blocks for this reason).
  o.atlas_format = TilesAtlasFormat::kBc7;
  const auto bc7 = encode(set, o);
  const auto r2 = open_reader(bc7);
  auto got7 = decoder::decode_tiles_track(r2, 0);
  ASSERT_TRUE(got7.ok()) << got7.status().to_string();
  const double db = psnr(set.atlas_rgba, got7->atlas_rgba);
  std::printf("BC7 atlas 62x40, 10 x 10 rectangles: PSNR %.2f dB\n", db);
  EXPECT_GT(db, 35.0);
  EXPECT_LT(db, 39.0);
}

TEST(TilesTrack, DeterministicForThreadsAndSchemes) {
  const TileSet set = medium_set();
  for (TilesAtlasFormat f : {TilesAtlasFormat::kBc7, TilesAtlasFormat::kRgba8}) {
    TilesEncodeOptions one = opts(f, Compression::kZstd, 1), four = opts(f, Compression::kZstd, 4);
    one.band_rows = four.band_rows = 32;
    EXPECT_EQ(encode(set, one), encode(set, four));
    std::vector<std::string> first;
    for (Compression c : {Compression::kZstd, Compression::kLzma2, Compression::kNone}) {
      const auto file = encode(set, opts(f, c, 0));
      const auto reader = open_reader(file);
      const auto r = decoder::verify_tiles_track(reader, 0, true, 10);
      ASSERT_TRUE(r.problems.empty()) << r.problems[0].to_string();
      ASSERT_EQ(r.hash_lines.size(), 2u);
      EXPECT_EQ(r.tiles_decoded, 96u);
      if (first.empty()) {
        first = r.hash_lines;
      } else {
        EXPECT_EQ(r.hash_lines, first);
      }
    }
  }
  // Re-encoding decoded rgba8 tiles gives the same bytes.
  const auto file = encode(set, opts(TilesAtlasFormat::kRgba8));
  const auto reader = open_reader(file);
  auto got = decoder::decode_tiles_track(reader, 0);
  ASSERT_TRUE(got.ok());
  EXPECT_EQ(encode(*got, opts(TilesAtlasFormat::kRgba8)), file);
}

TEST(TilesTrack, BadInputIsRefused) {
  const TileSet good = test::make_synthetic_tile_set(1, 8, 32, 5);
  EXPECT_TRUE(encoder::validate_tile_set(good).ok());
  std::vector<std::pair<const char*, std::function<void(TileSet&)>>> cases = {
      {"atlas short", [](auto& s) { s.atlas_rgba.pop_back(); }},
      {"atlas width 0", [](auto& s) { s.atlas_width = 0; }},
      {"atlas height 16385", [](auto& s) { s.atlas_height = 16385; }},
      {"colour above alpha", [](auto& s) { s.atlas_rgba[0] = 10, s.atlas_rgba[3] = 9; }},
      {"NaN position", [](auto& s) { s.tiles[2].corners[1].position[0] = NAN; }},
      {"far position", [](auto& s) { s.tiles[2].corners[1].position[2] = 2e12f; }},
      {"W zero", [](auto& s) { s.tiles[0].corners[3].uvw[2] = 0; }},
      {"W negative", [](auto& s) { s.tiles[0].corners[3].uvw[2] = -1; }},
      {"W infinite",
       [](auto& s) {
         s.tiles[0].corners[3].uvw = {0, 0, INFINITY};
       }},
      {"U above W",
       [](auto& s) { s.tiles[4].corners[0].uvw[0] = 2 * s.tiles[4].corners[0].uvw[2]; }},
      {"V negative", [](auto& s) { s.tiles[4].corners[0].uvw[1] = -1e-9f; }},
      {"U NaN", [](auto& s) { s.tiles[4].corners[0].uvw[0] = NAN; }},
      {"view region inverted", [](auto& s) { s.view_volume.min.x = 1; }},
      {"view region NaN", [](auto& s) { s.view_volume.max.z = NAN; }},
  };
  for (const auto& [name, edit] : cases) {
    TileSet bad = good;
    edit(bad);
    std::vector<uint8_t> file;
    auto w = container::Writer::create(container::memory_sink(&file));
    ASSERT_TRUE(w.ok());
    const Status st = encoder::encode_tiles_track(bad, {}, &*w);
    EXPECT_EQ(st.id(), ErrorId::kTilesInput) << name << ": " << st.to_string();
    ASSERT_TRUE(w->finish().ok());
    EXPECT_TRUE(open_reader(file).tracks().empty()) << name << ": nothing written";
  }
  const auto option = [&](std::function<void(TilesEncodeOptions&)> edit) {
    TilesEncodeOptions o;
    edit(o);
    std::vector<uint8_t> file;
    auto w = container::Writer::create(container::memory_sink(&file));
    return encoder::encode_tiles_track(good, o, &*w).id();
  };
  EXPECT_EQ(option([](auto& o) { o.threads = 300; }), ErrorId::kEncoderOption);
  EXPECT_EQ(option([](auto& o) { o.bc7_quality = 3; }), ErrorId::kEncoderOption);
  EXPECT_EQ(option([](auto& o) { o.band_rows = 6; }), ErrorId::kEncoderOption);
  EXPECT_EQ(option([](auto& o) { o.band_rows = 0; }), ErrorId::kEncoderOption);
  EXPECT_EQ(option([](auto& o) { o.band_rows = 16388; }), ErrorId::kEncoderOption);
  EXPECT_EQ(option([](auto& o) { o.supercompression = Compression(7); }), ErrorId::kEncoderOption);
}

// ---- Damaged chunks: the file is rebuilt with valid hashes, so the track's parser sees them ----

struct Edit {
  std::function<void(const container::ChunkKeys&, std::vector<uint8_t>&, bool& drop)> chunk;
  std::function<void(container::TilesTrackHeader&)> header;
  std::function<void(container::ChunkKeys&)> keys;
  bool duplicate_last = false;
};

std::vector<uint8_t> rebuild(const std::vector<uint8_t>& file, const Edit& edit) {
  const auto reader = open_reader(file);
  std::vector<uint8_t> out;
  auto w = container::Writer::create(container::memory_sink(&out));
  EXPECT_TRUE(w.ok());
  auto h = std::get<container::TilesTrackHeader>(reader.tracks()[0].header);
  if (edit.header) edit.header(h);
  EXPECT_TRUE(w->add_track(h).ok());
  std::vector<uint8_t> last;
  container::ChunkKeys last_keys;
  for (uint32_t id = 0; id < reader.chunks().size(); ++id) {
    auto raw = reader.read_chunk(id);
    EXPECT_TRUE(raw.ok());
    container::ChunkKeys keys = reader.chunks()[id].keys;
    bool drop = false;
    if (edit.chunk) edit.chunk(keys, *raw, drop);
    if (edit.keys) edit.keys(keys);
    if (drop) continue;
    EXPECT_TRUE(w->add_chunk(keys, *raw, Compression::kNone).ok());
    last = *raw;
    last_keys = keys;
  }
  if (edit.duplicate_last) {
    EXPECT_TRUE(w->add_chunk(last_keys, last, Compression::kNone).ok());
  }
  EXPECT_TRUE(w->finish().ok());
  return out;
}

// The first problem of verifying the damaged file's tiles track (open's, then decoding's).
Status damage(const std::vector<uint8_t>& file) {
  const auto reader = open_reader(file);
  const auto r = decoder::verify_tiles_track(reader, 0, false, 10);
  return r.problems.empty() ? Status::Ok() : r.problems[0];
}

bool is(const container::ChunkKeys& k, TilesStream s, uint32_t region = 0) {
  return k.stream == static_cast<uint16_t>(s) && k.region == region;
}

void put32(std::vector<uint8_t>& r, size_t at, uint32_t v) {
  for (int i = 0; i < 4; ++i) r[at + i] = static_cast<uint8_t>(v >> (8 * i));
}

TEST(TilesTrack, DamagedChunksGiveTheTrackIds) {
  const TileSet set = test::make_synthetic_tile_set(1, 8, 32, 9);  // 6 tiles, 32 x 16
  TilesEncodeOptions o = opts(TilesAtlasFormat::kBc7);
  o.band_rows = 8;  // 2 bands
  const auto good = encode(set, o);
  ASSERT_TRUE(damage(rebuild(good, {})).ok()) << "rebuilding alone changes nothing";
  const auto on = [](TilesStream s, uint32_t region, std::function<void(std::vector<uint8_t>&)> f) {
    Edit e;
    e.chunk = [=](const container::ChunkKeys& k, std::vector<uint8_t>& raw, bool&) {
      if (is(k, s, region)) f(raw);
    };
    return e;
  };
  const auto index = [&](std::function<void(std::vector<uint8_t>&)> f) {
    return on(TilesStream::kIndex, 0, f);
  };
  // The quads chunk's planes: 24 words per tile, 6 tiles: byte plane b of word w of tile t at
  // b * 144 + w * 6 + t. Corner 0's W of tile 2 (word 5) predicted by tile 1's: set its high
  // byte so W becomes negative or huge.
  const size_t n = 6, words = 24 * n;
  struct Case {
    const char* name;
    Edit edit;
    ErrorId id;
    const char* says;
  };
  std::vector<Case> cases = {
      {"layout version 2", index([](auto& r) { r[0] = 2; }), ErrorId::kTilesUnsupported,
       "layout version 2"},
      {"index flags", index([](auto& r) { r[4] = 1; }), ErrorId::kTilesUnsupported, "flags"},
      {"index truncated", index([](auto& r) { r.pop_back(); }), ErrorId::kTilesChunk, "band_rows"},
      {"index trailing byte", index([](auto& r) { r.push_back(0); }), ErrorId::kTilesChunk,
       "after the fields"},
      {"view region NaN", index([](auto& r) { put32(r, 8 + 4, 0x7ff80000u); }),
       ErrorId::kTilesValue, "view_min"},
      {"view region inverted", index([](auto& r) { put32(r, 8 + 4, 0x40590000u); }),  // 100
       ErrorId::kTilesValue, "view region axis 0"},
      {"band rows 6", index([](auto& r) { put32(r, 56, 6); }), ErrorId::kTilesValue,
       "multiple of 4"},
      {"band rows 0", index([](auto& r) { put32(r, 56, 0); }), ErrorId::kTilesValue, "band_rows"},
      {"band rows 2^20", index([](auto& r) { put32(r, 56, 1u << 20); }), ErrorId::kTilesLimit,
       "band_rows"},
      {"band rows 16: one band fewer", index([](auto& r) { put32(r, 56, 16); }),
       ErrorId::kTilesChunk, "band 1 of 1"},
      {"quads short", on(TilesStream::kQuads, 0, [](auto& r) { r.pop_back(); }),
       ErrorId::kTilesChunk, "quads chunk"},
      {"W negative", on(TilesStream::kQuads, 0, [&](auto& r) { r[3 * words + 5 * n + 2] ^= 0x80; }),
       ErrorId::kTilesValue, "tile 2 corner 0 W"},
      // Tile 0's corner 0 is predicted by 0: its residual is the float itself.
      {"position NaN",
       on(TilesStream::kQuads, 0,
          [&](auto& r) {
            for (size_t b = 0; b < 4; ++b) r[b * words] = b == 3 ? 0x7f : 0xff;
          }),
       ErrorId::kTilesValue, "tile 0 corner 0 x"},
      {"band short", on(TilesStream::kAtlas, 1, [](auto& r) { r.resize(r.size() - 16); }),
       ErrorId::kTilesChunk, "atlas band 1"},
  };
  const auto drop = [](TilesStream s, uint32_t region) {
    Edit e;
    e.chunk = [=](const container::ChunkKeys& k, std::vector<uint8_t>&, bool& d) {
      d = is(k, s, region);
    };
    return e;
  };
  cases.push_back(
      {"band missing", drop(TilesStream::kAtlas, 0), ErrorId::kTilesChunk, "no atlas band 0"});
  cases.push_back(
      {"quads missing", drop(TilesStream::kQuads, 0), ErrorId::kTilesChunk, "0 quads chunks"});
  cases.push_back({"index missing", drop(TilesStream::kIndex, 0), ErrorId::kOk, ""});
  Edit twice;
  twice.duplicate_last = true;
  cases.push_back({"band twice", twice, ErrorId::kTilesChunk, "both atlas band 1"});
  const auto rekey = [](std::function<void(container::ChunkKeys&)> f) {
    Edit e;
    e.keys = f;
    return e;
  };
  cases.push_back({"band beyond the atlas", rekey([](auto& k) {
                     if (k.stream == 1 && k.region == 1) k.region = 2;
                   }),
                   ErrorId::kTilesChunk, "band 2 of 2"});
  cases.push_back({"quads with a region", rekey([](auto& k) {
                     if (k.stream == 2) k.region = 1;
                   }),
                   ErrorId::kTilesChunk, "(quads)"});
  cases.push_back({"layer set", rekey([](auto& k) {
                     if (k.stream == 1) k.layer = 1;
                   }),
                   ErrorId::kTilesChunk, "(atlas)"});
  const auto header = [](std::function<void(container::TilesTrackHeader&)> f) {
    Edit e;
    e.header = f;
    return e;
  };
  cases.push_back({"two frames", header([](auto& h) { h.frame_count = 2; }),
                   ErrorId::kTilesUnsupported, "frame_count 2"});
  cases.push_back({"atlas format BC1", header([](auto& h) { h.atlas_format = 4; }),
                   ErrorId::kTilesUnsupported, "atlas_format 4"});
  cases.push_back({"header flag", header([](auto& h) { h.flags = 2; }), ErrorId::kTilesUnsupported,
                   "reserved flags"});
  cases.push_back({"tile count + 1", header([](auto& h) { h.tile_count += 1; }),
                   ErrorId::kTilesChunk, "7 tiles need 672"});
  cases.push_back({"tile count above 2^22", header([](auto& h) { h.tile_count = (1u << 22) + 1; }),
                   ErrorId::kTilesLimit, "tile_count"});
  cases.push_back({"atlas wider", header([](auto& h) { h.atlas_width += 4; }), ErrorId::kTilesChunk,
                   "atlas band 0"});
  cases.push_back({"rgba8 over BC7 bytes", header([](auto& h) { h.atlas_format = 1; }),
                   ErrorId::kTilesChunk, "atlas band 0"});
  for (const Case& c : cases) {
    const Status st = damage(rebuild(good, c.edit));
    EXPECT_EQ(st.id(), c.id) << c.name << ": " << st.to_string();
    EXPECT_NE(st.message().find(c.says), std::string::npos) << c.name << ": " << st.to_string();
  }
  // Damaged stored bytes (the container's hash) name the chunk of the track.
  std::vector<uint8_t> flipped = encode(set, opts(TilesAtlasFormat::kBc7, Compression::kNone));
  {
    const auto reader = open_reader(flipped);
    container::ChunkQuery q;
    q.track = 0;
    q.stream = static_cast<uint16_t>(TilesStream::kQuads);
    const auto ids = reader.find_chunks(q);
    ASSERT_EQ(ids.size(), 1u);
    flipped[reader.chunks()[ids[0]].offset + 7] ^= 1;
  }
  const Status st = damage(flipped);
  EXPECT_EQ(st.id(), ErrorId::kContainerChunkHash) << st.to_string();
  EXPECT_NE(st.to_string().find("tiles quads chunk"), std::string::npos) << st.to_string();
  // A truncated file does not open (the container's error).
  flipped.resize(flipped.size() - 40);
  EXPECT_EQ(container::Reader::open(container::memory_source(std::span<const uint8_t>(flipped)))
                .status()
                .id(),
            ErrorId::kContainerTruncated);
}

// ---- The frozen conformance clips (tests/conformance/tiles/) ----

std::string source_path(const std::string& rel) {
  const char* root = std::getenv("CALF_SOURCE_DIR");
  return std::string(root ? root : ".") + "/" + rel;
}

std::vector<uint8_t> read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

struct Clip {
  const char* name;
  TilesAtlasFormat format;
  Compression compression;
};
constexpr Clip kClips[] = {{"bc7_zstd", TilesAtlasFormat::kBc7, Compression::kZstd},
                           {"bc7_lzma2", TilesAtlasFormat::kBc7, Compression::kLzma2},
                           {"rgba8_none", TilesAtlasFormat::kRgba8, Compression::kNone}};

// 24 tiles of 10 x 10 texels in a 62 x 40 atlas, cut in bands of 16 rows (the last of 8; a
// partial BC7 block column).
TileSet clip_set() {
  return test::make_synthetic_tile_set(2, 10, 62, 2018);
}

// The frozen clips are container 1.0 files: a plain directory (SPEC §4.1 is 1.1).
std::vector<uint8_t> make_clip(const Clip& c) {
  TilesEncodeOptions o = opts(c.format, c.compression);
  o.band_rows = 16;
  o.levels.compress_directory = false;
  return encode(clip_set(), o);
}

// The generator (tests/conformance/README.md): with CALF_CONFORMANCE_OUT=DIR it writes the clips
// there; the committed copies are never regenerated for a new version.
TEST(TilesConformance, Generator) {
  const char* out = std::getenv("CALF_CONFORMANCE_OUT");
  if (!out) GTEST_SKIP() << "set CALF_CONFORMANCE_OUT to write the clips";
  auto write = [](const std::string& path, const std::vector<uint8_t>& bytes) {
    std::ofstream f(path, std::ios::binary);
    f.write(reinterpret_cast<const char*>(bytes.data()),
            static_cast<std::streamsize>(bytes.size()));
    ASSERT_TRUE(f.good()) << path;
  };
  for (const Clip& c : kClips) write(std::string(out) + "/" + c.name + ".calf", make_clip(c));
  // Fuzz seeds (tests/fuzz/corpus/tiles_track_fuzz/): a small clip stored, and damaged copies
  // with valid hashes, so that mutations reach the track's parsers.
  const std::string fuzz = std::string(out) + "/fuzz";
  std::filesystem::create_directories(fuzz);
  const TileSet small = test::make_synthetic_tile_set(1, 4, 12, 7);  // 6 tiles, 12 x 8
  TilesEncodeOptions o = opts(TilesAtlasFormat::kBc7, Compression::kNone);
  o.band_rows = 4;
  const auto valid = encode(small, o);
  write(fuzz + "/valid_bc7_none.calf", valid);
  o.atlas_format = TilesAtlasFormat::kRgba8;
  write(fuzz + "/valid_rgba8_none.calf", encode(small, o));
  const auto damaged = [&](const char* name, TilesStream stream, size_t at, uint8_t value) {
    Edit e;
    e.chunk = [=](const container::ChunkKeys& k, std::vector<uint8_t>& raw, bool&) {
      if (is(k, stream) && at < raw.size()) raw[at] = value;
    };
    write(fuzz + "/" + name + ".calf", rebuild(valid, e));
  };
  damaged("bad_index_version", TilesStream::kIndex, 0, 2);
  damaged("bad_band_rows", TilesStream::kIndex, 56, 6);
  damaged("bad_view_region", TilesStream::kIndex, 15, 0xff);
  damaged("bad_quad_w", TilesStream::kQuads, 3 * 144 + 5 * 6 + 1, 0x80);
}

// The runner: each committed clip decodes to its hashes and to the tile set it was made from
// (tiles exactly, the atlas exactly or within BC7's error), and today's encoder still writes its
// bytes.
TEST(TilesConformance, CommittedClipsDecodeToTheirHashes) {
  const TileSet set = clip_set();
  for (const Clip& c : kClips) {
    SCOPED_TRACE(c.name);
    const auto bytes =
        read_bytes(source_path(std::string("tests/conformance/tiles/") + c.name + ".calf"));
    ASSERT_FALSE(bytes.empty());
    const auto reader = open_reader(bytes);
    auto got = decoder::decode_tiles_track(reader, 0);
    ASSERT_TRUE(got.ok()) << got.status().to_string();
    expect_same_tiles(*got, set);
    if (c.format == TilesAtlasFormat::kRgba8) {
      EXPECT_EQ(got->atlas_rgba, set.atlas_rgba);
    } else {
      EXPECT_GT(psnr(set.atlas_rgba, got->atlas_rgba), 35.0);
    }
    const auto result = decoder::verify_tiles_track(reader, 0, true, 10);
    std::ostringstream lines;
    for (const auto& l : result.hash_lines) lines << l << "\n";
    const auto want =
        read_bytes(source_path(std::string("tests/conformance/tiles/") + c.name + ".hashes"));
    EXPECT_EQ(lines.str(), std::string(want.begin(), want.end()));
    EXPECT_EQ(make_clip(c), bytes);
  }
}

}  // namespace
}  // namespace calf
