// The lightfield coverage stream end to end (format/SPEC.md §11.1.11): a capture set with
// coverage (format/CAPTURE.md "Coverage") encoded by calf-encode's library, decoded by the
// reference decoder, the view-dependent decoder and the CPU player's views, each compared with the
// capture set's own channels; the option that drops it; what the encoder refuses; and damaged
// coverage chunks.
#include <gtest/gtest.h>

#include <unistd.h>

#include <bit>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <span>
#include <string>
#include <vector>

#include "../gl_test_context.h"
#include "calf/capture/capture_set.h"
#include "calf/decoder/cpu_textures.h"
#include "calf/decoder/lightfield_decoder.h"
#include "calf/decoder/lightfield_reference.h"
#include "calf/decoder/lightfield_verify.h"
#include "calf/encoder/lightfield_encode.h"
#include "calf/encoder/lightfield_shard.h"
#include "calf/format/container.h"
#include "calf/format/lightfield_layout.h"
#include "calf/player/lightfield_representation.h"
#include "calf/player/view_set.h"
#include "clip_edit.h"
#include "synthetic_capture.h"

namespace calf {
namespace {

namespace fs = std::filesystem;
using container::LightfieldStream;
using testing_support::SceneSpec;

capture::ViewFrame frame_with_coverage(const SceneSpec& s, uint32_t view, uint32_t frame) {
  return testing_support::make_frame(s, view, frame);  // s.coverage: add_coverage's channels
}

// The set of `s` with or without its coverage channels.
Status write_coverage_capture(const fs::path& dir, SceneSpec s, bool with_coverage) {
  s.coverage = with_coverage;
  return testing_support::write_synthetic_capture(dir, s);
}

class LightfieldCoverage : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = fs::temp_directory_path() /
            ("calf_cov_" + std::to_string(::getpid()) + "_" +
             ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(root_);
    fs::create_directories(root_);
    spec_.face = 16;
    spec_.frames = 5;
    spec_.views = 2;
    spec_.coverage = true;
    ASSERT_TRUE(write_coverage_capture(root_ / "cov", spec_, true).ok());
  }
  void TearDown() override { fs::remove_all(root_); }

  std::vector<uint8_t> encode(const fs::path& set, const encoder::LightfieldEncodeOptions& o,
                              encoder::LightfieldEncodeStats* stats = nullptr) {
    std::vector<uint8_t> bytes;
    auto in = capture::CaptureSetReader::open(set);
    EXPECT_TRUE(in.ok()) << in.status().to_string();
    auto writer = container::Writer::create(container::memory_sink(&bytes));
    EXPECT_TRUE(writer.ok());
    auto s = encoder::encode_lightfield(*in, *writer, o);
    EXPECT_TRUE(s.ok()) << s.status().to_string();
    if (stats != nullptr && s.ok()) *stats = *s;
    EXPECT_TRUE(writer->finish().ok());
    return bytes;
  }

  static container::Reader open(const std::vector<uint8_t>& bytes) {
    auto r = container::Reader::open(container::memory_source(bytes));
    EXPECT_TRUE(r.ok()) << r.status().to_string();
    return std::move(*r);
  }

  // The set's coverage of (view, frame, face) as the stream codes it.
  std::vector<lf::CoverageTexel> expected(uint32_t view, uint32_t frame, uint32_t face) const {
    const capture::ViewFrame vf = frame_with_coverage(spec_, view, frame);
    std::vector<lf::CoverageTexel> out;
    for (uint32_t y = 0; y < spec_.face; ++y) {
      for (uint32_t x = 0; x < spec_.face; ++x) {
        const size_t i = vf.texel_index(static_cast<CubeFace>(face), x, y);
        out.push_back({static_cast<uint16_t>(vf.coverage[3 * i + 2]),
                       static_cast<uint8_t>(vf.coverage[3 * i] * 16)});
      }
    }
    return out;
  }

  fs::path root_;
  SceneSpec spec_;
};

TEST_F(LightfieldCoverage, ReferenceDecoderGivesBackTheSetsCoverageExactly) {
  for (const encoder::DepthCoding depth :
       {encoder::DepthCoding::kRaw16PredictedMasked, encoder::DepthCoding::kRaw16}) {
    encoder::LightfieldEncodeOptions o;
    o.cell_size = 8;
    o.depth = depth;
    o.depth_keyframe_interval = 2;  // groups, static runs and P-frames with coverage
    encoder::LightfieldEncodeStats stats;
    const std::vector<uint8_t> bytes = encode(root_ / "cov", o, &stats);
    const container::Reader r = open(bytes);
    EXPECT_EQ(r.header().version_minor, container::kVersionMinorCoverage);
    EXPECT_GT(stats.coverage.chunks, 0u);
    EXPECT_GT(stats.coverage.stored, 0u);
    auto ref = decoder::LightfieldReference::open(r, 0);
    ASSERT_TRUE(ref.ok()) << ref.status().to_string();
    EXPECT_TRUE(ref->has_coverage());
    decoder::LightfieldFace face;
    for (uint32_t frame = 0; frame < spec_.frames; ++frame) {
      for (uint32_t v = 0; v < spec_.views; ++v) {
        for (uint32_t f = 0; f < 6; ++f) {
          ASSERT_TRUE(ref->decode_face(v, f, frame, &face).ok());
          EXPECT_EQ(face.coverage, expected(v, frame, f))
              << "view " << v << " face " << f << " frame " << frame;
        }
      }
    }
    const decoder::LightfieldVerifyResult verified =
        decoder::verify_lightfield_track(r, 0, true, 10);
    EXPECT_TRUE(verified.problems.empty())
        << (verified.problems.empty() ? "" : verified.problems[0].to_string());
  }
}

TEST_F(LightfieldCoverage, ViewDependentDecoderAndCpuPlayerSeeTheSameCoverage) {
  encoder::LightfieldEncodeOptions o;
  o.cell_size = 8;
  o.depth_keyframe_interval = 2;
  const std::vector<uint8_t> bytes = encode(root_ / "cov", o);
  const container::Reader r = open(bytes);
  decoder::LightfieldDecoderOptions dopt;
  dopt.view_dependent = false;
  dopt.background_thread = false;
  dopt.coverage = true;
  auto dec = decoder::LightfieldDecoder::open(r, 0, dopt);
  ASSERT_TRUE(dec.ok()) << dec.status().to_string();
  EXPECT_TRUE(dec->has_coverage());
  std::vector<decoder::LightfieldViewInfo> infos = {dec->view(0), dec->view(1)};
  decoder::CpuTextures tex(dec->header(), infos);
  decoder::LightfieldFrameUpdates updates;
  // Frames in an order that seeks backwards and across groups.
  for (const uint32_t frame : {0u, 1u, 4u, 2u, 3u, 0u}) {
    ASSERT_TRUE(dec->advance(frame, {}, {}, &updates).ok());
    EXPECT_EQ(updates.stats.errors, 0u) << updates.stats.first_error;
    ASSERT_TRUE(tex.apply(updates).ok());
    for (uint32_t v = 0; v < spec_.views; ++v) {
      for (uint32_t f = 0; f < 6; ++f) {
        const auto got = tex.coverage(v, static_cast<CubeFace>(f));
        const auto want = expected(v, frame, f);
        ASSERT_EQ(std::vector<lf::CoverageTexel>(got.begin(), got.end()), want)
            << "view " << v << " face " << f << " frame " << frame;
      }
    }
  }
  // Off (the default, and the GL player's): no coverage update at all.
  dopt.coverage = false;
  auto plain = decoder::LightfieldDecoder::open(r, 0, dopt);
  ASSERT_TRUE(plain.ok());
  ASSERT_TRUE(plain->advance(0, {}, {}, &updates).ok());
  for (const auto& u : updates.updates) EXPECT_NE(u.target, decoder::UpdateTarget::kCoverage);
  EXPECT_EQ(updates.stats.coverage_bytes, 0u);

  // The CPU player's views hold the capture set's channels, value for value, as
  // player::load_capture_views puts them into the views of a capture set.
  player::LightfieldOptions lo;
  lo.decoder.view_dependent = false;
  lo.decoder.background_thread = false;
  auto lf = player::LightfieldRepresentation::open(r, 0, lo, player::RenderBackend::kCpu, nullptr);
  ASSERT_TRUE(lf.ok()) << lf.status().to_string();
  Camera cam;
  cam.position = {0.25, 0, 0};
  cam.width = 8;
  cam.height = 8;
  for (const uint32_t frame : {0u, 3u, 1u}) {
    ASSERT_TRUE((*lf)->prepare(frame, std::span<const Camera>(&cam, 1)).ok());
    const player::ViewSet* views = (*lf)->cpu_views();
    ASSERT_NE(views, nullptr);
    for (uint32_t v = 0; v < spec_.views; ++v) {
      const player::View& view = views->views[v];
      ASSERT_TRUE(view.has_coverage());
      const capture::ViewFrame vf = frame_with_coverage(spec_, v, frame);
      for (uint32_t f = 0; f < 6; ++f) {
        const CubeFace face = static_cast<CubeFace>(f);
        for (uint32_t y = 0; y < spec_.face; ++y) {
          for (uint32_t x = 0; x < spec_.face; ++x) {
            const size_t i = vf.texel_index(face, x, y);
            const player::Coverage c = view.coverage_at(face, x, y);
            ASSERT_EQ(c.near, vf.coverage[3 * i]) << v << " " << f << " " << x << " " << y;
            ASSERT_EQ(c.far, vf.coverage[3 * i + 1]) << v << " " << f << " " << x << " " << y;
            ASSERT_EQ(c.mask, vf.coverage[3 * i + 2]) << v << " " << f << " " << x << " " << y;
          }
        }
      }
    }
  }
}

TEST_F(LightfieldCoverage, DroppedOrAbsentCoverageLeavesTheClipAsWithout) {
  ASSERT_TRUE(write_coverage_capture(root_ / "plain", spec_, false).ok());
  encoder::LightfieldEncodeOptions o;
  o.cell_size = 8;
  const std::vector<uint8_t> without = encode(root_ / "plain", o);
  o.coverage = false;
  const std::vector<uint8_t> dropped = encode(root_ / "cov", o);
  // The same bytes: no coverage stream, container 1.1, whatever the manifest's version.
  EXPECT_EQ(dropped, without);
  const container::Reader r = open(dropped);
  EXPECT_EQ(r.header().version_minor, container::kVersionMinor);
  EXPECT_FALSE(decoder::track_has_coverage(r, 0));
  o.coverage = true;
  EXPECT_EQ(encode(root_ / "plain", o), without);
}

// Unmixing baked into the clip (LightfieldEncodeOptions::coverage_unmix) gives the CPU player's
// views the colour that unmixing the plain clip's decoded views gives (calf/player/view_set.h),
// up to the half floats of rgba16f colour; a set without coverage is refused, nothing written.
TEST_F(LightfieldCoverage, BakedUnmixingIsWhatThePlayerUnmixesFromThePlainClip) {
  encoder::LightfieldEncodeOptions o;
  o.cell_size = 8;
  o.colour = encoder::ColourCoding::kRgba16f;
  o.depth = encoder::DepthCoding::kRaw16;
  o.min_psnr_db = 200;  // every frame a colour keyframe: no frame blends keyframes
  const std::vector<uint8_t> plain_bytes = encode(root_ / "cov", o);
  capture::CoverageUnmixOptions unmix;
  unmix.min_share = 0.25;
  o.coverage_unmix = unmix;
  encoder::LightfieldEncodeStats stats;
  const std::vector<uint8_t> baked_bytes = encode(root_ / "cov", o, &stats);
  EXPECT_GT(stats.colour_unmixed, 0u);
  const container::Reader plain = open(plain_bytes);
  const container::Reader baked = open(baked_bytes);
  player::LightfieldOptions lo;
  lo.decoder.view_dependent = false;
  lo.decoder.background_thread = false;
  auto plain_lf =
      player::LightfieldRepresentation::open(plain, 0, lo, player::RenderBackend::kCpu, nullptr);
  auto baked_lf =
      player::LightfieldRepresentation::open(baked, 0, lo, player::RenderBackend::kCpu, nullptr);
  ASSERT_TRUE(plain_lf.ok() && baked_lf.ok());
  Camera cam;
  cam.position = {0.25, 0, 0};
  cam.width = 8;
  cam.height = 8;
  uint64_t differing = 0, unmixed = 0;
  for (const uint32_t frame : {0u, 3u, 1u}) {
    ASSERT_TRUE((*plain_lf)->prepare(frame, std::span<const Camera>(&cam, 1)).ok());
    ASSERT_TRUE((*baked_lf)->prepare(frame, std::span<const Camera>(&cam, 1)).ok());
    player::ViewSet views = *(*plain_lf)->cpu_views();
    const player::ViewSet& want = *(*baked_lf)->cpu_views();
    for (uint32_t v = 0; v < spec_.views; ++v) {
      const player::ViewSet before = views;
      const Expected<uint64_t> n = player::unmix_coverage_colour(&views.views[v], unmix);
      ASSERT_TRUE(n.ok());
      unmixed += *n;
      for (uint32_t f = 0; f < 6; ++f) {
        const CubeFace face = static_cast<CubeFace>(f);
        const std::span<const float> got = views.views[v].colour_face(face);
        const std::span<const float> baked_colour = want.views[v].colour_face(face);
        const std::span<const float> plain_colour = before.views[v].colour_face(face);
        for (size_t i = 0; i < got.size(); ++i) {
          // rgba16f: half floats, 11 significant bits.
          ASSERT_NEAR(baked_colour[i], got[i], std::ldexp(std::fabs(got[i]), -10) + 1e-6)
              << "frame " << frame << " view " << v << " face " << f << " value " << i;
          if (baked_colour[i] != plain_colour[i]) ++differing;
        }
      }
    }
  }
  EXPECT_GT(unmixed, 0u);
  EXPECT_GT(differing, 0u);  // the baked clip's colour is not the plain one's

  ASSERT_TRUE(write_coverage_capture(root_ / "plain", spec_, false).ok());
  const fs::path out = root_ / "unmixed.calf";
  auto refused = encoder::encode_lightfield_file(root_ / "plain", out.string(), o);
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.status().id(), ErrorId::kEncoderInput) << refused.status().to_string();
  EXPECT_NE(refused.status().message().find("the capture set has none"), std::string::npos);
  EXPECT_FALSE(fs::exists(out));
}

// The analysis file records the unmixing options, and view shards of an unmixed encode merge into
// the bytes of one encode (docs/FARM.md).
TEST_F(LightfieldCoverage, ShardsOfAnUnmixedEncodeMergeIntoItsBytes) {
  encoder::LightfieldEncodeOptions o;
  o.cell_size = 8;
  capture::CoverageUnmixOptions unmix;
  unmix.min_share = 0.375;
  unmix.min_jump = 0.125;
  o.coverage_unmix = unmix;
  const fs::path one = root_ / "one.calf";
  ASSERT_TRUE(encoder::encode_lightfield_file(root_ / "cov", one.string(), o).ok());
  const std::string analysis_path = (root_ / "analysis.calf").string();
  ASSERT_TRUE(encoder::write_lightfield_analysis(root_ / "cov", analysis_path, o).ok());
  auto analysis = encoder::read_lightfield_analysis(analysis_path);
  ASSERT_TRUE(analysis.ok()) << analysis.status().to_string();
  ASSERT_TRUE(analysis->options.coverage_unmix.has_value());
  EXPECT_EQ(analysis->options.coverage_unmix->min_share, 0.375);
  EXPECT_EQ(analysis->options.coverage_unmix->min_jump, 0.125);
  std::vector<std::string> shards;
  for (uint32_t v = 0; v < spec_.views; ++v) {
    const std::string path = (root_ / ("shard" + std::to_string(v) + ".calf")).string();
    const uint32_t views[1] = {v};
    auto s =
        encoder::encode_lightfield_shard(root_ / "cov", *analysis, views, 0, spec_.frames, 1, path);
    ASSERT_TRUE(s.ok()) << s.status().to_string();
    EXPECT_GT(s->colour_unmixed, 0u);
    shards.push_back(path);
  }
  const std::string merged = (root_ / "merged.calf").string();
  ASSERT_TRUE(encoder::merge_lightfield_shards(*analysis, shards, merged).ok());
  const auto bytes_of = [](const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return std::vector<uint8_t>((std::istreambuf_iterator<char>(in)),
                                std::istreambuf_iterator<char>());
  };
  EXPECT_TRUE(bytes_of(merged) == bytes_of(one));
  o.coverage_unmix.reset();
  const fs::path plain = root_ / "plain.calf";
  ASSERT_TRUE(encoder::encode_lightfield_file(root_ / "cov", plain.string(), o).ok());
  EXPECT_FALSE(bytes_of(plain) == bytes_of(one));  // unmixing changed the clip
}

TEST_F(LightfieldCoverage, CoverageTheStreamCannotHoldIsRefusedWithE255) {
  const fs::path dir = root_ / "bad";
  SceneSpec s = spec_;
  s.views = 1;
  s.frames = 1;
  capture::CaptureManifest m;
  m.version = capture::kCaptureCoverageVersion;
  m.coverage = true;
  m.frame_count = 1;
  m.face_size = s.face;
  m.view_volume = {{-1, -1, -1}, {1, 1, 1}};
  m.viewpoints.push_back({"v0", {0, 0, 0}});
  m.fps = 24;
  for (const auto& [near, far, mask] : std::vector<std::tuple<float, float, float>>{
           {0.3f, 0.0f, 65535.0f},    // not a sixteenth
           {0.25f, 0.25f, 65535.0f},  // 8 + 16 cells
           {0.0f, 0.0f, 0.0f},        // no cell at all
           {0.0f, 0.5f, 255.0f},      // a sky texel (face 3, row 2) with cells farther than sky
       }) {
    fs::remove_all(dir);
    auto w = capture::CaptureSetWriter::create(dir, m);
    ASSERT_TRUE(w.ok());
    capture::ViewFrame vf = frame_with_coverage(s, 0, 0);
    const bool sky = mask == 255.0f;
    const size_t i = vf.texel_index(sky ? CubeFace::kNegY : CubeFace::kPosY, 2, sky ? 2 : 3);
    vf.coverage[3 * i] = near;
    vf.coverage[3 * i + 1] = far;
    vf.coverage[3 * i + 2] = mask;
    ASSERT_TRUE(w->write(0, 0, vf).ok());
    ASSERT_TRUE(w->finish().ok());
    const fs::path out = root_ / "bad.calf";
    encoder::LightfieldEncodeOptions o;
    auto stats = encoder::encode_lightfield_file(dir, out.string(), o);
    ASSERT_FALSE(stats.ok());
    EXPECT_EQ(stats.status().id(), ErrorId::kEncoderCoverage) << stats.status().to_string();
    EXPECT_NE(stats.status().message().find(sky ? "face 3 texel (2, 2)" : "face 2 texel (2, 3)"),
              std::string::npos)
        << stats.status().message();
    EXPECT_FALSE(fs::exists(out));  // nothing written
    o.coverage = false;
    EXPECT_TRUE(encoder::encode_lightfield_file(dir, out.string(), o).ok());
    fs::remove(out);
  }
}

// The clip with one coverage chunk's payload rewritten by `edit` (every chunk stored raw).
std::vector<uint8_t> with_coverage_chunk(const container::Reader& r, uint32_t view, uint32_t face,
                                         uint32_t tile,
                                         const std::function<void(std::vector<uint8_t>&)>& edit) {
  return testing_support::with_chunk_edited(
      r,
      [&](const container::ChunkKeys& k) {
        return k.stream == static_cast<uint16_t>(LightfieldStream::kCoverage) && k.view == view &&
               k.face == face && k.region == tile;
      },
      edit);
}

// Rewrites a coverage chunk's keyframe so that tile texel 0 is the edge texel (mask, near).
void first_texel_edge(std::vector<uint8_t>& raw, uint32_t tile_side, uint16_t mask, uint8_t near) {
  container::FieldReader reader(raw, ErrorId::kLightfieldChunk, ErrorId::kLightfieldChunk, "t",
                                ErrorId::kLightfieldChunk);
  lf::RegionHead head;
  ASSERT_TRUE(container::read_fields(head, reader).ok());
  // Keep the head; every rectangle plain but texel 0 of the keyframe's.
  std::vector<uint8_t> out;
  ASSERT_TRUE(container::write_fields(head, out, "head").ok());
  std::vector<std::vector<lf::CoverageTexel>> texels;
  std::vector<lf::CoverageRect> rects;
  for (const lf::RegionRect& rr : head.rects) texels.emplace_back(size_t{rr.w} * rr.h);
  texels[0][0] = {mask, near};
  for (size_t k = 0; k < head.rects.size(); ++k)
    rects.push_back({head.rects[k].w, head.rects[k].h, texels[k]});
  lf::append_coverage_payload(out, rects);
  ASSERT_EQ(head.rects[0].w, tile_side);
  raw = std::move(out);
}

TEST_F(LightfieldCoverage, DamagedCoverageChunksAreE065AndContradictionsE066) {
  encoder::LightfieldEncodeOptions o;
  o.cell_size = 8;
  const std::vector<uint8_t> bytes = encode(root_ / "cov", o);
  const container::Reader r = open(bytes);
  // Face 3 (-Y), tile 0: its top half is sky (make_frame), so tile texel 0 is sky.
  const auto counts_over_16 = with_coverage_chunk(
      r, 1, 3, 0, [](std::vector<uint8_t>& raw) { first_texel_edge(raw, 8, 0x00ff, 9); });
  const auto far_behind_sky = with_coverage_chunk(
      r, 1, 3, 0, [](std::vector<uint8_t>& raw) { first_texel_edge(raw, 8, 0x00ff, 4); });
  const auto fine_over_sky = with_coverage_chunk(
      r, 1, 3, 0, [](std::vector<uint8_t>& raw) { first_texel_edge(raw, 8, 0x00ff, 8); });
  struct Case {
    const std::vector<uint8_t>* file;
    ErrorId id;
  };
  for (const Case& c : {Case{&counts_over_16, ErrorId::kCoverageChunk},
                        Case{&far_behind_sky, ErrorId::kCoverageDepth}}) {
    const container::Reader damaged = open(*c.file);
    const decoder::LightfieldVerifyResult v = decoder::verify_lightfield_track(damaged, 0, true, 4);
    ASSERT_FALSE(v.problems.empty());
    EXPECT_EQ(v.problems[0].id(), c.id) << v.problems[0].to_string();
    EXPECT_NE(v.problems[0].message().find("view 1 face 3"), std::string::npos)
        << v.problems[0].message();
    EXPECT_TRUE(v.hashes.empty());
  }
  // 8 own sky cells and 8 nearer: no cell farther than sky, a valid clip.
  const container::Reader fine = open(fine_over_sky);
  const decoder::LightfieldVerifyResult ok = decoder::verify_lightfield_track(fine, 0, true, 4);
  EXPECT_TRUE(ok.problems.empty()) << ok.problems[0].to_string();
  // The view-dependent decoder reports the damaged chunk as a frame error, with its id.
  const container::Reader damaged = open(counts_over_16);
  decoder::LightfieldDecoderOptions dopt;
  dopt.view_dependent = false;
  dopt.background_thread = false;
  dopt.coverage = true;
  auto dec = decoder::LightfieldDecoder::open(damaged, 0, dopt);
  ASSERT_TRUE(dec.ok());
  decoder::LightfieldFrameUpdates updates;
  ASSERT_TRUE(dec->advance(0, {}, {}, &updates).ok());
  EXPECT_EQ(updates.stats.errors, 1u);
  EXPECT_EQ(updates.stats.first_error.rfind("CALF-E065", 0), 0u) << updates.stats.first_error;
}

// The GL player uploads a clip's coverage (kCoverage updates into its coverage textures) and
// answers LightfieldRenderOptions::coverage as the CPU player does, frame after frame (the coverage
// of face 0's moving square changes with it), with the coverage test on (modes 4 and 3) and off.
// The C key of calf-play's window switches between the two. Sharpened colour taps (the K key)
// through both players too.
TEST_F(LightfieldCoverage, GlPlayerUsesTheClipsCoverageAsTheCpuPlayer) {
  CALF_REQUIRE_GL();
  encoder::LightfieldEncodeOptions o;
  o.cell_size = 8;
  o.depth_keyframe_interval = 2;
  const std::vector<uint8_t> bytes = encode(root_ / "cov", o);
  const container::Reader r = open(bytes);
  player::LightfieldOptions lo;
  lo.decoder.background_thread = false;
  lo.render.steps = 96;
  lo.render.coverage = 3;
  auto gl = player::LightfieldRepresentation::open(r, 0, lo, player::RenderBackend::kGl,
                                                   &test::gl_context()->gl());
  ASSERT_TRUE(gl.ok()) << gl.status().to_string();
  auto cpu = player::LightfieldRepresentation::open(r, 0, lo, player::RenderBackend::kCpu, nullptr);
  ASSERT_TRUE(cpu.ok()) << cpu.status().to_string();
  EXPECT_TRUE((*gl)->has_coverage());
  Camera cam;
  cam.position = {0.25, 0.02, 0.03};
  cam.forward = {1, -0.05, 0.1};
  cam.fov_y = 1.2;
  cam.width = cam.height = 40;
  for (const uint32_t coverage : {4u, 3u, 0u}) {
    player::LightfieldRenderOptions ro = lo.render;
    ro.coverage = coverage;
    ASSERT_TRUE((*gl)->set_render_options(ro).ok());
    ASSERT_TRUE((*cpu)->set_render_options(ro).ok());
    for (const uint32_t frame : {2u, 0u, 1u, 2u, 3u, 4u}) {
      ASSERT_TRUE((*gl)->prepare(frame, std::span<const Camera>(&cam, 1)).ok());
      ASSERT_TRUE((*cpu)->prepare(frame, std::span<const Camera>(&cam, 1)).ok());
      player::RenderedImage a, b;
      ASSERT_TRUE((*gl)->render(cam, &a).ok());
      ASSERT_TRUE((*cpu)->render(cam, &b).ok());
      ASSERT_EQ(a.color.size(), b.color.size());
      double se = 0;
      size_t same_side = 0;
      for (size_t i = 0; i < a.color.size(); ++i)
        se += (a.color[i] - b.color[i]) * (a.color[i] - b.color[i]);
      for (size_t i = 0; i < a.depth.size(); ++i) {
        same_side += std::isfinite(a.depth[i]) == std::isfinite(b.depth[i]);
      }
      const double p = se == 0 ? 200 : 10 * std::log10(a.color.size() / se);
      std::printf(
          "coverage %u, frame %u: GL vs CPU player %.2f dB, %zu of %zu pixels agree on sky\n",
          coverage, frame, p, same_side, a.depth.size());
      // With coverage on, hits land on the cell edges of this set's made-up masks, where float
      // and double can shade from different texels (lightfield_gl_renderer_test.cc,
      // MatchesCpuWithCoverage): 53.8-55.6 dB on frames 0, 1, 3, 35.7-38.0 dB on frames 2, 4.
      EXPECT_GE(p, coverage == 0 ? 45.0 : 35.0) << "coverage " << coverage << " frame " << frame;
      EXPECT_GE(same_side + 1, a.depth.size());  // an isolated float / double flip at most
    }
  }
  bool found = false;
  for (const player::Statistic& st : (*gl)->stats().entries) {
    if (st.name != "coverage") continue;
    found = true;
    EXPECT_EQ(st.value, "off");
  }
  EXPECT_TRUE(found);
  // Sharpened colour taps through both players (the window's K key): the GL player's textures and
  // the CPU player's views give the same frame, which sharpening changes; the HUD says so.
  player::LightfieldRenderOptions ro = lo.render;
  ro.coverage = 0;
  player::RenderedImage plain;
  ASSERT_TRUE((*cpu)->set_render_options(ro).ok());
  ASSERT_TRUE((*cpu)->render(cam, &plain).ok());
  ro.colour_sharpen = 0.5;
  ASSERT_TRUE((*gl)->set_render_options(ro).ok());
  ASSERT_TRUE((*cpu)->set_render_options(ro).ok());
  player::RenderedImage a, b;
  ASSERT_TRUE((*gl)->render(cam, &a).ok());
  ASSERT_TRUE((*cpu)->render(cam, &b).ok());
  double se = 0, moved = 0;
  for (size_t k = 0; k < a.color.size(); ++k) {
    se += (double{a.color[k]} - b.color[k]) * (double{a.color[k]} - b.color[k]);
    moved = std::max(moved, std::fabs(double{b.color[k]} - plain.color[k]));
  }
  const double p = se == 0 ? 200 : 10 * std::log10(a.color.size() / se);
  std::printf("colour sharpen 0.5: GL vs CPU player %.2f dB; the CPU frame moves by up to %.3f\n",
              p, moved);
  EXPECT_GE(p, 45.0);
  EXPECT_GT(moved, 0.01);
  found = false;
  for (const player::Statistic& st : (*gl)->stats().entries) {
    if (st.name != "colour sharpen") continue;
    found = true;
    EXPECT_EQ(st.value, "k 0.50");
  }
  EXPECT_TRUE(found);
}

// LightfieldOptions::keep_coverage off (calf-play --headless): options that read no coverage
// (coverage 0, hint coverage 0) leave the stream undecoded, so the clip plays as the same clip
// without it, frame for frame and bit for bit in both players, and decodes none of its bytes; a
// rule that reads it still gets it.
TEST_F(LightfieldCoverage, CoverageNothingReadsIsNotDecodedWhenItNeedNotBeKept) {
  encoder::LightfieldEncodeOptions o;
  o.cell_size = 8;
  o.depth_keyframe_interval = 2;
  const std::vector<uint8_t> with = encode(root_ / "cov", o);
  o.coverage = false;
  const std::vector<uint8_t> without = encode(root_ / "cov", o);
  const container::Reader rw = open(with), rn = open(without);
  player::LightfieldOptions lo;
  lo.decoder.background_thread = false;
  lo.render.steps = 96;
  lo.render.coverage = 0;
  lo.render.surface_hint_coverage = 0;
  lo.keep_coverage = false;
  Camera cam;
  cam.position = {0.25, 0.02, 0.03};
  cam.forward = {1, -0.05, 0.1};
  cam.fov_y = 1.2;
  cam.width = cam.height = 40;
  const auto stat = [](const player::LightfieldRepresentation& lf, const std::string& name) {
    for (const player::Statistic& st : lf.stats().entries) {
      if (st.name == name) return st.value;
    }
    return std::string("(missing)");
  };
  for (const player::RenderBackend backend :
       {player::RenderBackend::kCpu, player::RenderBackend::kGl}) {
    const bool gl = backend == player::RenderBackend::kGl;
    if (gl && test::gl_context() == nullptr) continue;
    const player::GlFunctions* functions = gl ? &test::gl_context()->gl() : nullptr;
    auto a = player::LightfieldRepresentation::open(rw, 0, lo, backend, functions);
    auto b = player::LightfieldRepresentation::open(rn, 0, lo, backend, functions);
    ASSERT_TRUE(a.ok()) << a.status().to_string();
    ASSERT_TRUE(b.ok()) << b.status().to_string();
    EXPECT_TRUE((*a)->has_coverage());
    EXPECT_EQ(stat(**a, "coverage"), "off (not decoded)");
    for (const uint32_t frame : {0u, 3u, 1u, 4u}) {
      ASSERT_TRUE((*a)->prepare(frame, std::span<const Camera>(&cam, 1)).ok());
      ASSERT_TRUE((*b)->prepare(frame, std::span<const Camera>(&cam, 1)).ok());
      EXPECT_EQ(stat(**a, "updates"), stat(**b, "updates")) << "frame " << frame;
      player::RenderedImage ia, ib;
      ASSERT_TRUE((*a)->render(cam, &ia).ok());
      ASSERT_TRUE((*b)->render(cam, &ib).ok());
      EXPECT_EQ(ia.color, ib.color) << (gl ? "GL" : "CPU") << " frame " << frame;
      EXPECT_EQ(ia.depth, ib.depth) << (gl ? "GL" : "CPU") << " frame " << frame;
      if (!gl) {
        for (const player::View& v : (*a)->cpu_views()->views) EXPECT_FALSE(v.has_coverage());
      }
    }
    // Hint crossings confirmed by coverage read it: decoded.
    player::LightfieldOptions hints = lo;
    hints.render.surface_hint_coverage = 1;
    auto c = player::LightfieldRepresentation::open(rw, 0, hints, backend, functions);
    ASSERT_TRUE(c.ok()) << c.status().to_string();
    EXPECT_EQ(stat(**c, "coverage"), "off");
    ASSERT_TRUE((*c)->prepare(0, std::span<const Camera>(&cam, 1)).ok());
    if (!gl) {
      for (const player::View& v : (*c)->cpu_views()->views) EXPECT_TRUE(v.has_coverage());
    }
  }
}

}  // namespace
}  // namespace calf
