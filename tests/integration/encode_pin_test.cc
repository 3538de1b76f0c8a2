// calf-encode's output pinned: the XXH3-64 of whole .calf files encoded from synthetic capture
// sets (tests/integration/synthetic_capture.h, made by code, so the same on every CPU) with every
// colour and depth coding, material, both supercompressions and 1 or 2 threads.
//
// The pinned clips are also the lightfield conformance clips (tests/conformance/lightfield/),
// which this test writes when asked (CALF_CONFORMANCE_OUT).
//
// The pins are today's bytes, recorded when the test was written (52eba46). A change that alters
// them changes the bitstream: either a bug, or an intended format change that SPEC.md documents
// and whose new pins are recorded here with the reason. The encoder's metadata names its version
// (`encoder` = "calf-encode <version>"), so a version bump changes every pin too.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <ostream>
#include <string>
#include <vector>

#include "calf/encoder/lightfield_encode.h"
#include "calf/format/container_codec.h"
#include "synthetic_capture.h"

namespace calf {
namespace {

namespace fs = std::filesystem;
using testing_support::SceneSpec;

struct PinCase {
  const char* name;
  SceneSpec scene;
  encoder::ColourCoding colour;
  encoder::DepthCoding depth;
  container::Compression compression;
  const char* xxh3;  // of the whole file, hex
  double colour_rdo =
      0;  // encoder::LightfieldEncodeOptions::colour_rdo (0: the clips frozen before it)
  uint32_t depth_keyframe_interval = 30;
  uint32_t max_aabbs = 2;  // encoder::LightfieldEncodeOptions::max_aabbs
  // CompressionOptions::compress_directory: the clips frozen before container 1.1 are 1.0 files
  // with a plain directory (their pins unchanged since); `*_zdir` clips are their 1.1 twins.
  bool compress_directory = false;
  // encoder::LightfieldEncodeOptions::bc1_fit: the earlier frozen clips use the range fit.
  encoder::Bc1Fit bc1_fit = encoder::Bc1Fit::kRange;
  // CompressionOptions::store_when_larger: the earlier frozen clips keep zstd / LZMA2
  // chunks that are larger than their raw bytes.
  bool store_when_larger = false;
};

// clang-format off
const PinCase kCases[] = {
    {"bc1_raw16_zstd",     {.face = 16, .frames = 5, .views = 2},                   encoder::ColourCoding::kBc1,     encoder::DepthCoding::kRaw16, container::Compression::kZstd,  "603c3d181206262a"},
    {"bc7_bc5_zstd_mat",   {.face = 16, .frames = 5, .views = 2, .material = true}, encoder::ColourCoding::kBc7,     encoder::DepthCoding::kBc5,   container::Compression::kZstd,  "bb7a01f58aaca148"},
    {"bc6h_raw16_lzma2",   {.face = 8, .frames = 3, .views = 2, .hdr = true},       encoder::ColourCoding::kBc6h,    encoder::DepthCoding::kRaw16, container::Compression::kLzma2, "6a0110440f9cfd42"},
    {"rgba8_raw16_none",   {.face = 8, .frames = 4, .views = 1},                    encoder::ColourCoding::kRgba8,   encoder::DepthCoding::kRaw16, container::Compression::kNone,  "26f6acc8e30259fa"},
    {"rgba16f_bc5_zstd",   {.face = 8, .frames = 3, .views = 2, .hdr = true},       encoder::ColourCoding::kRgba16f, encoder::DepthCoding::kBc5,   container::Compression::kZstd,  "aa687605ccacb1d4"},
    {"auto_raw16_static",  {.face = 16, .frames = 6, .views = 2, .animated = false, .material = true}, encoder::ColourCoding::kAuto, encoder::DepthCoding::kRaw16, container::Compression::kZstd, "382569247fa8c205"},
    // Depth format r16p (SPEC §11.1.8): the raw16 clips' scenes and codings with predicted
    // depth; they decode to their raw16 twins' hashes (lightfield_conformance_test).
    {"bc1_pred16_zstd",    {.face = 16, .frames = 5, .views = 2},                   encoder::ColourCoding::kBc1,     encoder::DepthCoding::kRaw16Predicted, container::Compression::kZstd,  "4f52fb389266f4ed"},
    {"bc6h_pred16_lzma2",  {.face = 8, .frames = 3, .views = 2, .hdr = true},       encoder::ColourCoding::kBc6h,    encoder::DepthCoding::kRaw16Predicted, container::Compression::kLzma2, "3a4515816c9670ef"},
    {"auto_pred16_static", {.face = 16, .frames = 6, .views = 2, .animated = false, .material = true}, encoder::ColourCoding::kAuto, encoder::DepthCoding::kRaw16Predicted, container::Compression::kZstd, "8792a19d652f5f4f"},
    // Static depth and material groups merged (SPEC §11.1.2): K = 2 over 7 frames.
    {"bc1_raw16_groups",   {.face = 16, .frames = 7, .views = 2, .material = true},  encoder::ColourCoding::kBc1,     encoder::DepthCoding::kRaw16, container::Compression::kZstd,  "cefa7985168c295a", 0, 2},
    // Colour RDO (docs/ENCODER.md "Colour RDO"): standard BC6H / BC7 blocks, rewritten
    // towards copies of their neighbours' bytes; same decoder, its own frozen clips.
    {"bc6h_rdo_zstd",      {.face = 16, .frames = 5, .views = 2, .hdr = true},      encoder::ColourCoding::kBc6h,    encoder::DepthCoding::kRaw16, container::Compression::kZstd,  "e40d1fb3ffd8ba6f", 4.0},
    {"bc7_rdo_zstd",       {.face = 16, .frames = 5, .views = 2},                   encoder::ColourCoding::kBc7,     encoder::DepthCoding::kRaw16, container::Compression::kZstd,  "5b143c1103044687", 4.0},
    // BC1 RDO: standard BC1 blocks with endpoints or indices of a neighbour, indices
    // re-chosen for borrowed endpoints; stored block-split as every BC1 chunk.
    {"bc1_rdo_zstd",       {.face = 16, .frames = 5, .views = 2},                   encoder::ColourCoding::kBc1,     encoder::DepthCoding::kRaw16, container::Compression::kZstd,  "43deb744d350afa1", 4.0},
    // Depth format r16pm (SPEC §11.1.9): P-frame rectangles with change masks; the
    // twins of bc1_raw16_zstd and bc1_raw16_groups, they decode to their hashes. One rectangle
    // per P-frame, so that it spans the unchanged column inside the moving square (W = 2).
    {"bc1_pred16m_zstd",   {.face = 16, .frames = 5, .views = 2},                   encoder::ColourCoding::kBc1,     encoder::DepthCoding::kRaw16PredictedMasked, container::Compression::kZstd,  "a21f65e106f413f6", 0, 30, 1},
    {"bc1_pred16m_groups", {.face = 16, .frames = 7, .views = 2, .material = true},  encoder::ColourCoding::kBc1,     encoder::DepthCoding::kRaw16PredictedMasked, container::Compression::kZstd,  "61d24cbe36d26996", 0, 2, 1},
    // Container 1.1 (SPEC §4.1): the directory as one zstd frame, the encoders'
    // default since; twins of the 1.0 clips, they decode to their hashes.
    {"bc1_raw16_zstd_zdir",   {.face = 16, .frames = 5, .views = 2},                encoder::ColourCoding::kBc1,     encoder::DepthCoding::kRaw16, container::Compression::kZstd,  "fba3ff8193f27a11", 0, 30, 2, true},
    {"bc1_pred16m_groups_zdir", {.face = 16, .frames = 7, .views = 2, .material = true}, encoder::ColourCoding::kBc1, encoder::DepthCoding::kRaw16PredictedMasked, container::Compression::kZstd, "03502347f39cf975", 0, 2, 1, true},
    // Today's defaults: BC1 by cluster fit with BC1's own RDO lambda (auto = 12; docs/ENCODER.md
    // "BC1 fit"), r16pm depth, the 1.1 directory, and chunks that zstd would enlarge (the 16-byte
    // t chunks here) stored as they are.
    {"bc1_cluster_rdo_pred16m", {.face = 16, .frames = 5, .views = 2},                 encoder::ColourCoding::kBc1,     encoder::DepthCoding::kRaw16PredictedMasked, container::Compression::kZstd, "f1c992d88578e467", encoder::kColourRdoAuto, 30, 2, true, encoder::Bc1Fit::kCluster, true},
    // Container 1.2: a capture set with coverage (format/CAPTURE.md) gets the coverage stream
    // (SPEC §11.1.11) at today's defaults; K = 2, so that groups, static runs and P-frames carry
    // coverage.
    {"coverage_bc1_pred16m", {.face = 16, .frames = 5, .views = 2, .coverage = true}, encoder::ColourCoding::kBc1, encoder::DepthCoding::kRaw16PredictedMasked, container::Compression::kZstd, "c84a73d098538a5a", encoder::kColourRdoAuto, 2, 2, true, encoder::Bc1Fit::kCluster, true},
};
// clang-format on

std::string file_hash(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  const std::vector<uint8_t> bytes{std::istreambuf_iterator<char>(in), {}};
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx",
                static_cast<unsigned long long>(container::hash64(bytes)));
  return hex;
}

void PrintTo(const PinCase& c, std::ostream* os) {
  *os << c.name;
}

class EncodePin : public ::testing::TestWithParam<PinCase> {};

TEST_P(EncodePin, OutputBytesAreUnchanged) {
  const PinCase& c = GetParam();
  std::string dir = "calf_pin_";  // append, not operator+: GCC 12 -O3 misfires -Wrestrict on it
  dir.append(std::to_string(::testing::UnitTest::GetInstance()->random_seed()));
  dir.append("_").append(c.name);
  const fs::path root = fs::temp_directory_path() / dir;
  fs::remove_all(root);
  fs::create_directories(root);
  const fs::path capture = root / "capture";
  Status st = testing_support::write_synthetic_capture(capture, c.scene);
  ASSERT_TRUE(st.ok()) << st.to_string();
  for (uint32_t threads : {1u, 2u}) {
    encoder::LightfieldEncodeOptions o;
    o.colour = c.colour;
    o.colour_rdo = c.colour_rdo;
    o.bc1_fit = c.bc1_fit;
    o.depth = c.depth;
    o.supercompression = c.compression;
    o.cell_size = 8;
    o.depth_keyframe_interval = c.depth_keyframe_interval;
    o.max_aabbs = c.max_aabbs;
    o.levels.compress_directory = c.compress_directory;
    o.levels.store_when_larger = c.store_when_larger;
    o.threads = threads;
    const fs::path out = root / (threads == 1 ? "t1.calf" : "t2.calf");
    auto stats = encoder::encode_lightfield_file(capture, out.string(), o);
    ASSERT_TRUE(stats.ok()) << stats.status().to_string();
    EXPECT_EQ(file_hash(out), c.xxh3) << c.name << " with " << threads << " thread(s)";
  }
  // The generator of the lightfield conformance clips (tests/conformance/README.md): with
  // CALF_CONFORMANCE_OUT set, the pinned clips are copied there as <name>.calf.
  if (const char* out_dir = std::getenv("CALF_CONFORMANCE_OUT")) {
    const fs::path to = fs::path(out_dir) / (std::string(c.name) + ".calf");
    std::error_code ec;
    fs::copy_file(root / "t1.calf", to, fs::copy_options::overwrite_existing, ec);
    EXPECT_FALSE(ec) << to << ": " << ec.message();
  }
  fs::remove_all(root);
}

INSTANTIATE_TEST_SUITE_P(Clips, EncodePin, ::testing::ValuesIn(kCases),
                         [](const auto& param_info) { return std::string(param_info.param.name); });

}  // namespace
}  // namespace calf
