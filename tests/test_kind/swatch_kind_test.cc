// The test-only swatch kind (tests/test_kind/) through each layer's kind table: a clip written
// here is verified and summarised by the decoder table's entry and played through Playback, which
// opens it by the player table. Built only with -DCALF_TEST_KIND=ON (tools/test_kind.sh).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "../scratch_dir.h"
#include "calf/decoder/kind_table.h"
#include "calf/format/container.h"
#include "calf/format/container_codec.h"
#include "calf/format/track_registry.h"
#include "calf/player/playback.h"

namespace calf {
namespace {

using container::TrackKind;

// Three frames: red, green, blue-ish.
constexpr uint8_t kColours[3][3] = {{255, 0, 0}, {0, 255, 0}, {10, 20, 250}};

std::string write_clip(bool with_frame_2 = true) {
  const std::string path =
      (test::scratch_dir("swatch_kind_test") / (with_frame_2 ? "three.calf" : "short.calf"))
          .string();
  auto w = container::Writer::create(path);
  EXPECT_TRUE(w.ok());
  container::SwatchTrackHeader h;
  h.frame_count = 3;
  auto blob = container::write_track_header(h);
  EXPECT_TRUE(blob.ok());
  auto track = w->add_track(static_cast<uint16_t>(TrackKind::kSwatch), 0, *blob);
  EXPECT_TRUE(track.ok());
  const std::vector<uint8_t> index = {1, 0, 0, 0, 0, 0, 0, 0};  // layout 1, flags 0
  EXPECT_TRUE(
      w->add_chunk({.track = *track, .stream = 0}, index, container::Compression::kNone).ok());
  for (uint32_t f = 0; f < (with_frame_2 ? 3u : 2u); ++f) {
    const std::vector<uint8_t> c(kColours[f], kColours[f] + 3);
    EXPECT_TRUE(w->add_chunk({.track = *track, .stream = 1, .first_frame = f, .frame_count = 1}, c,
                             container::Compression::kNone)
                    .ok());
  }
  EXPECT_TRUE(w->finish().ok());
  return path;
}

std::vector<char> read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::vector<char>(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// tests/conformance/swatch/three_frames.calf, which the conformance runner checks against hashes
// computed apart from calf (xxh3_64 of each colour chunk's 3 bytes), is this test's clip.
// CALF_SWATCH_CLIP_OUT=PATH copies the clip this test writes to PATH.
TEST(SwatchKind, TheConformanceClipIsThisTestsClip) {
  const std::string path = write_clip();
  if (const char* out = std::getenv("CALF_SWATCH_CLIP_OUT"))
    std::filesystem::copy_file(path, out, std::filesystem::copy_options::overwrite_existing);
  const char* root = std::getenv("CALF_SOURCE_DIR");
  ASSERT_NE(root, nullptr) << "ctest sets CALF_SOURCE_DIR";
  const std::vector<char> committed =
      read_file(std::string(root) + "/tests/conformance/swatch/three_frames.calf");
  EXPECT_FALSE(committed.empty());
  EXPECT_TRUE(committed == read_file(path));
}

TEST(SwatchKind, TheRegistryNamesIt) {
  const auto kind = static_cast<uint16_t>(TrackKind::kSwatch);
  EXPECT_TRUE(container::is_known_track_kind(kind));
  EXPECT_STREQ(container::track_kind_name(kind), "swatch");
  EXPECT_EQ(container::stream_count(kind), 2);
  EXPECT_STREQ(container::stream_name(kind, 1), "colour");
}

TEST(SwatchKind, TheDecoderTableVerifiesAndSummarisesIt) {
  auto r = container::Reader::open(write_clip());
  ASSERT_TRUE(r.ok()) << r.status().to_string();
  const auto* kind = decoder::find_decoder_kind(static_cast<uint16_t>(TrackKind::kSwatch));
  ASSERT_NE(kind, nullptr);
  const decoder::TrackVerification v = kind->verify(*r, 0, true, 10);
  EXPECT_TRUE(v.problems.empty());
  ASSERT_EQ(v.hash_lines.size(), 3u);
  for (uint32_t f = 0; f < 3; ++f) {
    char expected[64];
    std::snprintf(expected, sizeof expected, "track 0 swatch frame %u %016llx", f,
                  static_cast<unsigned long long>(
                      container::hash64(std::span<const uint8_t>(kColours[f], kColours[f] + 3))));
    EXPECT_EQ(v.hash_lines[f], expected);
  }
  EXPECT_EQ(v.decoded[0], 3u);
  decoder::VerifiedTotals totals;
  totals.tracks = 1;
  totals.decoded[0] = 3;
  EXPECT_EQ(kind->verified_summary(totals), ", 3 swatch frames decoded");
  const auto figures = kind->figures(*r, r->tracks()[0]);
  ASSERT_TRUE(figures.has_value());
  EXPECT_EQ(figures->text, "swatch: 3 colour chunks");
}

TEST(SwatchKind, AMissingFrameIsAProblem) {
  auto r = container::Reader::open(write_clip(false));
  ASSERT_TRUE(r.ok()) << r.status().to_string();
  const auto* kind = decoder::find_decoder_kind(static_cast<uint16_t>(TrackKind::kSwatch));
  ASSERT_NE(kind, nullptr);
  const decoder::TrackVerification v = kind->verify(*r, 0, true, 10);
  ASSERT_EQ(v.problems.size(), 1u);
  EXPECT_NE(v.problems[0].message().find("frame 2"), std::string::npos);
  EXPECT_TRUE(v.hash_lines.empty());
}

TEST(SwatchKind, PlaybackOpensItThroughThePlayerTable) {
  player::PlaybackOptions options;
  options.use_gl = false;
  auto p = player::Playback::open(write_clip(), options, nullptr);
  ASSERT_TRUE(p.ok()) << p.status().to_string();
  ASSERT_EQ((*p)->representations().size(), 1u);
  EXPECT_EQ((*p)->representations()[0]->kind(), "swatch");
  EXPECT_EQ((*p)->frame_count(), 3u);
  Camera eye;
  eye.width = 4;
  eye.height = 2;
  for (uint32_t f = 0; f < 3; ++f) {
    ASSERT_TRUE((*p)->prepare(f, std::span<const Camera>(&eye, 1)).ok());
    player::RenderedImage image;
    ASSERT_TRUE((*p)->render(eye, &image).ok());
    ASSERT_EQ(image.color.size(), 3u * 4 * 2);
    for (size_t i = 0; i < 8; ++i) {
      for (int c = 0; c < 3; ++c)
        EXPECT_EQ(image.color[3 * i + c], static_cast<float>(kColours[f][c]) / 255.0f);
      EXPECT_TRUE(std::isinf(image.depth[i]));
    }
  }
}

}  // namespace
}  // namespace calf
