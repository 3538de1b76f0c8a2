// The image budget and the header rule where images enter (calf/capture/image_budget.h,
// scene_file.h's texture readers): a PNG is measured from its header before a buffer exists,
// libpng's errors come back as one Status and never reach stderr, and the PNG kinds calf reads
// decode to the bytes the PNG specification gives them; an OpenEXR header is walked before OpenEXR
// reads it, in memory and in a file.
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <span>
#include <string>

#include "../scratch_dir.h"
#include "calf/capture/image_budget.h"
#include "calf/capture/ingest.h"
#include "calf/capture/scene_file.h"
#include "hostile_images.h"

namespace calf::capture {
namespace {

namespace fs = std::filesystem;
using calf::test::exr_header_only;
using calf::test::exr_with;
using calf::test::png_chunk;
using calf::test::png_declaring;
using calf::test::png_file;
using calf::test::put_le32;
using calf::test::zlib_stored;

std::span<const uint8_t> bytes_of(const std::string& s) {
  return {reinterpret_cast<const uint8_t*>(s.data()), s.size()};
}

fs::path write(const std::string& name, const std::string& bytes) {
  const fs::path p = calf::test::scratch_dir("image_budget_test") / name;
  std::ofstream(p, std::ios::binary) << bytes;
  return p;
}

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

TEST(ImageBudget, CountsPixelsAndNamesTheOption) {
  EXPECT_TRUE(check_image_budget("x", 8192, 8192, kDefaultMaxImagePixels).ok());
  const Status s = check_image_budget("faces", 4096, 4096, kDefaultMaxImagePixels, 6);
  EXPECT_EQ(s.id(), ErrorId::kImageBudget);
  EXPECT_NE(s.message().find("6 x 4096 x 4096 = 100663296 pixels"), std::string::npos)
      << s.message();
  EXPECT_NE(s.message().find("--max-image-pixels"), std::string::npos);
}

// A PNG of 100 bytes that declares 16384 x 16384: refused from its chunks (deflate cannot expand
// 64 bytes of image data to 1 GB), before any buffer; it used to allocate 1 GB and take seconds.
TEST(PngHeader, HugeDeclarationOverFewBytesIsRefusedAtOnce) {
  const std::string png = png_declaring(16384, 16384);
  ASSERT_LT(png.size(), 200u);
  const auto start = std::chrono::steady_clock::now();
  SceneTexture t;
  Status s = decode_texture_image(bytes_of(png), "", "embedded", &t, uint64_t{1} << 28);
  EXPECT_EQ(s.id(), ErrorId::kSceneFileTexture) << s.to_string();
  EXPECT_NE(s.message().find("more than its"), std::string::npos) << s.message();
  s = read_texture_image(write("declaring.png", png), &t, uint64_t{1} << 28);
  EXPECT_EQ(s.id(), ErrorId::kSceneFileTexture) << s.to_string();
  EXPECT_TRUE(t.rgba.empty());
  EXPECT_LT(seconds_since(start), 1.0);
}

// The same file under the default budget (2^26 pixels): E012, naming the option.
TEST(PngHeader, OverTheBudgetIsE012) {
  SceneTexture t;
  const Status s = decode_texture_image(bytes_of(png_declaring(16384, 16384)), "", "big", &t);
  EXPECT_EQ(s.id(), ErrorId::kImageBudget) << s.to_string();
  EXPECT_NE(s.message().find("16384 x 16384 = 268435456 pixels"), std::string::npos);
  // 8192 x 8193 is one row over 2^26.
  EXPECT_EQ(decode_texture_image(bytes_of(png_declaring(8192, 8193)), "", "b", &t).id(),
            ErrorId::kImageBudget);
  EXPECT_EQ(
      decode_texture_image(bytes_of(png_declaring(8192, 8193)), "", "b", &t, uint64_t{8192} * 8193)
          .id(),
      ErrorId::kSceneFileTexture);  // within the budget: then its missing data
  EXPECT_EQ(decode_texture_image(bytes_of(png_declaring(16385, 1)), "", "wide", &t).id(),
            ErrorId::kSceneFileTexture);  // wider than any calf image
}

// A plausible PNG whose image data stops half way: libpng's error is the one Status, and nothing
// is printed (OpenImageIO's PNG reader let libpng print "libpng error: ..." to stderr).
TEST(PngHeader, LibpngErrorsAreOneStatusAndSilent) {
  const uint32_t w = 64, h = 64;
  std::string raw;
  for (uint32_t y = 0; y < h; ++y) raw += '\0' + std::string(4 * w, '\x7f');
  const std::string stream = zlib_stored(raw);
  const std::string cut = png_file(w, h, 8, 6, stream.substr(0, stream.size() / 2));
  testing::internal::CaptureStderr();
  SceneTexture t;
  const Status memory = decode_texture_image(bytes_of(cut), "", "cut", &t);
  const Status file = read_texture_image(write("cut.png", cut), &t);
  const std::string printed = testing::internal::GetCapturedStderr();
  EXPECT_EQ(memory.id(), ErrorId::kSceneFileTexture) << memory.to_string();
  EXPECT_EQ(file.id(), ErrorId::kSceneFileTexture) << file.to_string();
  EXPECT_NE(memory.message().find("cannot be decoded"), std::string::npos) << memory.message();
  EXPECT_EQ(printed, "");
  // A bad CRC too.
  std::string crc = png_file(w, h, 8, 6, stream);
  crc[29] ^= 1;  // the IHDR chunk's CRC
  testing::internal::CaptureStderr();
  EXPECT_EQ(decode_texture_image(bytes_of(crc), "", "crc", &t).id(), ErrorId::kSceneFileTexture);
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "");
  // Not a PNG past its signature.
  EXPECT_EQ(decode_texture_image(bytes_of(std::string("\x89PNG\r\n\x1a\n", 8) + "garbage"), "",
                                 "short", &t)
                .id(),
            ErrorId::kSceneFileTexture);
}

// The PNG kinds calf reads, decoded to SCENE.md's RGBA (values from the PNG specification).
TEST(PngDecode, GreyPaletteColourKeyAndSixteenBit) {
  SceneTexture t;
  // 8-bit grey 16, 32: grey spreads to RGB, alpha opaque.
  ASSERT_TRUE(
      decode_texture_image(bytes_of(png_file(2, 1, 8, 0, zlib_stored({0, 16, 32}))), "", "g", &t)
          .ok());
  EXPECT_EQ(t.rgba, (std::vector<uint8_t>{16, 16, 16, 255, 32, 32, 32, 255}));
  // 1-bit grey 1, 0 -> 255, 0.
  ASSERT_TRUE(
      decode_texture_image(bytes_of(png_file(2, 1, 1, 0, zlib_stored({0, '\x80'}))), "", "g1", &t)
          .ok());
  EXPECT_EQ(t.rgba, (std::vector<uint8_t>{255, 255, 255, 255, 0, 0, 0, 255}));
  // Palette red, green with tRNS 128 for entry 0.
  const std::string plte = png_chunk("PLTE", std::string("\xff\0\0\0\xff\0", 6)) +
                           png_chunk("tRNS", std::string("\x80", 1));
  ASSERT_TRUE(decode_texture_image(bytes_of(png_file(2, 1, 8, 3, zlib_stored({0, 0, 1}), plte)), "",
                                   "p", &t)
                  .ok());
  EXPECT_EQ(t.rgba, (std::vector<uint8_t>{255, 0, 0, 128, 0, 255, 0, 255}));
  // Grey + alpha.
  ASSERT_TRUE(
      decode_texture_image(bytes_of(png_file(1, 1, 8, 4, zlib_stored({0, 10, 20}))), "", "ga", &t)
          .ok());
  EXPECT_EQ(t.rgba, (std::vector<uint8_t>{10, 10, 10, 20}));
  // 16-bit grey 0x1234 = 4660: 4660 * 255 / 65535 = 18.1 -> 18.
  ASSERT_TRUE(decode_texture_image(bytes_of(png_file(1, 1, 16, 0, zlib_stored({0, 0x12, 0x34}))),
                                   "", "g16", &t)
                  .ok());
  EXPECT_EQ(t.rgba, (std::vector<uint8_t>{18, 18, 18, 255}));
  EXPECT_EQ(t.width, 1u);
}

// Checks that an in-memory texture, the same bytes as a texture file, and the same file as a
// Seurat image all give their reader's id with `message` in it.
void expect_refused(const std::string& exr, const std::string& message) {
  SceneTexture t;
  const Status memory = decode_texture_image(bytes_of(exr), "exr", "embedded", &t);
  EXPECT_EQ(memory.id(), ErrorId::kSceneFileTexture) << memory.to_string();
  EXPECT_NE(memory.message().find(message), std::string::npos) << memory.message();
  EXPECT_TRUE(t.rgba.empty());
  const fs::path file = write("hostile.exr", exr);
  const Status from_file = read_texture_image(file, &t);
  EXPECT_EQ(from_file.id(), ErrorId::kSceneFileTexture) << from_file.to_string();
  EXPECT_NE(from_file.message().find(message), std::string::npos) << from_file.message();
  // The same bytes without the .exr name: found by their magic number.
  const Status unnamed = read_texture_image(write("hostile.img", exr), &t);
  EXPECT_NE(unnamed.message().find(message), std::string::npos) << unnamed.message();
  // The capture-set and ingest reader (ExrReader) through a Seurat manifest.
  const fs::path dir = file.parent_path();
  std::ofstream(dir / "seurat.json")
      << calf::test::seurat_manifest(16, "hostile.exr", "hostile.exr");
  fs::remove_all(dir / "out");
  const Status ingest = ingest_seurat(dir / "seurat.json", dir / "out", IngestOptions{});
  EXPECT_EQ(ingest.id(), ErrorId::kCaptureImageFormat) << ingest.to_string();
  EXPECT_NE(ingest.message().find(message), std::string::npos) << ingest.message();
}

// A string attribute declaring 2^31 - 1 bytes in a 100-byte file: OpenEXR 3.1 resized a
// std::string to that size before noticing the file ends (2 GB for an embedded texture, found
// by libFuzzer). Refused from the walk, naming the attribute, in memory and from a file.
TEST(ExrHeader, AttributeLargerThanTheBytesLeftIsRefused) {
  const std::string exr = exr_with("comments", "string", 0x7fffffff, "abc");
  ASSERT_LT(exr.size(), 200u);
  const auto start = std::chrono::steady_clock::now();
  expect_refused(exr, "header attribute 'comments' (string) declares 2147483647 bytes, more than");
  // A negative size.
  expect_refused(exr_with("comments", "string", 0xfffffff0u, "abc"), "declares -16 bytes");
  EXPECT_LT(seconds_since(start), 2.0);
}

// Sizes inside an attribute: a preview whose pixels are not its bytes, a string vector whose
// string runs past it; and the file kinds calf does not read.
TEST(ExrHeader, InnerSizesAndFileKinds) {
  std::string preview;
  put_le32(&preview, 65535);
  put_le32(&preview, 65535);
  expect_refused(exr_with("preview", "preview", 8, preview),
                 "preview 'preview' declares 65535 x 65535 pixels in 8 bytes");
  std::string strings;
  put_le32(&strings, 0x7ffffff0u);
  strings += "abcd";
  expect_refused(exr_with("multiView", "stringvector", 8, strings),
                 "string vector 'multiView' declares a string of 2147483632 bytes");
  expect_refused(exr_with("comments", "string", 1, "a", 2 | 0x1000), "a multi-part OpenEXR file");
  expect_refused(exr_with("comments", "string", 1, "a", 2 | 0x200), "a tiled OpenEXR file");
  expect_refused(exr_with("comments", "string", 1, "a", 2 | 0x800), "a deep OpenEXR file");
  expect_refused(exr_with("comments", "string", 1, "a"), "the header has no dataWindow");
  // A float of 0 bytes (OpenEXR reads 4 whatever the size says, so its walk and ours would part)
  // and an attribute given twice (found by libFuzzer: OpenEXR then took 17 s and 400 MB).
  expect_refused(exr_with("screenWindowWidth", "float", 0, ""),
                 "'screenWindowWidth' (float) has 0 bytes; the type has 4");
  std::string second = std::string("x") + "comments" + '\0' + "string" + '\0';
  put_le32(&second, 1);
  expect_refused(exr_with("comments", "string", 1, second + "y"),
                 "header attribute 'comments' appears twice");
  // 1000 HALF channels of 16384 pixels in 16-row ZIP chunks: 500 MB a chunk.
  std::vector<std::string> many;
  for (int i = 0; i < 1000; ++i) many.push_back("c" + std::to_string(i));
  expect_refused(exr_header_only(16384, 16, many), "bytes a chunk, more than 268435456");
}

// Within the walk's limits, a header alone is then measured against the texture budget before
// OpenEXR opens it.
TEST(ExrHeader, TextureBudgetFromTheHeader) {
  SceneTexture t;
  const std::string big = exr_header_only(16384, 16384, {"R"});
  Status s = decode_texture_image(bytes_of(big), "", "big", &t);
  EXPECT_EQ(s.id(), ErrorId::kImageBudget) << s.to_string();
  EXPECT_NE(s.message().find("16384 x 16384 = 268435456 pixels"), std::string::npos);
  s = read_texture_image(write("big.exr", big), &t);
  EXPECT_EQ(s.id(), ErrorId::kImageBudget) << s.to_string();
  // A hint of "exr" over bytes that are not: refused by the walk, not tried as other formats.
  s = decode_texture_image(bytes_of(std::string(64, 'x')), "exr", "notexr", &t);
  EXPECT_EQ(s.id(), ErrorId::kSceneFileTexture) << s.to_string();
  EXPECT_NE(s.message().find("not an OpenEXR file"), std::string::npos) << s.message();
}

// A valid OpenEXR texture still decodes, from memory and from a file: 0 and 1 are bytes 0, 255.
TEST(ExrHeader, ValidTextureDecodes) {
  const fs::path file = calf::test::scratch_dir("image_budget_test") / "valid.exr";
  {
    std::unique_ptr<OIIO::ImageOutput> out = OIIO::ImageOutput::create("exr");
    ASSERT_TRUE(out);
    OIIO::ImageSpec spec(2, 1, 4, OIIO::TypeDesc::HALF);
    ASSERT_TRUE(out->open(file.string(), spec));
    const float pixels[8] = {0, 1, 0, 1, 1, 0, 1, 1};
    ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, pixels));
    ASSERT_TRUE(out->close());
  }
  const std::vector<uint8_t> expected = {0, 255, 0, 255, 255, 0, 255, 255};
  SceneTexture t;
  ASSERT_TRUE(read_texture_image(file, &t).ok());
  EXPECT_EQ(t.rgba, expected);
  std::ifstream in(file, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  SceneTexture m;
  const Status s = decode_texture_image(bytes_of(bytes), "", "embedded", &m);
  ASSERT_TRUE(s.ok()) << s.to_string();
  EXPECT_EQ(m.rgba, expected);
  EXPECT_EQ(m.width, 2u);
}

}  // namespace
}  // namespace calf::capture
