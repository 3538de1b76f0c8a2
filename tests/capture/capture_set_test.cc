// Capture-set images (format/CAPTURE.md "Images"): writer -> reader round trip of every channel,
// the writer's refusals, and one reader error per malformed-file case, each naming the file and,
// for pixels, the face and texel.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <OpenImageIO/imageio.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>
#include <thread>
#include <vector>

#include "calf/capture/capture_set.h"

namespace calf::capture {
namespace {

namespace fs = std::filesystem;
constexpr float kInf = std::numeric_limits<float>::infinity();

class CaptureSetTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("calf_capture_set_test_" +
            std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  static CaptureManifest manifest(bool material) {
    CaptureManifest m;
    m.frame_count = 2;
    m.fps = 30;
    m.face_size = 4;
    m.view_volume = {{0, 0, 0}, {1, 1, 1}};
    m.viewpoints = {{"a", {0, 0, 0}}, {"b", {1, 1, 1}}};
    m.material = material;
    return m;
  }

  // Values exactly representable in half, different per view, frame and texel; sky on face -Z.
  static ViewFrame frame_data(uint32_t view, uint32_t frame, bool material) {
    ViewFrame f;
    f.resize(4, material);
    for (size_t i = 0; i < f.texel_count(); ++i) {
      for (int c = 0; c < 3; ++c)
        f.color[3 * i + c] = static_cast<float>((i + c + view) % 8) * 0.25f;
      f.depth[i] =
          i >= 5 * 16 ? kInf : 0.5f + static_cast<float>(i) * 0.1f + static_cast<float>(frame);
      if (material) {
        f.material[3 * i] = (i % 2) ? 0.5f : 0.0f;
        f.material[3 * i + 1] = (i % 3 == 0) ? 0.25f : 0.0f;
        f.material[3 * i + 2] = 1.5f;
      }
    }
    return f;
  }

  void write_set(bool material) {
    auto w = CaptureSetWriter::create(dir_, manifest(material));
    ASSERT_TRUE(w.ok()) << w.status().to_string();
    for (uint32_t v = 0; v < 2; ++v) {
      for (uint32_t f = 0; f < 2; ++f) ASSERT_TRUE(w->write(v, f, frame_data(v, f, material)).ok());
    }
    ASSERT_TRUE(w->finish().ok());
  }

  // Writes an image directly with OIIO, bypassing the writer's validation.
  static void write_raw(const fs::path& path, int width, int height,
                        const std::vector<std::string>& channels, float fill, int bad_channel = -1,
                        int bad_x = 0, int bad_y = 0, float bad = 0) {
    auto out = OIIO::ImageOutput::create("exr");
    OIIO::ImageSpec spec(width, height, static_cast<int>(channels.size()), OIIO::TypeDesc::FLOAT);
    spec.channelnames = channels;
    spec.alpha_channel = -1;
    spec.z_channel = -1;
    std::vector<float> px(static_cast<size_t>(width) * height * channels.size(), fill);
    if (bad_channel >= 0)
      px[(static_cast<size_t>(bad_y) * width + bad_x) * channels.size() + bad_channel] = bad;
    ASSERT_TRUE(out->open(path.string(), spec));
    ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, px.data()));
    ASSERT_TRUE(out->close());
  }

  void expect_read_error(ErrorId id, const std::string& needle) {
    auto r = CaptureSetReader::open(dir_);
    ASSERT_TRUE(r.ok()) << r.status().to_string();
    ViewFrame f;
    Status s = r->read(1, 0, &f);
    EXPECT_EQ(s.id(), id) << s.to_string();
    EXPECT_NE(s.message().find(needle), std::string::npos) << s.to_string();
    EXPECT_NE(s.message().find("view001_frame00000.exr"), std::string::npos) << s.to_string();
  }

  fs::path image(uint32_t view, uint32_t frame) const {
    return dir_ / capture_file_name(manifest(false), view, frame);
  }

  fs::path dir_;
};

TEST_F(CaptureSetTest, RoundTripEveryChannel) {
  for (bool material : {false, true}) {
    fs::remove_all(dir_);
    write_set(material);
    auto r = CaptureSetReader::open(dir_);
    ASSERT_TRUE(r.ok()) << r.status().to_string();
    EXPECT_EQ(r->manifest(), manifest(material));
    EXPECT_TRUE(r->check_files().ok());
    ViewFrame got;  // reused across reads, as an encoder would
    for (uint32_t v = 0; v < 2; ++v) {
      for (uint32_t f = 0; f < 2; ++f) {
        ASSERT_TRUE(r->read(v, f, &got).ok());
        ViewFrame want = frame_data(v, f, material);
        EXPECT_EQ(got.face_size, 4u);
        EXPECT_EQ(got.has_material, material);
        EXPECT_EQ(got.color, want.color);
        EXPECT_EQ(got.depth, want.depth);  // float depth: exact, +inf kept
        EXPECT_EQ(got.material, want.material);
      }
    }
    EXPECT_EQ(r->read(2, 0, &got).id(), ErrorId::kCaptureIndex);
    EXPECT_EQ(r->read(0, 2, &got).id(), ErrorId::kCaptureIndex);
  }
}

TEST_F(CaptureSetTest, ImageLayoutIsAVerticalStripInGlFaceOrder) {
  write_set(false);
  auto in = OIIO::ImageInput::open(image(0, 1).string());
  ASSERT_TRUE(in);
  EXPECT_EQ(in->spec().width, 4);
  EXPECT_EQ(in->spec().height, 24);
  int z = -1;
  for (int c = 0; c < in->spec().nchannels; ++c) {
    if (in->spec().channelnames[c] == "Z") z = c;
  }
  ASSERT_GE(z, 0);
  EXPECT_EQ(in->spec().channelformat(z), OIIO::TypeDesc::FLOAT);
  std::vector<float> px(4 * 24 * in->spec().nchannels);
  ASSERT_TRUE(in->read_image(0, 0, 0, in->spec().nchannels, OIIO::TypeDesc::FLOAT, px.data()));
  // Face -Y (index 3), texel (2, 1) is image row 3 * 4 + 1, column 2.
  size_t i = (3 * 4 + 1) * 4 + 2;
  EXPECT_EQ(px[i * in->spec().nchannels + z], frame_data(0, 1, false).depth[i]);
}

TEST_F(CaptureSetTest, BytesDependOnPixelsOnlyNotOnTheClock) {
  // OIIO would stamp the wall-clock time into the header; two writes a second apart must match.
  auto read_bytes = [](const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  };
  write_set(true);
  std::string first = read_bytes(image(1, 1));
  std::this_thread::sleep_for(std::chrono::milliseconds(1100));
  fs::remove_all(dir_);
  write_set(true);
  EXPECT_EQ(read_bytes(image(1, 1)), first);
}

TEST_F(CaptureSetTest, WriterRefusals) {
  auto w = CaptureSetWriter::create(dir_, manifest(false));
  ASSERT_TRUE(w.ok());
  ViewFrame wrong = frame_data(0, 0, true);
  EXPECT_EQ(w->write(0, 0, wrong).id(), ErrorId::kCaptureWriterMisuse);
  ViewFrame nan = frame_data(0, 0, false);
  nan.depth[7] = std::nanf("");
  Status s = w->write(0, 0, nan);
  EXPECT_EQ(s.id(), ErrorId::kCaptureDepthPixel);
  EXPECT_NE(s.message().find("face +X texel (3, 1)"), std::string::npos) << s.to_string();
  ViewFrame hot = frame_data(0, 0, false);
  hot.color[0] = 70000;  // would overflow half to +inf
  EXPECT_EQ(w->write(0, 0, hot).id(), ErrorId::kCaptureColourPixel);
  EXPECT_FALSE(fs::exists(image(0, 0)));
  ASSERT_TRUE(w->write(0, 0, frame_data(0, 0, false)).ok());
  EXPECT_EQ(w->write(0, 0, frame_data(0, 0, false)).id(), ErrorId::kCaptureWriterMisuse);
  EXPECT_EQ(w->write(5, 0, frame_data(0, 0, false)).id(), ErrorId::kCaptureIndex);
  // Incomplete: finish refuses and no manifest appears.
  EXPECT_EQ(w->finish().id(), ErrorId::kCaptureWriterMisuse);
  EXPECT_FALSE(fs::exists(dir_ / kManifestFileName));
  w->abandon();
  EXPECT_FALSE(fs::exists(image(0, 0)));
}

TEST_F(CaptureSetTest, RewritingRemovesTheOldManifestFirst) {
  write_set(false);
  ASSERT_TRUE(fs::exists(dir_ / kManifestFileName));
  auto w = CaptureSetWriter::create(dir_, manifest(false));
  ASSERT_TRUE(w.ok());
  EXPECT_FALSE(fs::exists(dir_ / kManifestFileName));
  EXPECT_EQ(CaptureSetReader::open(dir_).status().id(), ErrorId::kFileOpen);
}

TEST_F(CaptureSetTest, MissingImage) {
  write_set(false);
  fs::remove(image(1, 0));
  auto r = CaptureSetReader::open(dir_);
  ASSERT_TRUE(r.ok());
  Status s = r->check_files();
  EXPECT_EQ(s.id(), ErrorId::kCaptureFileMissing);
  EXPECT_NE(s.message().find("view 1, frame 0"), std::string::npos) << s.to_string();
  expect_read_error(ErrorId::kCaptureFileMissing, "no such file");
}

// A directory or a FIFO under an image's name is "not a regular file", not "missing"; the FIFO
// is never opened (opening it would block).
TEST_F(CaptureSetTest, ImageThatIsNotARegularFile) {
  write_set(false);
  fs::remove(image(1, 0));
  fs::create_directories(image(1, 0));
  auto r = CaptureSetReader::open(dir_);
  ASSERT_TRUE(r.ok());
  Status s = r->check_files();
  EXPECT_EQ(s.id(), ErrorId::kFileOpen);
  EXPECT_NE(s.message().find("not a regular file (a directory) (view 1, frame 0)"),
            std::string::npos)
      << s.to_string();
  expect_read_error(ErrorId::kFileOpen, "not a regular file (a directory)");
  fs::remove(image(1, 0));
  ASSERT_EQ(::mkfifo(image(1, 0).c_str(), 0600), 0);
  EXPECT_EQ(r->check_files().id(), ErrorId::kFileOpen);
  expect_read_error(ErrorId::kFileOpen, "not a regular file (a FIFO)");
}

// Bytes of another format under an .exr name are refused before the image library sees them
// (OIIO would try every format, and libpng prints its own errors on stderr).
TEST_F(CaptureSetTest, OtherFormatUnderExrName) {
  write_set(false);
  const unsigned char png[] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n', 0, 0, 0, 13};
  std::ofstream(image(1, 0), std::ios::trunc | std::ios::binary)
      .write(reinterpret_cast<const char*>(png), sizeof png);
  expect_read_error(ErrorId::kCaptureImageFormat, "not an OpenEXR file");
}

TEST_F(CaptureSetTest, NotAnImage) {
  write_set(false);
  std::ofstream(image(1, 0), std::ios::trunc) << "this is not an EXR file";
  expect_read_error(ErrorId::kCaptureImageFormat, "not an OpenEXR file");
}

// OpenEXR sizes its line-offset table by the declared data window: a 90-byte file declaring
// 2^28 rows made it allocate 2 GB (found by capture_view_frame_fuzz). The header is checked first.
TEST_F(CaptureSetTest, HeaderDeclaringMoreRowsThanTheFileHolds) {
  write_set(false);
  std::string exr("\x76\x2f\x31\x01\x02\x00\x00\x00", 8);
  auto attribute = [&](const std::string& name, const std::string& type, const std::string& value) {
    exr += name + '\0' + type + '\0';
    const int32_t size = static_cast<int32_t>(value.size());
    exr.append(reinterpret_cast<const char*>(&size), 4);
    exr += value;
  };
  const int32_t window[4] = {0, 0, 3, (1 << 28) - 1};
  attribute("dataWindow", "box2i", std::string(reinterpret_cast<const char*>(window), 16));
  attribute("compression", "compression", std::string(1, '\0'));
  exr += '\0';
  std::ofstream(image(1, 0), std::ios::binary | std::ios::trunc) << exr;
  expect_read_error(ErrorId::kCaptureImageFormat, "larger than any calf image");
  const int32_t tall[4] = {0, 0, 3, 90000};
  exr.replace(exr.find("box2i") + 10, 16, std::string(reinterpret_cast<const char*>(tall), 16));
  std::ofstream(image(1, 0), std::ios::binary | std::ios::trunc) << exr;
  expect_read_error(ErrorId::kCaptureImageFormat, "90001 rows need 90001 chunk offsets");
  std::string tiled = exr;
  tiled[5] = 0x02;  // version flags: tiled
  std::ofstream(image(1, 0), std::ios::binary | std::ios::trunc) << tiled;
  expect_read_error(ErrorId::kCaptureImageFormat, "single-part scanline");
}

// A PNG (or any other image) named .exr never reaches another format's decoder: it is refused by
// its magic bytes, so that no library prints its own line.
TEST_F(CaptureSetTest, ImageOfAnotherFormatNamedExr) {
  write_set(false);
  auto out = OIIO::ImageOutput::create("png");
  ASSERT_TRUE(out);
  const fs::path png = dir_ / "image.png";
  OIIO::ImageSpec spec(4, 24, 3, OIIO::TypeDesc::UINT8);
  std::vector<uint8_t> px(4 * 24 * 3, 128);
  ASSERT_TRUE(out->open(png.string(), spec));
  ASSERT_TRUE(out->write_image(OIIO::TypeDesc::UINT8, px.data()));
  ASSERT_TRUE(out->close());
  fs::rename(png, image(1, 0));
  expect_read_error(ErrorId::kCaptureImageFormat, "not an OpenEXR file");
}

TEST_F(CaptureSetTest, TruncatedImage) {
  write_set(false);
  fs::resize_file(image(1, 0), fs::file_size(image(1, 0)) / 2);
  expect_read_error(ErrorId::kCaptureImageFormat, "");
}

TEST_F(CaptureSetTest, WrongSize) {
  write_set(false);
  write_raw(image(1, 0), 4, 20, {"R", "G", "B", "Z"}, 1.0f);
  expect_read_error(ErrorId::kCaptureImageFormat, "4 x 20, expected 4 x 24");
}

TEST_F(CaptureSetTest, MissingDepthChannel) {
  write_set(false);
  write_raw(image(1, 0), 4, 24, {"R", "G", "B"}, 1.0f);
  expect_read_error(ErrorId::kCaptureImageFormat, "channel 'Z' is missing");
}

// CAPTURE.md allows HALF and FLOAT channels only: the image library would read a UINT channel
// normalised to [0, 1] (depth 3 as ~7e-10), a silent misread.
TEST_F(CaptureSetTest, UintChannelsAreRefused) {
  for (const char* bad : {"Z", "G"}) {
    write_set(false);
    auto out = OIIO::ImageOutput::create("exr");
    ASSERT_TRUE(out);
    const std::vector<std::string> names = {"R", "G", "B", "Z"};
    OIIO::ImageSpec spec(4, 24, 4, OIIO::TypeDesc::FLOAT);
    spec.channelnames = names;
    spec.channelformats.clear();
    for (const std::string& n : names) {
      spec.channelformats.push_back(n == bad ? OIIO::TypeDesc::UINT : OIIO::TypeDesc::FLOAT);
    }
    spec.alpha_channel = -1;
    spec.z_channel = -1;
    std::vector<uint32_t> px(4 * 24 * 4, 3);
    ASSERT_TRUE(out->open(image(1, 0).string(), spec));
    ASSERT_TRUE(out->write_image(OIIO::TypeDesc::UINT, px.data()));
    ASSERT_TRUE(out->close());
    {
      auto in = OIIO::ImageInput::open(image(1, 0).string());
      ASSERT_TRUE(in);
      EXPECT_EQ(in->spec().channelformat(bad[0] == 'Z' ? 3 : 1), OIIO::TypeDesc::UINT);
    }
    expect_read_error(ErrorId::kCaptureImageFormat,
                      std::string("channel '") + bad + "' has pixel type uint");
  }
}

TEST_F(CaptureSetTest, UnannouncedMaterial) {
  write_set(false);
  write_raw(image(1, 0), 4, 24,
            {"R", "G", "B", "Z", "material.reflect", "material.refract", "material.ior"}, 1.0f);
  expect_read_error(ErrorId::kCaptureImageFormat, "\"material\": false");
}

TEST_F(CaptureSetTest, MissingMaterial) {
  write_set(true);
  write_raw(image(1, 0), 4, 24, {"R", "G", "B", "Z"}, 1.0f);
  expect_read_error(ErrorId::kCaptureImageFormat, "material.reflect' is missing");
}

TEST_F(CaptureSetTest, BadDepthPixels) {
  // Image row 5 = face -X (1), y = 1.
  for (float bad : {std::nanf(""), -1.0f, 0.0f, -kInf}) {
    fs::remove_all(dir_);
    write_set(false);
    write_raw(image(1, 0), 4, 24, {"R", "G", "B", "Z"}, 1.0f, 3, 2, 5, bad);
    expect_read_error(ErrorId::kCaptureDepthPixel, "face -X texel (2, 1)");
  }
}

TEST_F(CaptureSetTest, BadColourPixels) {
  for (float bad : {std::nanf(""), kInf, -0.5f}) {
    fs::remove_all(dir_);
    write_set(false);
    write_raw(image(1, 0), 4, 24, {"R", "G", "B", "Z"}, 1.0f, 1, 0, 23, bad);
    expect_read_error(ErrorId::kCaptureColourPixel, "face -Z texel (0, 3): colour channel G");
  }
}

TEST_F(CaptureSetTest, BadMaterialPixels) {
  // reflect > 1, refract < 0, IOR 0.
  const std::vector<std::string> ch = {
      "R", "G", "B", "Z", "material.reflect", "material.refract", "material.ior"};
  for (auto [channel, bad] : {std::pair{4, 1.5f}, std::pair{5, -0.25f}, std::pair{6, 0.0f}}) {
    fs::remove_all(dir_);
    write_set(true);
    write_raw(image(1, 0), 4, 24, ch, 0.5f, channel, 1, 4, bad);
    expect_read_error(ErrorId::kCaptureMaterialPixel, "face -X texel (1, 0)");
  }
}

// Coverage (format/CAPTURE.md "Coverage"): a version-2 set round-trips its coverage channels; a
// version-1 set reads with none; shares out of range, a mask that is not an integer 0..65535, a
// missing or unannounced channel, and a coverage key in a version-1 manifest are refused.
TEST_F(CaptureSetTest, CoverageRoundTripAndRefusals) {
  CaptureManifest m = manifest(false);
  m.version = kCaptureCoverageVersion;
  m.coverage = true;
  const auto with_coverage = [](uint32_t view, uint32_t frame) {
    ViewFrame f = frame_data(view, frame, false);
    const ViewFrame base = f;
    f.resize(4, false, true);
    f.color = base.color;
    f.depth = base.depth;
    for (size_t i = 0; i < f.texel_count(); ++i) {
      f.coverage[3 * i] = static_cast<float>(i % 5) / 16;
      f.coverage[3 * i + 1] = static_cast<float>(i % 3) / 16;
      f.coverage[3 * i + 2] = static_cast<float>((i * 4099) % 65536);
    }
    return f;
  };
  {
    auto w = CaptureSetWriter::create(dir_, m);
    ASSERT_TRUE(w.ok()) << w.status().to_string();
    EXPECT_EQ(w->write(0, 0, frame_data(0, 0, false)).id(), ErrorId::kCaptureWriterMisuse);
    ViewFrame bad = with_coverage(0, 0);
    bad.coverage[3 * 7] = 0.75f;
    bad.coverage[3 * 7 + 1] = 0.5f;  // near + far > 1
    Status s = w->write(0, 0, bad);
    EXPECT_EQ(s.id(), ErrorId::kCaptureImageFormat) << s.to_string();
    EXPECT_NE(s.message().find("face +X texel (3, 1): coverage"), std::string::npos)
        << s.to_string();
    bad = with_coverage(0, 0);
    bad.coverage[3 * 7 + 2] = 2.5f;  // not an integer mask
    EXPECT_EQ(w->write(0, 0, bad).id(), ErrorId::kCaptureImageFormat);
    for (uint32_t v = 0; v < 2; ++v) {
      for (uint32_t f = 0; f < 2; ++f) ASSERT_TRUE(w->write(v, f, with_coverage(v, f)).ok());
    }
    ASSERT_TRUE(w->finish().ok());
  }
  auto r = CaptureSetReader::open(dir_);
  ASSERT_TRUE(r.ok()) << r.status().to_string();
  EXPECT_EQ(r->manifest(), m);
  ViewFrame got;
  ASSERT_TRUE(r->read(1, 1, &got).ok());
  EXPECT_TRUE(got.has_coverage);
  EXPECT_EQ(got.coverage, with_coverage(1, 1).coverage);
  EXPECT_EQ(got.color, with_coverage(1, 1).color);
  // A mask that is not an integer (0.25 everywhere), in a file written past the writer.
  const std::vector<std::string> channels = {
      "R", "G", "B", "Z", "coverage.near", "coverage.far", "coverage.mask"};
  write_raw(image(1, 0), 4, 24, channels, 0.25f);
  expect_read_error(ErrorId::kCaptureImageFormat, "face +X texel (0, 0): coverage");
  write_raw(image(1, 0), 4, 24, {"R", "G", "B", "Z", "coverage.near", "coverage.far"}, 0.0f);
  expect_read_error(ErrorId::kCaptureImageFormat, "coverage.mask' is missing");
  // A version-1 set: no coverage key, and a coverage channel is refused.
  fs::remove_all(dir_);
  write_set(false);
  ASSERT_TRUE(CaptureSetReader::open(dir_)->read(1, 0, &got).ok());
  EXPECT_FALSE(got.has_coverage);
  EXPECT_TRUE(got.coverage.empty());
  write_raw(image(1, 0), 4, 24, channels, 0.5f);
  expect_read_error(ErrorId::kCaptureImageFormat, "does not say \"coverage\": true");
  CaptureManifest v1 = manifest(false);
  v1.coverage = true;
  EXPECT_EQ(validate_manifest(v1).id(), ErrorId::kManifestVersion);
  std::string json = serialize_manifest(manifest(false));
  json.replace(json.find("\"material\""), 0, "\"coverage\": true, ");
  EXPECT_EQ(parse_manifest(json, "m").status().id(), ErrorId::kManifestField);
  m.coverage = false;  // version 2 without coverage: valid, and says so
  EXPECT_NE(serialize_manifest(m).find("\"coverage\": false"), std::string::npos);
  EXPECT_EQ(*parse_manifest(serialize_manifest(m), "m"), m);
  // Version 1 manifests serialize as before: no coverage key.
  EXPECT_EQ(serialize_manifest(manifest(false)).find("coverage"), std::string::npos);
}

TEST_F(CaptureSetTest, MissingOrBrokenManifest) {
  EXPECT_EQ(CaptureSetReader::open(dir_).status().id(), ErrorId::kFileOpen);
  fs::create_directories(dir_);
  std::ofstream(dir_ / kManifestFileName) << "{\"format\": \"calf-capture-set\", \"version\": 1}";
  auto r = CaptureSetReader::open(dir_);
  EXPECT_EQ(r.status().id(), ErrorId::kManifestField);
  EXPECT_NE(r.status().message().find("manifest.json"), std::string::npos);
}

}  // namespace
}  // namespace calf::capture
