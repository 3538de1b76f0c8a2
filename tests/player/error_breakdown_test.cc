// Tests of the error breakdown (player/include/calf/player/error_breakdown.h) on a capture set
// written here: one viewpoint at the origin inside a sphere of radius 2. The ground truth's
// left half shows a surface at distance 1 (an object the capture never saw: disocclusion), its
// right half the sphere (seen), with sky in the top rows; every class's pixels and squared error
// are known exactly.
#include "calf/player/error_breakdown.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "../scratch_dir.h"
#include "calf/format/cube.h"

namespace calf::player {
namespace {

namespace fs = std::filesystem;
constexpr uint32_t kFace = 16, kW = 20, kH = 10;
constexpr float kInf = std::numeric_limits<float>::infinity();

const fs::path& sphere_capture() {
  static const fs::path dir = [] {
    const fs::path d = test::scratch_dir("error_breakdown_test") / "sphere";
    capture::CaptureManifest m;
    m.frame_count = 1;
    m.face_size = kFace;
    m.view_volume = {{-0.1, -0.1, -0.1}, {0.1, 0.1, 0.1}};
    m.viewpoints = {{"centre", {0, 0, 0}}};
    auto w = capture::CaptureSetWriter::create(d, m);
    EXPECT_TRUE(w.ok()) << w.status().to_string();
    capture::ViewFrame f;
    f.resize(kFace, false);
    for (size_t t = 0; t < f.texel_count(); ++t) {
      f.depth[t] = 2.0f;
      for (int c = 0; c < 3; ++c) f.color[3 * t + c] = 0.5f;
    }
    EXPECT_TRUE(w->write(0, 0, f).ok());
    EXPECT_TRUE(w->finish().ok());
    return d;
  }();
  return dir;
}

Camera eye() {
  Camera c;
  c.position = {0, 0, 0};
  c.forward = {0, 0, -1};
  c.width = kW;
  c.height = kH;
  return c;
}

// Ground truth: black; depth 1 in columns < kW / 2, 2 beyond, sky in rows 0..1.
capture::PerspectiveImage truth() {
  capture::PerspectiveImage t;
  t.width = kW;
  t.height = kH;
  t.color.assign(3 * kW * kH, 0.0f);
  t.depth.resize(kW * kH);
  for (uint32_t y = 0; y < kH; ++y) {
    for (uint32_t x = 0; x < kW; ++x) {
      t.depth[y * kW + x] = y < 2 ? kInf : (x < kW / 2 ? 1.0f : 2.0f);
    }
  }
  // The depth along each ray is radial: the left half's surface at 1 lies inside the sphere.
  return t;
}

CaptureVisibility visibility() {
  auto reader = capture::CaptureSetReader::open(sphere_capture());
  EXPECT_TRUE(reader.ok()) << reader.status().to_string();
  auto v = CaptureVisibility::load(*reader, 0);
  EXPECT_TRUE(v.ok()) << v.status().to_string();
  return std::move(*v);
}

TEST(ErrorBreakdown, ClassesPartitionTheSquaredError) {
  const capture::PerspectiveImage gt = truth();
  std::vector<float> white(3 * kW * kH, 1.0f);  // sRGB 1 against 0: squared error 1 a pixel
  const CaptureVisibility views = visibility();
  std::vector<uint8_t> classes;
  std::vector<float> squared;
  // No depth with the reconstruction: no pixel can be geometry.
  auto b = classify_errors({kW, kH, white, {}}, gt, eye(), views, nullptr, {}, &classes, &squared);
  ASSERT_TRUE(b.ok()) << b.status().to_string();
  // Depth edges: sky | surface between rows 1 and 2 (marks rows 1 and 2, every column) and
  // depth 1 | 2 between columns 9 and 10 in rows 2..9; grown by one pixel: rows 0..3, and
  // columns 8..11 of rows 1..9. Disocclusion comes first: rows 2..9, columns 0..9 (80 pixels,
  // the surface at 1 that the viewpoint, seeing the sphere at 2, never saw). Silhouette: rows
  // 0..1 (40, sky is never disoccluded), rows 2..3 columns 10..19 (20), rows 4..9 columns 10..11
  // (12): 72. Shading: rows 4..9, columns 12..19: 48.
  EXPECT_EQ(b->pixel_count, uint64_t{kW * kH});
  EXPECT_EQ(b->pixels[size_t(ErrorClass::kDisocclusion)], 80u);
  EXPECT_EQ(b->pixels[size_t(ErrorClass::kSilhouette)], 72u);
  EXPECT_EQ(b->pixels[size_t(ErrorClass::kShading)], 48u);
  EXPECT_EQ(b->pixels[size_t(ErrorClass::kCodec)], 0u);
  EXPECT_FALSE(b->codec_measured);
  EXPECT_DOUBLE_EQ(b->total(), double(kW * kH));
  for (size_t c = 0; c < kErrorClassCount; ++c) {
    EXPECT_DOUBLE_EQ(b->squared[c], double(b->pixels[c])) << error_class_name(ErrorClass(c));
  }
  EXPECT_EQ(classes[5 * kW + 3], uint8_t(ErrorClass::kDisocclusion));
  EXPECT_EQ(classes[5 * kW + 10], uint8_t(ErrorClass::kSilhouette));
  EXPECT_EQ(classes[5 * kW + 15], uint8_t(ErrorClass::kShading));
  EXPECT_EQ(classes[0], uint8_t(ErrorClass::kSilhouette));
  EXPECT_FLOAT_EQ(squared[0], 1.0f);
}

TEST(ErrorBreakdown, CodecIsWhatTheLossyClipAddsToTheLossless) {
  const capture::PerspectiveImage gt = truth();
  std::vector<float> lossy(3 * kW * kH, 1.0f);
  // The lossless render is exact on the left half and as wrong as the lossy one on the right.
  std::vector<float> lossless(3 * kW * kH, 0.0f);
  for (uint32_t y = 0; y < kH; ++y) {
    for (uint32_t x = kW / 2; x < kW; ++x) {
      for (int c = 0; c < 3; ++c) lossless[3 * (y * kW + x) + c] = 1.0f;
    }
  }
  const RgbImageRef lossless_ref{kW, kH, lossless};
  auto b = classify_errors({kW, kH, lossy, {}}, gt, eye(), visibility(), &lossless_ref, {});
  ASSERT_TRUE(b.ok()) << b.status().to_string();
  EXPECT_TRUE(b->codec_measured);
  EXPECT_DOUBLE_EQ(b->squared[size_t(ErrorClass::kCodec)], double(kW * kH / 2));
  EXPECT_DOUBLE_EQ(b->squared[size_t(ErrorClass::kDisocclusion)], 0.0);  // all codec there
  EXPECT_DOUBLE_EQ(b->total(), double(kW * kH));
  EXPECT_DOUBLE_EQ(b->share(ErrorClass::kCodec), 0.5);
}

TEST(ErrorBreakdown, AnotherSurfaceAwayFromEdgesIsGeometry) {
  // The reconstruction shows the sphere at 2.1 (5 % off) in columns 14..15 of rows 5..9, and sky
  // in column 18 of rows 5..9, where the ground truth has the sphere at 2: geometry; column 13
  // at 2.02 (1 %, within the 2 % tolerance) stays shading. Classes elsewhere as in the test above.
  const capture::PerspectiveImage gt = truth();
  RenderedImage test{kW, kH, std::vector<float>(3 * kW * kH, 1.0f), gt.depth};
  for (uint32_t y = 5; y < kH; ++y) {
    test.depth[y * kW + 13] = 2.02f;
    test.depth[y * kW + 14] = test.depth[y * kW + 15] = 2.1f;
    test.depth[y * kW + 18] = kInf;
  }
  std::vector<uint8_t> classes;
  auto b = classify_errors(test, gt, eye(), visibility(), nullptr, {}, &classes);
  ASSERT_TRUE(b.ok()) << b.status().to_string();
  EXPECT_EQ(b->pixels[size_t(ErrorClass::kGeometry)], 5u * 3);
  EXPECT_EQ(b->pixels[size_t(ErrorClass::kShading)], 48u - 15);
  EXPECT_EQ(b->pixels[size_t(ErrorClass::kDisocclusion)], 80u);
  EXPECT_EQ(classes[6 * kW + 13], uint8_t(ErrorClass::kShading));
  EXPECT_EQ(classes[6 * kW + 14], uint8_t(ErrorClass::kGeometry));
  EXPECT_EQ(classes[6 * kW + 18], uint8_t(ErrorClass::kGeometry));
  EXPECT_DOUBLE_EQ(b->squared[size_t(ErrorClass::kGeometry)], 15.0);
}

TEST(ErrorBreakdown, ExactImageHasNoError) {
  const capture::PerspectiveImage gt = truth();
  auto b = classify_errors({kW, kH, gt.color, gt.depth}, gt, eye(), visibility(), nullptr, {});
  ASSERT_TRUE(b.ok());
  EXPECT_EQ(b->total(), 0.0);
  EXPECT_EQ(b->share(ErrorClass::kShading), 0.0);  // no division by zero
}

TEST(ErrorBreakdown, Errors) {
  const capture::PerspectiveImage gt = truth();
  const CaptureVisibility views = visibility();
  std::vector<float> small(3 * 4 * 4, 0.0f);
  auto b = classify_errors({4, 4, small, {}}, gt, eye(), views, nullptr, {});
  EXPECT_EQ(b.status().id(), ErrorId::kImageCompare);
  ErrorBreakdownOptions o;
  o.visibility_tolerance = 0;
  b = classify_errors({kW, kH, gt.color, {}}, gt, eye(), views, nullptr, o);
  EXPECT_EQ(b.status().id(), ErrorId::kImageCompareOption);
  o = {};
  o.silhouette_radius = 17;
  b = classify_errors({kW, kH, gt.color, {}}, gt, eye(), views, nullptr, o);
  EXPECT_EQ(b.status().id(), ErrorId::kImageCompareOption);
  const fs::path png = test::scratch_dir("error_breakdown_test") / "classes.png";
  EXPECT_EQ(write_error_class_png(png, 2, 2, {0, 1, 2}, {0, 0, 0, 0}).id(), ErrorId::kImageCompare);
  EXPECT_EQ(write_error_class_png(png, 2, 2, {0, 1, 2, 3}, {0, 0, 0, 0}, 0).id(),
            ErrorId::kImageCompareOption);
  EXPECT_TRUE(write_error_class_png(png, 2, 2, {0, 1, 2, 3}, {0, 0.01f, 0.02f, 1}).ok());
  EXPECT_TRUE(fs::exists(png));
}

}  // namespace
}  // namespace calf::player
