// Encode -> decode round trips of the lightfield track (encoder/include/calf/encoder/
// lightfield_encode.h, decoder/include/calf/decoder/lightfield_reference.h, format/SPEC.md §11.1)
// on tiny synthetic capture sets written with the capture-set writer.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>
#include <vector>

#include "calf/capture/capture_set.h"
#include "calf/decoder/lightfield_reference.h"
#include "calf/encoder/colour_keyframes.h"
#include "calf/encoder/lightfield_encode.h"
#include "calf/format/container.h"
#include "calf/format/grid.h"
#include "calf/format/log_depth.h"
#include "synthetic_capture.h"

namespace calf {
namespace {

namespace fs = std::filesystem;
using testing_support::kSky;

using testing_support::SceneSpec;

class LightfieldRoundTrip : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = fs::temp_directory_path() /
            ("calf_lf_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "_" +
             ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(root_);
    fs::create_directories(root_);
  }
  void TearDown() override { fs::remove_all(root_); }

  fs::path make_capture(const SceneSpec& s, const std::string& name) {
    const fs::path dir = root_ / name;
    Status st = testing_support::write_synthetic_capture(dir, s);
    EXPECT_TRUE(st.ok()) << st.to_string();
    return dir;
  }

  encoder::LightfieldEncodeStats encode(const fs::path& capture, const fs::path& out,
                                        encoder::LightfieldEncodeOptions o) {
    auto stats = encoder::encode_lightfield_file(capture, out.string(), o);
    EXPECT_TRUE(stats.ok()) << stats.status().to_string();
    return stats.ok() ? *stats : encoder::LightfieldEncodeStats{};
  }

  static std::string slurp(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
  }

  // Decodes every view, face and frame of `file` and checks colour against Q (on the spatial
  // reference), depth against the quantised input (exactly, or within `max_rel` for BC5), and
  // material codes exactly (raw). BC1 is fitted with `bc1_fit`, as the file was encoded.
  void check_file(const fs::path& capture_dir, const fs::path& file, encoder::ColourCoding coding,
                  double q, bool exact_depth, double max_rel = 0, bool exact_material = true,
                  encoder::Bc1Fit bc1_fit = encoder::LightfieldEncodeOptions{}.bc1_fit) {
    auto reader = container::Reader::open(file.string());
    ASSERT_TRUE(reader.ok()) << reader.status().to_string();
    EXPECT_TRUE(reader->verify().empty());
    auto dec = decoder::LightfieldReference::open(*reader, 0);
    ASSERT_TRUE(dec.ok()) << dec.status().to_string();
    auto input = capture::CaptureSetReader::open(capture_dir);
    ASSERT_TRUE(input.ok());
    const auto& m = input->manifest();
    const auto& h = dec->header();
    ASSERT_EQ(h.face_size, m.face_size);
    auto cells = FaceGrid::with_cell_size(h.face_size, h.cell_size);
    ASSERT_TRUE(cells.ok());
    const bool hdr = (h.flags & 1) != 0;
    capture::ViewFrame vf;
    decoder::LightfieldFace out;
    double worst = std::numeric_limits<double>::infinity();
    for (uint32_t v = 0; v < h.view_count; ++v) {
      const auto& info = dec->view(v);
      auto range = LogDepthRange::make(info.z_near, info.z_far);
      ASSERT_TRUE(range.ok());
      for (uint32_t f = 0; f < h.frame_count; ++f) {
        ASSERT_TRUE(input->read(v, f, &vf).ok());
        for (uint32_t face = 0; face < 6; ++face) {
          Status st = dec->decode_face(v, face, f, &out);
          ASSERT_TRUE(st.ok()) << st.to_string();
          for (uint32_t c = 0; c < cells->cell_count(); ++c) {
            const PixelRect r = *cells->cell_rect(c);
            std::vector<float> orig, got;
            for (uint32_t y = r.y; y < r.y + r.height; ++y) {
              for (uint32_t x = r.x; x < r.x + r.width; ++x) {
                const size_t i = vf.texel_index(static_cast<CubeFace>(face), x, y);
                const size_t o = (size_t{y} * h.face_size + x) * 3;
                for (int k = 0; k < 3; ++k) {
                  orig.push_back(vf.color[3 * i + k]);
                  got.push_back(out.colour[o + k]);
                }
              }
            }
            std::vector<float> reference;
            ASSERT_TRUE(encoder::spatial_colour_reference(coding, bc1_fit, orig, r.width, r.height,
                                                          &reference)
                            .ok());
            const double quality =
                hdr ? encoder::psnr_log2(reference, got) : encoder::psnr_srgb(reference, got);
            worst = std::min(worst, quality);
            EXPECT_GE(quality, q) << "view " << v << " face " << face << " frame " << f << " cell "
                                  << c;
          }
          for (uint32_t y = 0; y < h.face_size; ++y) {
            for (uint32_t x = 0; x < h.face_size; ++x) {
              const size_t i = vf.texel_index(static_cast<CubeFace>(face), x, y);
              const float z = vf.depth[i];
              const uint16_t want = range->encode_unchecked(z);
              const uint16_t got = out.depth[size_t{y} * h.face_size + x];
              if (exact_depth) {
                ASSERT_EQ(got, want) << "view " << v << " face " << face << " frame " << f
                                     << " texel " << x << "," << y;
                if (std::isinf(z)) {
                  ASSERT_EQ(got, kLog16Sky);
                }
              } else if (want != kLog16Sky && got != kLog16Sky) {
                const double rel = std::abs(
                    std::expm1((static_cast<double>(got) - want) * range->relative_step()));
                ASSERT_LE(rel, max_rel * (1 + 1e-9) + 1e-12);
              }
              if (info.has_material && exact_material) {
                const size_t o = (size_t{y} * h.face_size + x) * 3;
                ASSERT_EQ(out.material[o], std::lround(vf.material[3 * i] * 255.0f));
              }
            }
          }
        }
      }
    }
    RecordProperty("worst_cell_db", std::to_string(worst));
  }

  fs::path root_;
};

TEST_F(LightfieldRoundTrip, Bc1ColourMeetsQAndRaw16DepthIsExact) {
  const fs::path cap = make_capture({}, "ldr");
  const fs::path cap32 = make_capture({.face = 32}, "ldr32");
  encoder::LightfieldEncodeOptions o;
  o.cell_size = 8;
  o.threads = 2;
  // Q bounds the temporal loss against the frames as the BC1 encoder alone makes them; the colour
  // RDO's error comes on top (docs/ENCODER.md "Colour RDO"), so Q is checked without it here and
  // the RDO below.
  o.colour_rdo = 0;
  const auto stats = encode(cap, root_ / "ldr.calf", o);
  EXPECT_EQ(stats.colour_format, static_cast<uint16_t>(container::PixelFormat::kBc1));
  EXPECT_FALSE(stats.hdr);
  EXPECT_GE(stats.min_colour_quality_db, 50.0);
  // Some cells animate (face 0 square, face 2 fade): more keyframes than cells, far fewer than
  // every frame.
  EXPECT_GT(stats.colour_keyframes, stats.colour_cells);
  EXPECT_LT(stats.colour_keyframes, stats.colour_cells * 5);
  EXPECT_GT(stats.depth_empty_pframes, 0u);
  check_file(cap, root_ / "ldr.calf", encoder::ColourCoding::kBc1, 50.0, true);
  // The default RDO (lambda 0.5) makes the colour smaller; its error per block is at most
  // lambda * 60 squared 8-bit units (bc_rdo.h), 0.625 per RGB sample, on top of Q's 0.65 (50 dB):
  // a cell's MSE is then at most 2 (0.65 + 0.625) (the two errors in the same direction), 44.1 dB.
  // Cells of 32 (64 blocks a chunk): in 8² cells a chunk is 4 blocks, too few for zstd to find
  // the copies.
  encoder::LightfieldEncodeOptions off = o, rdo = o;
  off.cell_size = rdo.cell_size = 32;
  rdo.colour_rdo = 0.5;
  const auto without = encode(cap32, root_ / "ldr32.calf", off);
  const auto with_rdo = encode(cap32, root_ / "ldr32-rdo.calf", rdo);
  EXPECT_LT(with_rdo.colour.stored, without.colour.stored);
  check_file(cap32, root_ / "ldr32-rdo.calf", encoder::ColourCoding::kBc1, 44.0, true);
}

// Every BC1 fit meets Q against its own spatial coding; the refined and cluster fits show the
// source closer than the range fit (the mean over every decoded frame and face), and auto picks
// BC1's own RDO lambda.
TEST_F(LightfieldRoundTrip, EveryBc1FitMeetsQAndTheBetterFitsShowTheSourceCloser) {
  const fs::path cap = make_capture({.face = 16, .frames = 3}, "fits");
  double source_psnr[3] = {};
  for (encoder::Bc1Fit fit :
       {encoder::Bc1Fit::kRange, encoder::Bc1Fit::kRefined, encoder::Bc1Fit::kCluster}) {
    encoder::LightfieldEncodeOptions o;
    o.cell_size = 8;
    o.colour_rdo = 0;  // Q is checked: see Bc1ColourMeetsQAndRaw16DepthIsExact
    o.bc1_fit = fit;
    const fs::path file = root_ / ("fit" + std::to_string(static_cast<int>(fit)) + ".calf");
    encode(cap, file, o);
    check_file(cap, file, encoder::ColourCoding::kBc1, 50.0, true, 0, true, fit);
    // Against the source: sRGB PSNR over every face of every frame.
    auto reader = container::Reader::open(file.string());
    ASSERT_TRUE(reader.ok());
    auto dec = decoder::LightfieldReference::open(*reader, 0);
    ASSERT_TRUE(dec.ok());
    auto input = capture::CaptureSetReader::open(cap);
    ASSERT_TRUE(input.ok());
    std::vector<float> src, got;
    capture::ViewFrame vf;
    decoder::LightfieldFace out;
    const uint32_t n = input->manifest().face_size;
    for (uint32_t v = 0; v < dec->header().view_count; ++v) {
      for (uint32_t f = 0; f < dec->header().frame_count; ++f) {
        ASSERT_TRUE(input->read(v, f, &vf).ok());
        for (uint32_t face = 0; face < 6; ++face) {
          ASSERT_TRUE(dec->decode_face(v, face, f, &out).ok());
          for (uint32_t y = 0; y < n; ++y) {
            for (uint32_t x = 0; x < n; ++x) {
              const size_t i = vf.texel_index(static_cast<CubeFace>(face), x, y);
              for (int k = 0; k < 3; ++k) {
                src.push_back(vf.color[3 * i + k]);
                got.push_back(out.colour[(size_t{y} * n + x) * 3 + k]);
              }
            }
          }
        }
      }
    }
    source_psnr[static_cast<int>(fit)] = encoder::psnr_srgb(src, got);
  }
  RecordProperty("range_db", std::to_string(source_psnr[0]));
  RecordProperty("refined_db", std::to_string(source_psnr[1]));
  RecordProperty("cluster_db", std::to_string(source_psnr[2]));
  EXPECT_GT(source_psnr[1], source_psnr[0]);
  EXPECT_GT(source_psnr[2], source_psnr[0]);
  encoder::LightfieldEncodeOptions o;
  EXPECT_EQ(encoder::colour_rdo_lambda(o, encoder::ColourCoding::kBc1), 12.0);
  EXPECT_EQ(encoder::colour_rdo_lambda(o, encoder::ColourCoding::kBc6h), 0.5);
  EXPECT_EQ(encoder::colour_rdo_lambda(o, encoder::ColourCoding::kBc7), 0.5);
  o.colour_rdo = 3;
  EXPECT_EQ(encoder::colour_rdo_lambda(o, encoder::ColourCoding::kBc1), 3.0);
}

TEST_F(LightfieldRoundTrip, EveryColourFormatAndSchemeRoundTrips) {
  const fs::path cap = make_capture({.face = 12, .frames = 4, .views = 1}, "formats");
  const std::pair<encoder::ColourCoding, container::Compression> cases[] = {
      {encoder::ColourCoding::kBc7, container::Compression::kLzma2},
      {encoder::ColourCoding::kRgba8, container::Compression::kNone},
      {encoder::ColourCoding::kRgba16f, container::Compression::kZstd},
      {encoder::ColourCoding::kBc6h, container::Compression::kZstd}};
  for (const auto& [coding, scheme] : cases) {
    encoder::LightfieldEncodeOptions o;
    o.cell_size = 8;  // 12 = one 8-cell and one 4-cell per side: edge cells included
    o.colour = coding;
    o.supercompression = scheme;
    o.min_psnr_db = 45;
    o.depth_keyframe_interval = 3;
    std::string file_name = "f";
    file_name.append(std::to_string(static_cast<int>(coding))).append(".calf");
    const fs::path file = root_ / file_name;
    encode(cap, file, o);
    check_file(cap, file, coding, 45.0, true);
  }
}

TEST_F(LightfieldRoundTrip, HdrInputChoosesBc6hAndLdrNeverPaysForHdr) {
  const fs::path hdr = make_capture({.face = 8, .frames = 3, .views = 1, .hdr = true}, "hdr");
  const fs::path ldr = make_capture({.face = 8, .frames = 3, .views = 1}, "ldr");
  encoder::LightfieldEncodeOptions o;
  o.cell_size = 8;
  const auto sh = encode(hdr, root_ / "hdr.calf", o);
  const auto sl = encode(ldr, root_ / "ldr.calf", o);
  EXPECT_EQ(sh.colour_format, static_cast<uint16_t>(container::PixelFormat::kBc6h));
  EXPECT_TRUE(sh.hdr);
  EXPECT_EQ(sl.colour_format, static_cast<uint16_t>(container::PixelFormat::kBc1));
  // BC1 keyframes are half the bytes of BC6H ones.
  EXPECT_LT(sl.colour.spatial, sh.colour.spatial);
  check_file(hdr, root_ / "hdr.calf", encoder::ColourCoding::kBc6h, 50.0, true);
}

TEST_F(LightfieldRoundTrip, OneAndTwoThreadsGiveIdenticalBytes) {
  const fs::path cap = make_capture({.material = true}, "threads");
  encoder::LightfieldEncodeOptions o;
  o.cell_size = 8;
  o.threads = 1;
  encode(cap, root_ / "t1.calf", o);
  o.threads = 2;
  encode(cap, root_ / "t2.calf", o);
  const std::string a = slurp(root_ / "t1.calf"), b = slurp(root_ / "t2.calf");
  ASSERT_FALSE(a.empty());
  EXPECT_TRUE(a == b) << "thread count changed the output";
  o.depth = encoder::DepthCoding::kBc5;
  o.threads = 1;
  encode(cap, root_ / "b1.calf", o);
  o.threads = 2;
  encode(cap, root_ / "b2.calf", o);
  EXPECT_TRUE(slurp(root_ / "b1.calf") == slurp(root_ / "b2.calf"));
}

TEST_F(LightfieldRoundTrip, StaticSceneIsOneKeyframePerCellAndEmptyPFrames) {
  const fs::path cap = make_capture({.frames = 6, .animated = false}, "static");
  encoder::LightfieldEncodeOptions o;
  o.cell_size = 8;
  o.colour_rdo = 0;  // Q is checked: see Bc1ColourMeetsQAndRaw16DepthIsExact
  const auto stats = encode(cap, root_ / "static.calf", o);
  EXPECT_EQ(stats.colour_keyframes, stats.colour_cells);
  EXPECT_EQ(stats.depth_pframes, stats.depth_empty_pframes);
  auto reader = container::Reader::open((root_ / "static.calf").string());
  ASSERT_TRUE(reader.ok());
  auto dec = decoder::LightfieldReference::open(*reader, 0);
  ASSERT_TRUE(dec.ok());
  for (uint32_t v = 0; v < 2; ++v) {
    for (uint32_t face = 0; face < 6; ++face) {
      for (uint32_t c = 0; c < 4; ++c) {
        auto tl = dec->cell_timeline(v, face, c);
        ASSERT_TRUE(tl.ok());
        EXPECT_EQ(tl->keyframes, std::vector<uint32_t>{0});
      }
      for (uint32_t t = 0; t < 4; ++t) {
        auto counts = dec->depth_rect_counts(v, face, t);
        ASSERT_TRUE(counts.ok());
        EXPECT_EQ(*counts, (std::vector<uint32_t>{1, 0, 0, 0, 0, 0}));
      }
    }
  }
  // Static content costs almost nothing: far below one keyframe per frame.
  EXPECT_LT(stats.colour.stored * 3, stats.colour.raw / 6);
  check_file(cap, root_ / "static.calf", encoder::ColourCoding::kBc1, 50.0, true);
}

TEST_F(LightfieldRoundTrip, Bc5DepthReportsItsErrorAndDecodesWithinIt) {
  const fs::path cap = make_capture({.material = true}, "bc5");
  encoder::LightfieldEncodeOptions o;
  o.cell_size = 8;
  o.colour_rdo = 0;  // Q is checked: see Bc1ColourMeetsQAndRaw16DepthIsExact
  o.depth = encoder::DepthCoding::kBc5;
  const auto stats = encode(cap, root_ / "bc5.calf", o);
  EXPECT_EQ(stats.depth_format, static_cast<uint16_t>(container::PixelFormat::kBc5));
  EXPECT_EQ(stats.material_format, static_cast<uint16_t>(container::PixelFormat::kBc1));
  EXPECT_GE(stats.depth_max_rel_error, stats.depth_mean_rel_error);
  EXPECT_LT(stats.depth_max_rel_error, 1.0);
  RecordProperty("bc5_max_rel", std::to_string(stats.depth_max_rel_error));
  RecordProperty("bc5_mean_rel", std::to_string(stats.depth_mean_rel_error));
  check_file(cap, root_ / "bc5.calf", encoder::ColourCoding::kBc1, 50.0, false,
             stats.depth_max_rel_error, false);
}

TEST_F(LightfieldRoundTrip, MaterialOnlyWhereAViewSeesIt) {
  const fs::path cap = make_capture({.material = true}, "material");
  encoder::LightfieldEncodeOptions o;
  o.cell_size = 8;
  o.colour_rdo = 0;  // Q is checked: see Bc1ColourMeetsQAndRaw16DepthIsExact
  const auto stats = encode(cap, root_ / "m.calf", o);
  EXPECT_EQ(stats.material_views, 2u);
  EXPECT_EQ(stats.material_format, static_cast<uint16_t>(container::PixelFormat::kRgba8));
  check_file(cap, root_ / "m.calf", encoder::ColourCoding::kBc1, 50.0, true);
  // A set with material channels but no reflective texel gets no material stream.
  const fs::path plain = make_capture({.face = 8, .frames = 2, .views = 1}, "plain");
  const auto s2 = encode(plain, root_ / "p.calf", o);
  EXPECT_EQ(s2.material_views, 0u);
  EXPECT_EQ(s2.material_format, 0u);
}

TEST_F(LightfieldRoundTrip, BadInputNamesTheFileAndWritesNothing) {
  const fs::path cap = make_capture({.face = 8, .frames = 3}, "bad");
  encoder::LightfieldEncodeOptions o;
  o.cell_size = 8;
  // A missing image (NaN / negative depth pixels are rejected by the capture reader with the
  // file, face and texel named: tests/capture/capture_set_test.cc).
  {
    const fs::path bad = root_ / "missing";
    auto in = capture::CaptureSetReader::open(cap);
    ASSERT_TRUE(in.ok());
    fs::copy(cap, bad);
    fs::path victim = bad / capture::capture_file_name(in->manifest(), 1, 2);
    fs::remove(victim);
    auto r = encoder::encode_lightfield_file(bad, (root_ / "nan.calf").string(), o);
    ASSERT_FALSE(r.ok());
    EXPECT_NE(r.status().message().find("view001_frame00002"), std::string::npos)
        << r.status().to_string();
    EXPECT_FALSE(fs::exists(root_ / "nan.calf"));
  }
  {
    encoder::LightfieldEncodeOptions bad_options = o;
    bad_options.cell_size = 6;
    auto r = encoder::encode_lightfield_file(cap, (root_ / "opt.calf").string(), bad_options);
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.status().id(), ErrorId::kEncoderOption);
    EXPECT_FALSE(fs::exists(root_ / "opt.calf"));
  }
  // Any leftover temporary file would show up here.
  for (const auto& e : fs::directory_iterator(root_)) {
    EXPECT_EQ(e.path().extension() != ".calf" || fs::exists(e.path()), true);
    EXPECT_EQ(e.path().string().find(".tmp"), std::string::npos) << e.path();
  }
}

}  // namespace
}  // namespace calf
