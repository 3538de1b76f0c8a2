// The crafted lightfield conformance clips (tests/conformance/lightfield/crafted_*, format/SPEC.md
// §14): the committed files are what the generator (tests/conformance/lightfield_crafted.h)
// derives; they hold what the issue lists (every BC7 / BC6H mode and partition, edge regions and
// partial blocks, material P-frames, interpolated BC1 / BC7 frames, track 1, chunk flags, zstd
// checksums, a dropped view), counted here from the bytes by the SPEC's bit layout; and the BC1
// clip's decoded colour equals an independent decoding written from SPEC §11.1.4, §11.1.5 and
// §11.1.10 in this file, with two blocks' values written out by hand. Both of calf's decoders
// reproduce the hashes in tests/integration/lightfield_conformance_test.cc.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>
#include <string>
#include <vector>

#include "../conformance/block_census.h"
#include "../conformance/lightfield_crafted.h"
#include "calf/decoder/lightfield_reference.h"
#include "calf/format/container.h"
#include "calf/format/grid.h"
#include "calf/format/lightfield_layout.h"

namespace calf::conformance::crafted {
namespace {

namespace fs = std::filesystem;
using container::LightfieldStream;

fs::path suite_dir() {
  const char* root = std::getenv("CALF_SOURCE_DIR");
  return fs::path(root ? root : ".") / "tests" / "conformance" / "lightfield";
}

Bytes read_file(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

container::Reader open_clip(const std::string& name) {
  auto r = container::Reader::open((suite_dir() / (name + ".calf")).string());
  EXPECT_TRUE(r.ok()) << name << ": " << r.status().to_string();
  return std::move(*r);
}

uint16_t lightfield_track(const container::Reader& r) {
  for (const auto& t : r.tracks()) {
    if (std::holds_alternative<container::LightfieldTrackHeader>(t.header)) return t.id;
  }
  return 0;
}

// With CALF_CONFORMANCE_WRITE=1 a clip that is not committed yet is written (never one that is:
// committed clips are frozen); its .hashes come from calf-verify --decode (README).
TEST(LightfieldCrafted, GeneratorReproducesTheCommittedClips) {
  const bool write = std::getenv("CALF_CONFORMANCE_WRITE") != nullptr;
  for (const ClipSpec& s : clip_specs()) {
    Expected<Bytes> made = make_clip(s);
    ASSERT_TRUE(made.ok()) << s.name << ": " << made.status().to_string();
    const fs::path path = suite_dir() / (s.name + ".calf");
    if (write && !fs::exists(path)) {
      std::ofstream(path, std::ios::binary)
          .write(reinterpret_cast<const char*>(made->data()),
                 static_cast<std::streamsize>(made->size()));
    }
    EXPECT_TRUE(*made == read_file(path)) << s.name << " differs from the generator's bytes";
  }
}

// Reads the lightfield track's chunks of `stream`, raw.
std::vector<std::pair<container::ChunkKeys, Bytes>> chunks_of(const container::Reader& r,
                                                              LightfieldStream stream) {
  std::vector<std::pair<container::ChunkKeys, Bytes>> out;
  const uint16_t track = lightfield_track(r);
  for (uint32_t id = 0; id < r.chunks().size(); ++id) {
    const auto& k = r.chunks()[id].keys;
    if (k.track != track || k.stream != static_cast<uint16_t>(stream)) continue;
    auto raw = r.read_chunk(id);
    EXPECT_TRUE(raw.ok()) << raw.status().to_string();
    if (raw.ok()) out.emplace_back(k, std::move(*raw));
  }
  return out;
}

// Every BC7 mode with every partition (modes 0-3, 7), rotation and index selection (4, 5), and
// the reserved mode, read from the blocks by SPEC §11.1.10's bit layout.
TEST(LightfieldCrafted, Bc7ClipHasEveryModeAndPartition) {
  const container::Reader r = open_clip("crafted_bc7_raw16_mat");
  std::set<std::pair<int, int>> seen;  // (mode, partition / rotation + 4 index selection)
  for (const auto& [k, raw] : chunks_of(r, LightfieldStream::kColour)) {
    add_bc7_shapes(raw.data(), raw.size(), seen);
  }
  EXPECT_EQ(seen.size(), 1u + 16 + 64 * 4 + 8 + 4 + 1);
}

TEST(LightfieldCrafted, Bc6hClipHasEveryModeAndPartition) {
  const container::Reader r = open_clip("crafted_bc6h_bc5_mat");
  std::set<std::pair<int, int>> seen;  // (mode value, partition)
  for (const auto& [k, raw] : chunks_of(r, LightfieldStream::kColour)) {
    for (size_t b = 0; b + 16 <= raw.size(); b += 16) {
      const uint8_t* block = &raw[b];
      const int value = (block[0] & 3) < 2 ? block[0] & 3 : block[0] & 31;
      // Two-region modes: the 2-bit ones and the 5-bit values 2 ... 30 ending in binary 10.
      const bool one_region = value == 3 || value == 7 || value == 11 || value == 15;
      const bool reserved = value == 19 || value == 23 || value == 27 || value == 31;
      seen.insert({value, one_region || reserved ? 0 : static_cast<int>(block_bits(block, 77, 5))});
    }
  }
  EXPECT_EQ(seen.size(), 10u * 32 + 4 + 4);
}

// Edge regions and partial blocks, material P-frame rectangles, interpolated frames, track 1,
// optional chunk flags, zstd frames with a content checksum, a dropped view, a view without
// material in a track with material.
TEST(LightfieldCrafted, ClipsHoldWhatTheyAreFor) {
  for (const ClipSpec& s : clip_specs()) {
    const container::Reader r = open_clip(s.name);
    const auto& h =
        std::get<container::LightfieldTrackHeader>(r.tracks()[lightfield_track(r)].header);
    EXPECT_NE(h.face_size % h.cell_size, 0u) << s.name;
    EXPECT_NE(h.face_size % h.depth_region_size, 0u) << s.name;
    EXPECT_NE(h.face_size % 4, 0u) << s.name;
    size_t interpolated = 0;
    for (const auto& [k, raw] : chunks_of(r, LightfieldStream::kTParams)) {
      auto tl = lf::parse_t_chunk(raw, k.frame_count, s.name);
      ASSERT_TRUE(tl.ok());
      for (uint32_t f = 0; f < k.frame_count; ++f) {
        interpolated += tl->t[f] > 0 && tl->t[f] < 255 && tl->bracket(f) + 1 < tl->keyframes.size();
      }
    }
    EXPECT_GT(interpolated, 0u) << s.name;
    if (s.material_format != 0) {
      size_t p_rects = 0, views_with = 0, views_without = 0;
      for (const auto& [k, raw] : chunks_of(r, LightfieldStream::kMaterial)) {
        for (uint32_t i = 1; i < k.frame_count; ++i) p_rects += raw[4 + 4 * i];  // R_i < 256
      }
      for (const auto& [k, raw] : chunks_of(r, LightfieldStream::kIndex)) {
        ((raw[36] & 2) ? views_with : views_without) += 1;
      }
      EXPECT_GT(p_rects, 0u) << s.name;
      EXPECT_GT(views_with, 0u) << s.name;
      EXPECT_GT(views_without, 0u) << s.name;
    }
    if (s.chunk_flags_and_checksums) {
      EXPECT_EQ(lightfield_track(r), 1u);
      size_t flagged = 0, checksummed = 0;
      for (uint32_t id = 0; id < r.chunks().size(); ++id) {
        flagged += r.chunks()[id].flags != 0;
        if (r.chunks()[id].compression == static_cast<uint16_t>(container::Compression::kZstd)) {
          auto stored = r.read_stored(id);
          ASSERT_TRUE(stored.ok());
          checksummed += ((*stored)[4] & 4) != 0;  // Content_Checksum_flag
        }
      }
      EXPECT_GT(flagged, 0u);
      EXPECT_GT(checksummed, 0u);
    }
    if (s.dropped_view >= 0) {
      EXPECT_EQ(chunks_of(r, LightfieldStream::kIndex).size(), h.view_count - 1);
    }
  }
}

// The dropped-view clip is its twin without view 1's index chunk: its .hashes are the twin's
// lines of the other views, and the reference decoder reports the view (CALF-E202).
TEST(LightfieldCrafted, DroppedViewClipDecodesTheOtherViewsAsItsTwin) {
  std::ifstream twin(suite_dir() / "crafted_bc1_raw16.hashes");
  std::string want;
  for (std::string line; std::getline(twin, line);) {
    if (line.find(" view 1 ") == std::string::npos) want += line + "\n";
  }
  const Bytes mine = read_file(suite_dir() / "crafted_bc1_dropped_view.hashes");
  EXPECT_EQ(std::string(mine.begin(), mine.end()), want);
  const container::Reader r = open_clip("crafted_bc1_dropped_view");
  auto ref = decoder::LightfieldReference::open(r, 0);
  ASSERT_TRUE(ref.ok());
  EXPECT_TRUE(ref->view_problem(0).ok());
  EXPECT_EQ(ref->view_problem(1).id(), ErrorId::kLightfieldChunk);
}

// ---- An independent decoding of BC1 colour, from the SPEC's formulas ----

// §11.1.10 BC1: R, G, B bytes of the 16 texels of one block.
void bc1_by_the_spec(const uint8_t* endpoints, const uint8_t* indices, uint8_t out[16][3]) {
  const uint32_t c[2] = {uint32_t{endpoints[0]} | uint32_t{endpoints[1]} << 8,
                         uint32_t{endpoints[2]} | uint32_t{endpoints[3]} << 8};
  int p[4][3];
  for (int e = 0; e < 2; ++e) {
    const int r5 = (c[e] >> 11) & 31, g6 = (c[e] >> 5) & 63, b5 = c[e] & 31;
    p[e][0] = (r5 << 3) | (r5 >> 2);
    p[e][1] = (g6 << 2) | (g6 >> 4);
    p[e][2] = (b5 << 3) | (b5 >> 2);
  }
  for (int ch = 0; ch < 3; ++ch) {
    if (c[0] > c[1]) {
      p[2][ch] = (2 * p[0][ch] + p[1][ch]) / 3;
      p[3][ch] = (p[0][ch] + 2 * p[1][ch]) / 3;
    } else {
      p[2][ch] = (p[0][ch] + p[1][ch]) / 2;
      p[3][ch] = 0;
    }
  }
  const uint32_t word = uint32_t{indices[0]} | uint32_t{indices[1]} << 8 |
                        uint32_t{indices[2]} << 16 | uint32_t{indices[3]} << 24;
  for (int k = 0; k < 16; ++k) {
    for (int ch = 0; ch < 3; ++ch) out[k][ch] = static_cast<uint8_t>(p[(word >> (2 * k)) & 3][ch]);
  }
}

// §11.1.5 / §14: the sRGB curve in binary64, rounded once.
float srgb(uint8_t byte) {
  const double c = byte / 255.0;
  return static_cast<float>(c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4));
}

// A w x h BC1 cell payload (block split) as linear RGB, texel-interleaved.
std::vector<float> cell_by_the_spec(const Bytes& payload, uint32_t w, uint32_t h) {
  const uint32_t bw = (w + 3) / 4, bh = (h + 3) / 4, blocks = bw * bh;
  std::vector<float> rgb(size_t{w} * h * 3);
  for (uint32_t b = 0; b < blocks; ++b) {
    uint8_t texels[16][3];
    bc1_by_the_spec(&payload[4 * b], &payload[4 * blocks + 4 * b], texels);
    for (uint32_t k = 0; k < 16; ++k) {
      const uint32_t x = 4 * (b % bw) + k % 4, y = 4 * (b / bw) + k / 4;
      if (x >= w || y >= h) continue;  // outside an edge block
      for (int ch = 0; ch < 3; ++ch) rgb[(size_t{y} * w + x) * 3 + ch] = srgb(texels[k][ch]);
    }
  }
  return rgb;
}

// §11.1.4, one operation at a time: volatile keeps each rounded to binary32 and unfused.
float interpolate(float a, float b, uint8_t t) {
  volatile float w = static_cast<float>(t) / 255.0f;
  volatile float u = 1.0f - w;
  volatile float p = u * a;
  volatile float q = w * b;
  volatile float sum = p + q;
  return sum;
}

TEST(LightfieldCrafted, Bc1ColourMatchesTheSpecFormulas) {
  const container::Reader r = open_clip("crafted_bc1_raw16");
  auto ref = decoder::LightfieldReference::open(r, 0);
  ASSERT_TRUE(ref.ok());
  const auto& h = ref->header();
  auto cells = FaceGrid::with_cell_size(h.face_size, h.cell_size);
  ASSERT_TRUE(cells.ok());
  const auto colour = chunks_of(r, LightfieldStream::kColour);
  const auto tchunks = chunks_of(r, LightfieldStream::kTParams);
  auto find = [](const auto& list, uint32_t v, uint32_t f, uint32_t c, uint32_t first) {
    for (const auto& [k, raw] : list) {
      if (k.view == v && k.face == f && k.region == c && k.first_frame == first) return &raw;
    }
    return static_cast<const Bytes*>(nullptr);
  };
  size_t checked = 0, mixed = 0;
  for (uint32_t frame = 0; frame < h.frame_count; ++frame) {
    for (uint32_t v = 0; v < h.view_count; ++v) {
      for (uint32_t f = 0; f < 6; ++f) {
        decoder::LightfieldFace face;
        ASSERT_TRUE(ref->decode_face(v, f, frame, &face).ok());
        for (uint32_t c = 0; c < cells->cell_count(); ++c) {
          auto rect = cells->cell_rect(c);
          ASSERT_TRUE(rect.ok());
          const Bytes* traw = find(tchunks, v, f, c, 0);
          ASSERT_NE(traw, nullptr);
          auto tl = lf::parse_t_chunk(*traw, h.frame_count, "t");
          ASSERT_TRUE(tl.ok());
          const uint32_t m = tl->bracket(frame);
          const Bytes* a_raw = find(colour, v, f, c, tl->keyframes[m]);
          ASSERT_NE(a_raw, nullptr);
          std::vector<float> want = cell_by_the_spec(*a_raw, rect->width, rect->height);
          if (m + 1 < tl->keyframes.size() && tl->t[frame] != 0) {
            const Bytes* b_raw = find(colour, v, f, c, tl->keyframes[m + 1]);
            ASSERT_NE(b_raw, nullptr);
            const std::vector<float> b = cell_by_the_spec(*b_raw, rect->width, rect->height);
            for (size_t i = 0; i < want.size(); ++i)
              want[i] = interpolate(want[i], b[i], tl->t[frame]);
            ++mixed;
          }
          for (uint32_t y = 0; y < rect->height; ++y) {
            for (uint32_t x = 0; x < rect->width * 3; ++x) {
              const float got = face.colour[(size_t{rect->y + y} * h.face_size + rect->x) * 3 + x];
              const float exp = want[size_t{y} * rect->width * 3 + x];
              ASSERT_EQ(std::bit_cast<uint32_t>(got), std::bit_cast<uint32_t>(exp))
                  << "view " << v << " face " << f << " frame " << frame << " cell " << c;
              ++checked;
            }
          }
        }
        if (frame == 0 && v == 0 && f == 0) {
          // SPEC §11.1.10's example blocks, the first two of the clip, by hand: row 0's R bytes
          // 255, 8, 172 (not 173), 90, then the 3-colour block's 0 (index 3) and 131.
          const uint8_t by_hand[6] = {255, 8, 172, 90, 0, 131};
          for (int x = 0; x < 6; ++x) {
            EXPECT_EQ(std::bit_cast<uint32_t>(face.colour[3 * x]),
                      std::bit_cast<uint32_t>(srgb(by_hand[x])))
                << x;
          }
          EXPECT_EQ(face.colour[3 * 4 + 1], 0.0f);  // index 3: G and B 0 too
          EXPECT_EQ(face.colour[3 * 4 + 2], 0.0f);
        }
      }
    }
  }
  EXPECT_GT(mixed, 0u);
  EXPECT_EQ(checked, size_t{h.frame_count} * h.view_count * 6 * h.face_size * h.face_size * 3);
}

}  // namespace
}  // namespace calf::conformance::crafted
