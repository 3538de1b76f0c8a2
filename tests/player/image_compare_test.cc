// Image metrics against values computed independently: PSNR from its closed form on sRGB bytes,
// SSIM for identical and uniform images (closed form) and against a brute-force evaluation of
// Wang et al.'s definition written out here window by window, the heat-map ramp's stops, and the
// image files read back.
#include "calf/player/image_compare.h"

#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "calf/format/colour.h"

namespace calf::player {
namespace {

namespace fs = std::filesystem;

// An image whose pixels are given as sRGB bytes (decoded to linear, as a PNG would be), so that
// the metrics' sRGB encoding brings back exactly byte / 255 (up to float rounding).
struct Bytes {
  uint32_t w, h;
  std::vector<uint8_t> rgb;
  std::vector<float> linear() const {
    std::vector<float> out(rgb.size());
    for (size_t i = 0; i < rgb.size(); ++i) out[i] = linear_from_srgb8(rgb[i]);
    return out;
  }
};

Bytes uniform(uint32_t w, uint32_t h, uint8_t v) {
  return {w, h, std::vector<uint8_t>(3 * w * h, v)};
}

// Deterministic pseudo-random bytes (a 32-bit LCG), with structure so that windows differ.
Bytes noise(uint32_t w, uint32_t h, uint32_t seed) {
  Bytes b{w, h, std::vector<uint8_t>(3 * w * h)};
  uint32_t s = seed;
  for (uint32_t y = 0; y < h; ++y) {
    for (uint32_t x = 0; x < w; ++x) {
      for (int c = 0; c < 3; ++c) {
        s = s * 1664525u + 1013904223u;
        const int base = (x * 16 + y * 8) % 200;
        b.rgb[3 * (y * w + x) + c] = static_cast<uint8_t>(base + (s >> 24) % 56);
      }
    }
  }
  return b;
}

// SSIM exactly as Wang et al. (2004) define it, evaluated window by window with no shortcuts:
// luma Y = 0.2126 R + 0.7152 G + 0.0722 B of byte / 255, an 11 x 11 Gaussian window (sigma 1.5,
// weights normalised to sum 1) at every position inside the image, the mean over positions.
double brute_force_ssim(const Bytes& a, const Bytes& b) {
  double g[11][11], gs = 0;
  for (int j = 0; j < 11; ++j) {
    for (int i = 0; i < 11; ++i) {
      g[j][i] = std::exp(-((i - 5) * (i - 5) + (j - 5) * (j - 5)) / (2 * 1.5 * 1.5));
      gs += g[j][i];
    }
  }
  const auto luma = [](const Bytes& im, uint32_t x, uint32_t y) {
    const uint8_t* p = &im.rgb[3 * (y * im.w + x)];
    return (0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]) / 255;
  };
  const double c1 = 0.0001, c2 = 0.0009;
  double sum = 0;
  int n = 0;
  for (uint32_t y0 = 0; y0 + 11 <= a.h; ++y0) {
    for (uint32_t x0 = 0; x0 + 11 <= a.w; ++x0) {
      double mx = 0, my = 0;
      for (int j = 0; j < 11; ++j) {
        for (int i = 0; i < 11; ++i) {
          mx += g[j][i] / gs * luma(a, x0 + i, y0 + j);
          my += g[j][i] / gs * luma(b, x0 + i, y0 + j);
        }
      }
      double vx = 0, vy = 0, cxy = 0;
      for (int j = 0; j < 11; ++j) {
        for (int i = 0; i < 11; ++i) {
          const double dx = luma(a, x0 + i, y0 + j) - mx, dy = luma(b, x0 + i, y0 + j) - my;
          vx += g[j][i] / gs * dx * dx;
          vy += g[j][i] / gs * dy * dy;
          cxy += g[j][i] / gs * dx * dy;
        }
      }
      sum += (2 * mx * my + c1) * (2 * cxy + c2) / ((mx * mx + my * my + c1) * (vx + vy + c2));
      ++n;
    }
  }
  return sum / n;
}

TEST(ImageCompare, PsnrClosedForms) {
  const Bytes a = uniform(5, 3, 100), b = uniform(5, 3, 110);
  const std::vector<float> la = a.linear(), lb = b.linear();
  // Identical: +inf.
  EXPECT_TRUE(std::isinf(*psnr({5, 3, la}, {5, 3, la})));
  // Every value 10/255 apart: PSNR = 20 log10(255 / 10) = 28.1308 dB.
  EXPECT_NEAR(*psnr({5, 3, la}, {5, 3, lb}), 28.130803608679106, 1e-4);
  // One channel of one pixel of 15 off by 51/255 = 0.2: MSE = 0.04 / 45.
  Bytes c = a;
  c.rgb[7] = 151;
  EXPECT_NEAR(*psnr({5, 3, la}, {5, 3, c.linear()}), 10 * std::log10(45 / 0.04), 1e-4);
  // HDR values clamp to 1 after encoding: 2.0 and 5.0 show the same.
  const std::vector<float> hdr2(9, 2.0f), hdr5(9, 5.0f), one(9, 1.0f), zero(9, 0.0f);
  EXPECT_TRUE(std::isinf(*psnr({3, 1, hdr2}, {3, 1, hdr5})));
  // White against black: MSE 1, 0 dB.
  EXPECT_NEAR(*psnr({3, 1, one}, {3, 1, zero}), 0.0, 1e-12);
}

TEST(ImageCompare, SsimIdenticalAndUniform) {
  const Bytes x = noise(23, 17, 7);
  const std::vector<float> lx = x.linear();
  EXPECT_NEAR(*ssim({23, 17, lx}, {23, 17, lx}), 1.0, 1e-12);
  // Uniform greys a, b: every variance is 0, SSIM = (2ab + C1) / (a^2 + b^2 + C1).
  for (auto [va, vb] : {std::pair{100, 110}, std::pair{0, 255}, std::pair{30, 200}}) {
    const Bytes a = uniform(12, 11, static_cast<uint8_t>(va));
    const Bytes b = uniform(12, 11, static_cast<uint8_t>(vb));
    const double fa = va / 255.0, fb = vb / 255.0;
    const double want = (2 * fa * fb + 1e-4) / (fa * fa + fb * fb + 1e-4);
    EXPECT_NEAR(*ssim({12, 11, a.linear()}, {12, 11, b.linear()}), want, 1e-6) << va << " " << vb;
  }
}

TEST(ImageCompare, SsimMatchesTheDefinitionWindowByWindow) {
  for (uint32_t seed : {1u, 2u, 3u}) {
    const Bytes a = noise(19, 14, seed);
    Bytes b = noise(19, 14, seed + 10);
    // Mix: a quarter of the bytes shared, so SSIM lies well inside (0, 1).
    for (size_t i = 0; i < b.rgb.size(); i += 4) b.rgb[i] = a.rgb[i];
    const double want = brute_force_ssim(a, b);
    const double got = *ssim({19, 14, a.linear()}, {19, 14, b.linear()});
    EXPECT_NEAR(got, want, 1e-6) << "seed " << seed;
    EXPECT_GT(want, 0.05);
    EXPECT_LT(want, 0.98);
    // Symmetric in its arguments.
    EXPECT_NEAR(*ssim({19, 14, b.linear()}, {19, 14, a.linear()}), got, 1e-12);
  }
}

TEST(ImageCompare, RejectsBadImages) {
  const std::vector<float> px(3 * 12 * 12, 0.5f);
  EXPECT_EQ(psnr({12, 12, px}, {12, 11, px}).status().id(), ErrorId::kImageCompare);
  EXPECT_EQ(psnr({0, 12, px}, {0, 12, px}).status().id(), ErrorId::kImageCompare);
  EXPECT_EQ(psnr({13, 12, px}, {13, 12, px}).status().id(), ErrorId::kImageCompare);
  EXPECT_EQ(ssim({10, 12, px}, {10, 12, px}).status().id(), ErrorId::kImageCompare);
  EXPECT_EQ(error_map({12, 12, px}, {11, 12, px}).status().id(), ErrorId::kImageCompare);
}

TEST(ImageCompare, ErrorMapAndRamp) {
  Bytes a = uniform(2, 2, 50), b = a;
  b.rgb[3] = 50 + 102;  // pixel 1, red channel, 0.4 apart: RMS over channels 0.4 / sqrt(3)
  const std::vector<float> e = *error_map({2, 2, a.linear()}, {2, 2, b.linear()});
  ASSERT_EQ(e.size(), 4u);
  EXPECT_EQ(e[0], 0.0f);
  EXPECT_NEAR(e[1], 0.4 / std::sqrt(3.0), 1e-5);
  using C = std::array<uint8_t, 3>;
  EXPECT_EQ(heat_colour(0), (C{0, 0, 0}));
  EXPECT_EQ(heat_colour(0.25), (C{0, 0, 255}));
  EXPECT_EQ(heat_colour(0.5), (C{0, 255, 255}));
  EXPECT_EQ(heat_colour(0.75), (C{255, 255, 0}));
  EXPECT_EQ(heat_colour(1), (C{255, 0, 0}));
  EXPECT_EQ(heat_colour(0.125), (C{0, 0, 128}));
  EXPECT_EQ(heat_colour(-3), (C{0, 0, 0}));
  EXPECT_EQ(heat_colour(7), (C{255, 0, 0}));
  EXPECT_EQ(heat_colour(std::nan("")), (C{255, 0, 0}));
}

class ImageFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("calf_image_compare_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  // The 8-bit RGB pixels of a PNG.
  static std::vector<uint8_t> read_png(const fs::path& p, int* w, int* h) {
    std::unique_ptr<OIIO::ImageInput> in = OIIO::ImageInput::open(p.string());
    EXPECT_TRUE(in);
    if (!in) return {};
    *w = in->spec().width;
    *h = in->spec().height;
    EXPECT_EQ(in->spec().nchannels, 3);
    std::vector<uint8_t> px(size_t{3} * *w * *h);
    EXPECT_TRUE(in->read_image(0, 0, 0, 3, OIIO::TypeDesc::UINT8, px.data()));
    return px;
  }
  fs::path dir_;
};

TEST_F(ImageFiles, PngHeatMapAndExrReadBack) {
  const Bytes a = noise(4, 3, 5);
  ASSERT_TRUE(write_png(dir_ / "a.png", {4, 3, a.linear()}).ok());
  int w = 0, h = 0;
  EXPECT_EQ(read_png(dir_ / "a.png", &w, &h), a.rgb);
  EXPECT_EQ(w, 4);
  EXPECT_EQ(h, 3);

  Bytes b = a;
  b.rgb[0] = static_cast<uint8_t>(a.rgb[0] + 13);  // error 13 / 255 / sqrt(3) at pixel 0
  ASSERT_TRUE(write_heat_map_png(dir_ / "heat.png", {4, 3, a.linear()}, {4, 3, b.linear()}).ok());
  const std::vector<uint8_t> heat = read_png(dir_ / "heat.png", &w, &h);
  const std::array<uint8_t, 3> want = heat_colour(13 / 255.0 / std::sqrt(3.0) / 0.1);
  EXPECT_NEAR(heat[0], want[0], 1);
  EXPECT_NEAR(heat[1], want[1], 1);
  EXPECT_NEAR(heat[2], want[2], 1);
  for (size_t i = 3; i < heat.size(); ++i) EXPECT_EQ(heat[i], 0);

  RenderedImage r;
  r.width = 2;
  r.height = 1;
  r.color = {0.25f, 2.5f, 0.0f, 1.0f, 0.5f, 0.125f};  // HDR kept in EXR
  r.depth = {3.5f, INFINITY};
  ASSERT_TRUE(write_exr(dir_ / "r.exr", r).ok());
  const Expected<capture::PerspectiveImage> back = capture::read_perspective_image(dir_ / "r.exr");
  ASSERT_TRUE(back.ok()) << back.status().to_string();
  EXPECT_EQ(back->color, r.color);  // exact in half
  EXPECT_EQ(back->depth[0], 3.5f);
  EXPECT_TRUE(std::isinf(back->depth[1]));
  for (const auto& e : fs::directory_iterator(dir_)) {
    EXPECT_EQ(e.path().extension().string().find("tmp"), std::string::npos) << e.path();
  }
}

TEST_F(ImageFiles, WriteErrorsLeaveNothing) {
  const std::vector<float> px(3 * 4, 0.5f);
  const fs::path nowhere = dir_ / "missing-dir" / "a.png";
  const Status s = write_png(nowhere, {2, 2, px});
  EXPECT_EQ(s.id(), ErrorId::kFileWrite);
  EXPECT_NE(s.message().find("a.png"), std::string::npos);
  EXPECT_FALSE(fs::exists(nowhere));
  EXPECT_EQ(write_heat_map_png(dir_ / "h.png", {2, 2, px}, {2, 2, px}, 0).id(),
            ErrorId::kImageCompareOption);
  EXPECT_EQ(write_heat_map_png(dir_ / "h.png", {2, 2, px}, {2, 2, px}, 1.5).id(),
            ErrorId::kImageCompareOption);
  EXPECT_EQ(write_png(dir_ / "e.png", {3, 2, px}).id(), ErrorId::kImageCompare);
  EXPECT_TRUE(fs::is_empty(dir_));
}

}  // namespace
}  // namespace calf::player
