// The lightfield conformance clips (tests/conformance/lightfield/): frozen files of today's
// bitstream with the hash of every decoded face at every frame (SPEC §14). Both decoders must
// reproduce every line: the reference decoder through verify_lightfield_track (what
// `calf-verify --decode` prints) and the view-dependent LightfieldDecoder with everything visible,
// read back from its CPU textures. The files were written by encode_pin_test
// (CALF_CONFORMANCE_OUT), the crafted_* clips by tests/conformance/lightfield_crafted.h, and
// hashed by calf-verify --decode when they were frozen; nothing here regenerates them.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "calf/decoder/cpu_textures.h"
#include "calf/decoder/lightfield_decoder.h"
#include "calf/decoder/lightfield_reference.h"
#include "calf/decoder/lightfield_verify.h"
#include "calf/format/container.h"
#include "calf/format/container_codec.h"
#include "calf/format/cube.h"
#include "calf/format/grid.h"
#include "calf/format/lightfield_layout.h"

namespace calf::decoder {
namespace {

namespace fs = std::filesystem;

fs::path suite_dir() {
  const char* root = std::getenv("CALF_SOURCE_DIR");
  return fs::path(root ? root : ".") / "tests" / "conformance" / "lightfield";
}

std::vector<std::string> read_lines(const fs::path& p) {
  std::ifstream in(p);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

// The clips, by name; the suite holds one per colour coding at least (README there).
std::vector<std::string> clip_names() {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(suite_dir())) {
    if (e.path().extension() == ".calf") names.push_back(e.path().stem().string());
  }
  std::sort(names.begin(), names.end());
  return names;
}

TEST(LightfieldConformance, SuiteIsComplete) {
  const std::vector<std::string> names = clip_names();
  EXPECT_GE(names.size(), 6u);
  for (const char* colour : {"bc1", "bc7", "bc6h", "rgba8", "rgba16f", "av1"}) {
    bool found = false;
    for (const auto& n : names) found |= n.rfind(std::string(colour) + "_", 0) == 0;
    EXPECT_TRUE(found) << "no clip with colour " << colour;
  }
  for (const auto& n : names) {
    EXPECT_TRUE(fs::exists(suite_dir() / (n + ".hashes"))) << n;
  }
}

std::string read_text(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

// Depth format r16p is lossless: each predicted clip (same scene and codings as a raw16 clip, depth
// predicted) decodes to the hashes frozen for its raw16 twin before r16p existed.
// So do the masked clips (r16pm, §11.1.9, `*_pred16m_*`), frozen after it.
TEST(LightfieldConformance, PredictedDepthClipsDecodeAsTheirRaw16Twins) {
  size_t twins = 0;
  for (const auto& n : clip_names()) {
    if (n.ends_with("_zdir")) continue;  // 1.1 twins: CompressedDirectoryClipsDecodeAs...
    size_t at = n.find("_pred16_"), len = 8;
    if (at == std::string::npos) {
      at = n.find("_pred16m_");
      len = 9;
    }
    if (at == std::string::npos) continue;
    const std::string twin = n.substr(0, at) + "_raw16_" + n.substr(at + len);
    const std::string mine = read_text(suite_dir() / (n + ".hashes"));
    EXPECT_FALSE(mine.empty()) << n;
    EXPECT_EQ(mine, read_text(suite_dir() / (twin + ".hashes"))) << n << " vs " << twin;
    ++twins;
  }
  EXPECT_GE(twins, 5u);
}

// Container 1.1 (SPEC §4.1): each `*_zdir` clip is a plain-directory clip's twin with its
// directory compressed, and decodes to the twin's hashes.
TEST(LightfieldConformance, CompressedDirectoryClipsDecodeAsTheirPlainTwins) {
  size_t twins = 0;
  for (const auto& n : clip_names()) {
    if (!n.ends_with("_zdir")) continue;
    const std::string twin = n.substr(0, n.size() - 5);
    const std::string mine = read_text(suite_dir() / (n + ".hashes"));
    EXPECT_FALSE(mine.empty()) << n;
    EXPECT_EQ(mine, read_text(suite_dir() / (twin + ".hashes"))) << n << " vs " << twin;
    auto a = container::Reader::open((suite_dir() / (n + ".calf")).string());
    auto b = container::Reader::open((suite_dir() / (twin + ".calf")).string());
    ASSERT_TRUE(a.ok() && b.ok()) << n;
    EXPECT_EQ(a->header().required_features, container::kFeatureCompressedDirectory) << n;
    EXPECT_EQ(b->header().required_features, 0u) << twin;
    EXPECT_LT(a->header().file_size, b->header().file_size) << n;
    ++twins;
  }
  EXPECT_GE(twins, 2u);
}

container::Reader open_clip(const std::string& name) {
  auto r = container::Reader::open((suite_dir() / (name + ".calf")).string());
  EXPECT_TRUE(r.ok()) << r.status().to_string();
  return std::move(*r);
}

// The r16pm clips exercise what is new in them: P-frame rectangles whose masks leave texels to
// the tile state, and rectangles that store every texel.
TEST(LightfieldConformance, MaskedDepthClipsSkipTexels) {
  size_t clips = 0;
  for (const auto& n : clip_names()) {
    if (n.find("_pred16m_") == std::string::npos) continue;
    const container::Reader reader = open_clip(n);
    auto ref = LightfieldReference::open(reader, 0);
    ASSERT_TRUE(ref.ok()) << n;
    auto grid = FaceGrid::with_cell_size(ref->header().face_size, ref->header().depth_region_size);
    ASSERT_TRUE(grid.ok()) << n;
    uint64_t skipped = 0, p_rects = 0, skipping_rects = 0;
    for (uint32_t id = 0; id < reader.chunks().size(); ++id) {
      const container::ChunkKeys& k = reader.chunks()[id].keys;
      if (k.stream != static_cast<uint16_t>(container::LightfieldStream::kDepth)) continue;
      auto raw = reader.read_chunk(id);
      auto r = grid->cell_rect(k.region);
      ASSERT_TRUE(raw.ok() && r.ok()) << n;
      auto c = lf::parse_region_chunk(*raw, k.frame_count, r->width, r->height,
                                      lf::RegionCoding::kR16PredictedMasked, n);
      ASSERT_TRUE(c.ok()) << c.status().to_string();
      uint64_t stored = uint64_t{r->width} * r->height;  // the keyframe's
      for (size_t i = 1; i < c->rects.size(); ++i) {
        const lf::RegionRect& rr = c->rects[i];
        const uint64_t next = i + 1 < c->rects.size() ? c->rects[i + 1].first_unit : c->units;
        const uint64_t area = uint64_t{rr.w} * rr.h, kept = next - rr.first_unit;
        stored += kept;
        ++p_rects;
        skipping_rects += kept < area;
        skipped += area - kept;
      }
      EXPECT_EQ(stored, c->units) << n;
    }
    EXPECT_GT(skipped, 0u) << n;
    EXPECT_GT(skipping_rects, 0u) << n;
    EXPECT_LT(skipping_rects, p_rects) << n;
    ++clips;
  }
  EXPECT_GE(clips, 2u);
}

// The clip's lightfield track: track 0, except in clips that put another track first.
uint16_t lightfield_track(const container::Reader& r) {
  for (const auto& t : r.tracks()) {
    if (std::holds_alternative<container::LightfieldTrackHeader>(t.header)) return t.id;
  }
  ADD_FAILURE() << "no lightfield track";
  return 0;
}

TEST(LightfieldConformance, ReferenceDecoderReproducesEveryHash) {
  size_t dropped_clips = 0;
  for (const std::string& name : clip_names()) {
    const container::Reader reader = open_clip(name);
    const uint16_t track = lightfield_track(reader);
    const std::vector<std::string> want = read_lines(suite_dir() / (name + ".hashes"));
    auto ref = LightfieldReference::open(reader, track);
    ASSERT_TRUE(ref.ok()) << name << ": " << ref.status().to_string();
    bool dropped = false;
    for (uint32_t v = 0; v < ref->header().view_count; ++v) dropped |= !ref->view_problem(v).ok();
    const LightfieldVerifyResult result = verify_lightfield_track(reader, track, true, 10);
    if (dropped) {
      // SPEC §14: a dropped view is a problem of the file, which then has no hash lines; the
      // .hashes list the other views, which decode as if nothing were wrong.
      ASSERT_FALSE(result.problems.empty()) << name;
      EXPECT_EQ(result.problems[0].id(), ErrorId::kLightfieldChunk) << name;
      EXPECT_TRUE(result.hashes.empty()) << name;
      std::vector<std::string> got;
      LightfieldFace face;
      for (uint32_t frame = 0; frame < ref->header().frame_count; ++frame) {
        for (uint32_t v = 0; v < ref->header().view_count; ++v) {
          if (!ref->view_problem(v).ok()) continue;
          for (uint32_t f = 0; f < 6; ++f) {
            ASSERT_TRUE(ref->decode_face(v, f, frame, &face).ok()) << name;
            got.push_back(face_hash_line(track, {frame, v, f, face_hash(face)}));
          }
        }
      }
      EXPECT_EQ(got, want) << name;
      ++dropped_clips;
      continue;
    }
    ASSERT_TRUE(result.problems.empty()) << name << ": " << result.problems[0].to_string();
    ASSERT_EQ(result.hashes.size(), want.size()) << name;
    for (size_t i = 0; i < want.size(); ++i) {
      EXPECT_EQ(face_hash_line(track, result.hashes[i]), want[i]) << name << " line " << i + 1;
    }
  }
  EXPECT_GE(dropped_clips, 1u);
}

TEST(LightfieldConformance, ViewDependentDecoderReproducesEveryHash) {
  for (const std::string& name : clip_names()) {
    const container::Reader reader = open_clip(name);
    const std::vector<std::string> want = read_lines(suite_dir() / (name + ".hashes"));
    const uint16_t track = lightfield_track(reader);
    LightfieldDecoderOptions o;
    o.view_dependent = false;
    o.background_thread = false;
    o.coverage = true;  // the hash of a track with coverage holds it (SPEC §14 item 4)
    auto d = LightfieldDecoder::open(reader, track, o);
    ASSERT_TRUE(d.ok()) << name << ": " << d.status().to_string();
    std::vector<LightfieldViewInfo> views;
    for (uint32_t v = 0; v < d->header().view_count; ++v) views.push_back(d->view(v));
    CpuTextures tex(d->header(), views);
    size_t line = 0;
    for (uint32_t frame = 0; frame < d->header().frame_count; ++frame) {
      LightfieldFrameUpdates fu;
      ASSERT_TRUE(d->advance(frame, {}, {}, &fu).ok()) << name;
      ASSERT_EQ(fu.stats.errors, 0u) << name << ": " << fu.stats.first_error;
      ASSERT_TRUE(tex.apply(fu).ok()) << name;
      for (uint32_t v = 0; v < d->header().view_count; ++v) {
        if (!d->view_problem(v).ok()) continue;  // a dropped view has no lines (SPEC §14)
        for (uint32_t f = 0; f < 6; ++f) {
          const CubeFace face = static_cast<CubeFace>(f);
          LightfieldFace decoded;
          decoded.colour = tex.colour(v, face);
          const auto depth = tex.depth(v, face);
          decoded.depth.assign(depth.begin(), depth.end());
          const auto material = tex.material(v, face);
          decoded.material.assign(material.begin(), material.end());
          const auto coverage = tex.coverage(v, face);
          ASSERT_EQ(coverage.empty(), !d->has_coverage()) << name;
          decoded.coverage.assign(coverage.begin(), coverage.end());
          ASSERT_LT(line, want.size()) << name;
          EXPECT_EQ(face_hash_line(track, {frame, v, f, face_hash(decoded)}), want[line])
              << name << " line " << line + 1;
          ++line;
        }
      }
    }
    EXPECT_EQ(line, want.size()) << name;
  }
}

// The hash is of values, not of a struct's bytes: a known face gives a known XXH3-64 of the
// little-endian bytes spelled out here (1.0f = 0x3f800000, depth code 0x0102, material 7).
TEST(LightfieldConformance, FaceHashIsOfLittleEndianValues) {
  LightfieldFace face;
  face.colour = {1.0f};
  face.depth = {0x0102};
  face.material = {7};
  const std::vector<uint8_t> bytes = {0x00, 0x00, 0x80, 0x3f, 0x02, 0x01, 0x07};
  EXPECT_EQ(face_hash(face), container::hash64(bytes));
  face.material.clear();
  EXPECT_EQ(face_hash(face), container::hash64(std::span(bytes).first(6)));
  // A track with coverage: each texel's mask (u16) and near count after the material.
  face.material = {7};
  face.coverage = {{0x0a0b, 12}};
  const std::vector<uint8_t> with = {0x00, 0x00, 0x80, 0x3f, 0x02, 0x01, 0x07, 0x0b, 0x0a, 0x0c};
  EXPECT_EQ(face_hash(face), container::hash64(with));
}

}  // namespace
}  // namespace calf::decoder
