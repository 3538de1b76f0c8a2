// The light-field encoder's two passes (encoder/include/calf/encoder/lightfield_encode.h "Two
// passes"): the analysis decides every header field before a view is coded, views coded apart
// (in another order, with other thread counts) assemble into the very bytes of
// encoder::encode_lightfield(), and misuse of the passes (wrong order, other options, images
// changed in between) is refused.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "../integration/synthetic_capture.h"
#include "calf/capture/capture_set.h"
#include "calf/encoder/lightfield_encode.h"
#include "calf/format/container.h"

namespace calf {
namespace {

namespace fs = std::filesystem;
using testing_support::kSky;
constexpr uint32_t kFace = 8, kFrames = 4, kViews = 3;

// View 0 sees a mirror on face 1 and depths 2.0 ... 2.75 (2.0 only at frame 0); view 1 no
// material and depths 3.0 ... 3.5; view 2 only sky. Colour is LDR except, with `hdr_view` set,
// one texel of that view's last frame.
capture::ViewFrame make_frame(uint32_t view, uint32_t frame, int hdr_view) {
  capture::ViewFrame vf;
  vf.resize(kFace, true);
  for (uint32_t face = 0; face < 6; ++face) {
    for (uint32_t y = 0; y < kFace; ++y) {
      for (uint32_t x = 0; x < kFace; ++x) {
        const size_t i = vf.texel_index(static_cast<CubeFace>(face), x, y);
        vf.color[3 * i] = 0.1f + 0.1f * x;
        vf.color[3 * i + 1] = 0.05f * y + 0.1f * frame;
        vf.color[3 * i + 2] = 0.1f * face;
        float z = kSky;
        if (view == 0) z = 2.0f + 0.25f * (face % 2) + 0.5f * (x == 0 ? frame % 2 : 1) * (y < 4);
        if (view == 0 && frame == 0 && face == 0 && x == 0 && y == 0) z = 2.0f;
        if (view == 0 && face == 5) z = 2.75f;
        if (view == 1) z = y < 2 ? kSky : (face == 3 && x == 7 ? 3.5f : 3.0f);
        vf.depth[i] = z;
        const bool mirror = view == 0 && face == 1 && x < 3 && frame >= 1;
        vf.material[3 * i] = mirror ? 0.75f : 0.0f;
        vf.material[3 * i + 1] = 0.0f;
        vf.material[3 * i + 2] = 1.0f;
      }
    }
  }
  if (hdr_view >= 0 && view == static_cast<uint32_t>(hdr_view) && frame == kFrames - 1) {
    vf.color[3 * vf.texel_index(CubeFace::kNegZ, 5, 6) + 1] = 7.5f;
  }
  return vf;
}

class LightfieldTwoPass : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = fs::temp_directory_path() /
            ("calf_lf2_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "_" +
             ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(root_);
    fs::create_directories(root_);
  }
  void TearDown() override { fs::remove_all(root_); }

  fs::path make_capture(const std::string& name, int hdr_view) {
    testing_support::SceneSpec spec;
    spec.face = kFace;
    spec.frames = kFrames;
    spec.views = kViews;
    spec.material = true;
    const fs::path dir = root_ / name;
    const Status st = testing_support::write_capture(
        dir, spec, [&](uint32_t v, uint32_t f) { return make_frame(v, f, hdr_view); });
    EXPECT_TRUE(st.ok()) << st.to_string();
    return dir;
  }

  static encoder::LightfieldEncodeOptions options(uint32_t threads) {
    encoder::LightfieldEncodeOptions o;
    o.cell_size = 4;
    o.depth_regions_per_side = 2;
    o.depth_keyframe_interval = 3;
    o.threads = threads;
    return o;
  }

  // encoder::encode_lightfield() into memory.
  static std::vector<uint8_t> encode_whole(const capture::CaptureSetReader& input,
                                           const encoder::LightfieldEncodeOptions& o) {
    std::vector<uint8_t> bytes;
    auto writer = container::Writer::create(container::memory_sink(&bytes), o.levels);
    EXPECT_TRUE(writer.ok());
    auto stats = encoder::encode_lightfield(input, *writer, o);
    EXPECT_TRUE(stats.ok()) << stats.status().to_string();
    const Status st = writer->finish();
    EXPECT_TRUE(st.ok()) << st.to_string();
    return bytes;
  }

  fs::path root_;
};

TEST_F(LightfieldTwoPass, AnalysisDecidesTheWholeHeader) {
  const fs::path dir = make_capture("set", /*hdr_view=*/2);
  auto input = capture::CaptureSetReader::open(dir);
  ASSERT_TRUE(input.ok());
  auto a = encoder::analyse_lightfield(*input, options(2));
  ASSERT_TRUE(a.ok()) << a.status().to_string();

  // HDR appears in the last view only, and in its last frame: still a HDR track.
  EXPECT_TRUE(a->hdr);
  EXPECT_EQ(a->colour, encoder::ColourCoding::kBc6h);
  EXPECT_EQ(a->header.colour_format, static_cast<uint16_t>(container::PixelFormat::kBc6h));
  EXPECT_EQ(a->header.flags, 1);
  // The default depth coding (encoder::LightfieldEncodeOptions::depth): r16pm.
  EXPECT_EQ(a->header.depth_format,
            static_cast<uint16_t>(container::PixelFormat::kR16PredictedMasked));
  EXPECT_EQ(a->header.material_format, static_cast<uint16_t>(container::PixelFormat::kRgba8));
  EXPECT_EQ(a->header.view_count, kViews);
  EXPECT_EQ(a->header.frame_count, kFrames);
  EXPECT_EQ(a->header.face_size, kFace);
  EXPECT_EQ(a->header.cell_size, 4u);
  EXPECT_EQ(a->header.depth_region_size, 4u);
  EXPECT_EQ(a->header.fps_numerator, 24u);
  EXPECT_EQ(a->header.fps_denominator, 1u);

  ASSERT_EQ(a->views.size(), kViews);
  ASSERT_TRUE(a->views[0].depth_range.has_value());
  EXPECT_EQ(a->views[0].depth_range->z_near(), 2.0f);
  EXPECT_EQ(a->views[0].depth_range->z_far(), 2.75f);
  EXPECT_TRUE(a->views[0].has_material);
  EXPECT_FALSE(a->views[0].hdr);
  ASSERT_TRUE(a->views[1].depth_range.has_value());
  EXPECT_EQ(a->views[1].depth_range->z_near(), 3.0f);
  EXPECT_EQ(a->views[1].depth_range->z_far(), 3.5f);
  EXPECT_FALSE(a->views[1].has_material);
  EXPECT_FALSE(a->views[2].depth_range.has_value());
  EXPECT_FALSE(a->views[2].has_material);
  EXPECT_TRUE(a->views[2].hdr);

  // The file's track header is the analysis's, byte for byte: nothing was patched afterwards.
  const std::vector<uint8_t> bytes = encode_whole(*input, options(1));
  auto reader = container::Reader::open(container::memory_source(bytes));
  ASSERT_TRUE(reader.ok()) << reader.status().to_string();
  ASSERT_EQ(reader->tracks().size(), 1u);
  auto planned = container::encode_track_header(a->header);
  ASSERT_TRUE(planned.ok());
  EXPECT_EQ(reader->tracks()[0].record.header, *planned);
}

TEST_F(LightfieldTwoPass, LdrSetWithoutMaterialPlansBc1AndNoMaterialStream) {
  const fs::path dir = make_capture("set", /*hdr_view=*/-1);
  auto input = capture::CaptureSetReader::open(dir);
  ASSERT_TRUE(input.ok());
  encoder::LightfieldEncodeOptions o = options(1);
  o.depth = encoder::DepthCoding::kBc5;
  auto a = encoder::analyse_lightfield(*input, o);
  ASSERT_TRUE(a.ok()) << a.status().to_string();
  EXPECT_FALSE(a->hdr);
  EXPECT_EQ(a->header.colour_format, static_cast<uint16_t>(container::PixelFormat::kBc1));
  EXPECT_EQ(a->header.depth_format, static_cast<uint16_t>(container::PixelFormat::kBc5));
  EXPECT_EQ(a->header.material_format, static_cast<uint16_t>(container::PixelFormat::kBc1));
  EXPECT_EQ(a->header.flags, 0);
  // Facts without material anywhere: no material stream, whatever the manifest promises.
  std::vector<encoder::LightfieldViewFacts> facts = a->views;
  facts[0].has_material = false;
  auto plain = encoder::plan_lightfield(input->manifest(), facts, o);
  ASSERT_TRUE(plain.ok()) << plain.status().to_string();
  EXPECT_EQ(plain->header.material_format, 0);
  // A given colour format is kept even for HDR facts.
  facts[1].hdr = true;
  o.colour = encoder::ColourCoding::kBc7;
  auto bc7 = encoder::plan_lightfield(input->manifest(), facts, o);
  ASSERT_TRUE(bc7.ok());
  EXPECT_EQ(bc7->colour, encoder::ColourCoding::kBc7);
  EXPECT_FALSE(bc7->hdr);
  o.colour = encoder::ColourCoding::kAuto;
  auto hdr = encoder::plan_lightfield(input->manifest(), facts, o);
  ASSERT_TRUE(hdr.ok());
  EXPECT_EQ(hdr->colour, encoder::ColourCoding::kBc6h);
  // One fact per viewpoint.
  facts.pop_back();
  EXPECT_EQ(encoder::plan_lightfield(input->manifest(), facts, o).status().id(),
            ErrorId::kEncoderInput);
}

// Views analysed one by one and coded in reverse order with other thread counts, then assembled:
// the bytes of one encoder::encode_lightfield() run.
TEST_F(LightfieldTwoPass, ViewsCodedApartAssembleIntoTheSameBytes) {
  for (const int hdr_view : {-1, 1}) {
    const fs::path dir = make_capture("set" + std::to_string(hdr_view + 1), hdr_view);
    auto input = capture::CaptureSetReader::open(dir);
    ASSERT_TRUE(input.ok());
    const std::vector<uint8_t> whole = encode_whole(*input, options(1));
    ASSERT_FALSE(whole.empty());

    std::vector<encoder::LightfieldViewFacts> facts(kViews);
    for (uint32_t v = kViews; v-- > 0;) {
      auto f = encoder::analyse_lightfield_view(*input, v);
      ASSERT_TRUE(f.ok()) << f.status().to_string();
      facts[v] = *f;
    }
    auto a = encoder::plan_lightfield(input->manifest(), facts, options(1));
    ASSERT_TRUE(a.ok()) << a.status().to_string();
    std::vector<encoder::LightfieldViewEncoding> views(kViews);
    std::vector<uint64_t> progress;
    for (uint32_t v = kViews; v-- > 0;) {
      encoder::LightfieldEncodeOptions o = options(v + 1);
      o.progress = [&](uint64_t done, uint64_t total) {
        EXPECT_EQ(total, 6u * kViews);
        progress.push_back(done);
      };
      auto e = encoder::encode_lightfield_view(*input, *a, v, o);
      ASSERT_TRUE(e.ok()) << e.status().to_string();
      EXPECT_EQ(e->view, v);
      views[v] = std::move(*e);
    }
    EXPECT_EQ(progress, (std::vector<uint64_t>{13, 14, 15, 16, 17, 18, 7, 8, 9, 10, 11, 12, 1, 2, 3,
                                               4, 5, 6}));

    std::vector<uint8_t> apart;
    auto writer = container::Writer::create(container::memory_sink(&apart));
    ASSERT_TRUE(writer.ok());
    auto track = encoder::LightfieldTrackWriter::begin(*writer, *a);
    ASSERT_TRUE(track.ok()) << track.status().to_string();
    EXPECT_EQ(track->finish().status().id(), ErrorId::kEncoderInput);  // no view yet
    EXPECT_EQ(track->append(views[1]).id(), ErrorId::kEncoderInput);   // view 0 comes first
    for (const encoder::LightfieldViewEncoding& v : views) ASSERT_TRUE(track->append(v).ok());
    EXPECT_EQ(track->append(views[0]).id(), ErrorId::kEncoderInput);  // one view too many
    auto stats = track->finish();
    ASSERT_TRUE(stats.ok()) << stats.status().to_string();
    ASSERT_TRUE(writer->finish().ok());
    EXPECT_EQ(apart, whole) << "hdr view " << hdr_view;

    // The merged figures count each view once.
    EXPECT_EQ(stats->material_views, 1u);
    EXPECT_EQ(stats->colour_cells, uint64_t{kViews} * 6 * 4);
    EXPECT_EQ(stats->depth_regions, uint64_t{kViews} * 6 * 4);
    EXPECT_EQ(stats->hdr, hdr_view >= 0);
    uint64_t chunks = 0;
    for (const encoder::LightfieldViewEncoding& v : views) chunks += v.chunks.size();
    EXPECT_EQ(stats->colour.chunks + stats->depth.chunks + stats->material.chunks + kViews, chunks);
  }
}

TEST_F(LightfieldTwoPass, ViewPassRefusesAnotherPlanOrChangedImages) {
  const fs::path dir = make_capture("set", /*hdr_view=*/-1);
  auto input = capture::CaptureSetReader::open(dir);
  ASSERT_TRUE(input.ok());
  auto a = encoder::analyse_lightfield(*input, options(1));
  ASSERT_TRUE(a.ok()) << a.status().to_string();
  ASSERT_TRUE(encoder::encode_lightfield_view(*input, *a, 1, options(1)).ok());

  EXPECT_EQ(encoder::encode_lightfield_view(*input, *a, kViews, options(1)).status().id(),
            ErrorId::kEncoderInput);
  encoder::LightfieldEncodeOptions other = options(1);
  other.cell_size = 8;  // another grid than the header's
  EXPECT_EQ(encoder::encode_lightfield_view(*input, *a, 0, other).status().id(),
            ErrorId::kEncoderInput);
  other = options(1);
  other.colour = encoder::ColourCoding::kBc7;
  EXPECT_EQ(encoder::encode_lightfield_view(*input, *a, 0, other).status().id(),
            ErrorId::kEncoderInput);
  encoder::LightfieldAnalysis edited = *a;
  edited.header.material_format = 0;
  EXPECT_EQ(encoder::encode_lightfield_view(*input, edited, 0, options(1)).status().id(),
            ErrorId::kEncoderInput);
  // Options the view pass refuses whatever the analysis.
  other = options(1);
  other.max_aabbs = 0;
  EXPECT_EQ(encoder::encode_lightfield_view(*input, *a, 0, other).status().id(),
            ErrorId::kEncoderOption);

  // View 1's depth range grows after the analysis: its depth codes would no longer mean what
  // the index chunk says.
  {
    capture::CaptureManifest m = input->manifest();
    capture::ViewFrame vf = make_frame(1, 2, -1);
    vf.depth[vf.texel_index(CubeFace::kPosY, 4, 4)] = 9.0f;
    auto w = capture::CaptureSetWriter::create(root_ / "scratch", m);
    ASSERT_TRUE(w.ok());
    ASSERT_TRUE(w->write(1, 2, vf).ok());
    fs::copy_file(root_ / "scratch" / capture::capture_file_name(m, 1, 2),
                  dir / capture::capture_file_name(m, 1, 2), fs::copy_options::overwrite_existing);
  }
  auto changed = encoder::encode_lightfield_view(*input, *a, 1, options(1));
  EXPECT_EQ(changed.status().id(), ErrorId::kEncoderInput) << changed.status().to_string();
  EXPECT_TRUE(encoder::encode_lightfield_view(*input, *a, 0, options(1)).ok());
}

// A bad image in a later view: the analysis reports the first failing view, whatever the thread
// count, and before any chunk is written.
TEST_F(LightfieldTwoPass, AnalysisReportsTheFirstFailingView) {
  const fs::path dir = make_capture("set", /*hdr_view=*/-1);
  auto input = capture::CaptureSetReader::open(dir);
  ASSERT_TRUE(input.ok());
  const capture::CaptureManifest& m = input->manifest();
  for (const uint32_t v : {2u, 1u}) {  // corrupt view 2, then also view 1
    std::ofstream(dir / capture::capture_file_name(m, v, 3), std::ios::binary) << "not an image";
    for (const uint32_t threads : {1u, 3u}) {
      auto a = encoder::analyse_lightfield(*input, options(threads));
      ASSERT_FALSE(a.ok());
      EXPECT_NE(a.status().message().find(capture::capture_file_name(m, v, 3)), std::string::npos)
          << a.status().to_string();
    }
  }
}

}  // namespace
}  // namespace calf
