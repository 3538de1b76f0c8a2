// Capture sets into player views: a small capture set written with the capture writer is read
// back as a ViewSet (positions, colour, log-16 depth in a range covering exactly the finite depths,
// sky, material), errors name the file, eye-path poses become cameras, and a view re-projected at
// its own centre shows its own texels.
#include "calf/player/capture_views.h"

#include <gtest/gtest.h>

#include <unistd.h>
#include <cmath>
#include <filesystem>
#include <string>

namespace calf::player {
namespace {

namespace fs = std::filesystem;
constexpr double kPi = 3.141592653589793;

// A fresh directory under the system's temporary directory, removed at the end.
class TempDir {
 public:
  explicit TempDir(const std::string& name)
      : path_(fs::temp_directory_path() /
              ("calf_capture_views_" + name + "_" + std::to_string(::getpid()))) {
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ignored;
    fs::remove_all(path_, ignored);
  }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

// Texel values that say where they are: depth 1 + (face + x + 2 y) / 8 (so 1 .. 2.375 over 4 x 4
// faces), with a sky texel at (+Y, 1, 2); colour (face, x, y) / 8 + view; material on -Z only.
capture::ViewFrame frame_for(uint32_t view, bool all_sky) {
  capture::ViewFrame f;
  f.resize(4, true);
  for (int face = 0; face < kCubeFaceCount; ++face) {
    for (uint32_t y = 0; y < 4; ++y) {
      for (uint32_t x = 0; x < 4; ++x) {
        const size_t i = f.texel_index(cube_face_from_index(face), x, y);
        f.depth[i] = all_sky ? INFINITY : 1.0f + (face + x + 2.0f * y) / 8;
        f.color[3 * i + 0] = face / 8.0f + view;
        f.color[3 * i + 1] = x / 8.0f;
        f.color[3 * i + 2] = y / 8.0f;
        const bool mirror = cube_face_from_index(face) == CubeFace::kNegZ;
        f.material[3 * i + 0] = mirror ? 0.5f : 0.0f;
        f.material[3 * i + 1] = mirror ? 0.25f : 0.0f;
        f.material[3 * i + 2] = mirror ? 1.5f : 1.0f;
      }
    }
  }
  if (!all_sky) f.depth[f.texel_index(CubeFace::kPosY, 1, 2)] = INFINITY;
  return f;
}

// Two viewpoints, two frames; view 1 is all sky at frame 1.
void write_set(const fs::path& dir) {
  capture::CaptureManifest m;
  m.frame_count = 2;
  m.fps = 10;
  m.face_size = 4;
  m.material = true;
  m.view_volume = {{0, 0, 0}, {1, 1, 1}};
  m.viewpoints = {{"a", {0.25, 0.5, 0.75}}, {"b", {1, 1, 1}}};
  Expected<capture::CaptureSetWriter> w = capture::CaptureSetWriter::create(dir, m);
  ASSERT_TRUE(w.ok()) << w.status().to_string();
  for (uint32_t v = 0; v < 2; ++v) {
    for (uint32_t f = 0; f < 2; ++f) {
      ASSERT_TRUE(w->write(v, f, frame_for(v, v == 1 && f == 1)).ok());
    }
  }
  ASSERT_TRUE(w->finish().ok());
}

TEST(CaptureViews, LoadsColourDepthAndMaterial) {
  TempDir dir("load");
  write_set(dir.path());
  const Expected<capture::CaptureSetReader> reader = capture::CaptureSetReader::open(dir.path());
  ASSERT_TRUE(reader.ok()) << reader.status().to_string();
  const Expected<ViewSet> views = load_capture_views(*reader, 0);
  ASSERT_TRUE(views.ok()) << views.status().to_string();
  ASSERT_EQ(views->views.size(), 2u);
  EXPECT_TRUE(views->has_material());
  const View& a = views->views[0];
  EXPECT_EQ(a.position().x, 0.25);
  EXPECT_EQ(a.position().y, 0.5);
  EXPECT_EQ(a.position().z, 0.75);
  EXPECT_EQ(a.face_size(), 4u);
  // The range covers exactly the finite depths: 1 (face 0, x = y = 0) .. 1 + (5 + 3 + 6) / 8.
  EXPECT_FLOAT_EQ(a.range().z_near(), 1.0f);
  EXPECT_FLOAT_EQ(a.range().z_far(), 2.75f);
  EXPECT_EQ(a.depth_code_at(CubeFace::kPosX, 0, 0), 0);
  EXPECT_EQ(a.depth_code_at(CubeFace::kNegZ, 3, 3), kLog16MaxFinite);
  EXPECT_EQ(a.depth_code_at(CubeFace::kPosY, 1, 2), kLog16Sky);
  // Every finite depth within half a code step (relative) of what was written.
  for (int face = 0; face < kCubeFaceCount; ++face) {
    for (uint32_t y = 0; y < 4; ++y) {
      for (uint32_t x = 0; x < 4; ++x) {
        const CubeFace f = cube_face_from_index(face);
        if (f == CubeFace::kPosY && x == 1 && y == 2) continue;
        const double want = 1.0 + (face + x + 2.0 * y) / 8;
        const double got = a.range().decode(a.depth_code_at(f, x, y));
        EXPECT_NEAR(got / want, 1.0, a.range().relative_step()) << face << " " << x << " " << y;
        // Colour is stored as half floats in the file: these values are exact in half.
        EXPECT_EQ(a.colour_at(f, x, y)[0], face / 8.0f);
        EXPECT_EQ(a.colour_at(f, x, y)[1], x / 8.0f);
        EXPECT_EQ(a.colour_at(f, x, y)[2], y / 8.0f);
      }
    }
  }
  EXPECT_EQ(views->views[1].colour_at(CubeFace::kPosX, 0, 0)[0], 1.0f);  // view index added
  const Material m = a.material_at(CubeFace::kNegZ, 2, 1);
  EXPECT_EQ(m.reflect, 0.5f);
  EXPECT_EQ(m.refract, 0.25f);
  EXPECT_EQ(m.ior, 1.5f);
  EXPECT_EQ(a.material_at(CubeFace::kPosX, 2, 1).ior, 1.0f);
}

TEST(CaptureViews, AllSkyViewFrame) {
  TempDir dir("sky");
  write_set(dir.path());
  const Expected<ViewSet> views =
      load_capture_views(*capture::CaptureSetReader::open(dir.path()), 1);
  ASSERT_TRUE(views.ok()) << views.status().to_string();
  const View& b = views->views[1];
  for (int face = 0; face < kCubeFaceCount; ++face) {
    for (uint16_t c : b.depth_face(cube_face_from_index(face))) ASSERT_EQ(c, kLog16Sky);
  }
  EXPECT_EQ(b.range().z_near(), 1.0f);
  EXPECT_EQ(b.range().z_far(), 2.0f);
}

TEST(CaptureViews, ErrorsNameTheFile) {
  TempDir dir("errors");
  write_set(dir.path());
  const capture::CaptureSetReader reader = *capture::CaptureSetReader::open(dir.path());
  const Expected<ViewSet> beyond = load_capture_views(reader, 2);
  ASSERT_FALSE(beyond.ok());
  EXPECT_EQ(beyond.status().id(), ErrorId::kPlayerCaptureViews);
  EXPECT_NE(beyond.status().message().find(dir.path().string()), std::string::npos)
      << beyond.status().to_string();
  const fs::path missing = reader.image_path(1, 0);
  fs::remove(missing);
  const Expected<ViewSet> gone = load_capture_views(reader, 0);
  ASSERT_FALSE(gone.ok());
  EXPECT_EQ(gone.status().id(), ErrorId::kCaptureFileMissing);
  EXPECT_NE(gone.status().message().find(missing.string()), std::string::npos);
}

TEST(CaptureViews, RejectsBadFrames) {
  capture::ViewFrame f = frame_for(0, false);
  f.depth[f.texel_index(CubeFace::kNegX, 3, 1)] = std::nanf("");
  const Expected<View> nan = view_from_capture_frame(f, {}, "x.exr");
  ASSERT_FALSE(nan.ok());
  EXPECT_EQ(nan.status().id(), ErrorId::kPlayerCaptureViews);
  EXPECT_NE(nan.status().message().find("x.exr"), std::string::npos);
  EXPECT_NE(nan.status().message().find("(3, 1)"), std::string::npos) << nan.status().to_string();
  f = frame_for(0, false);
  f.depth[5] = -1;
  EXPECT_EQ(view_from_capture_frame(f, {}, "").status().id(), ErrorId::kPlayerCaptureViews);
  f = frame_for(0, false);
  f.color.pop_back();
  EXPECT_EQ(view_from_capture_frame(f, {}, "").status().id(), ErrorId::kPlayerCaptureViews);
  f = frame_for(0, false);
  EXPECT_EQ(view_from_capture_frame(f, {INFINITY, 0, 0}, "").status().id(),
            ErrorId::kPlayerViewSet);
}

TEST(CaptureViews, FrameAtTime) {
  capture::CaptureManifest m;
  m.frame_count = 8;
  m.fps = 30;
  EXPECT_EQ(capture_frame_at(m, 0), 0u);
  EXPECT_EQ(capture_frame_at(m, 3.0 / 30), 3u);
  EXPECT_EQ(capture_frame_at(m, 3.49 / 30), 3u);
  EXPECT_EQ(capture_frame_at(m, 3.51 / 30), 4u);
  EXPECT_EQ(capture_frame_at(m, 100), 7u);
  EXPECT_EQ(capture_frame_at(m, -1), 0u);
  EXPECT_EQ(capture_frame_at(m, std::nan("")), 0u);
}

TEST(CaptureViews, CameraFromPose) {
  capture::EyePose pose;
  pose.position = {1, 2, 3};
  pose.forward = {0, 0, 1};
  pose.up = {0, 1, 0};
  pose.fov_y_degrees = 60;
  const Camera c = capture::camera_from_pose(pose, 6, 4);
  EXPECT_EQ(c.width, 6u);
  EXPECT_EQ(c.height, 4u);
  EXPECT_NEAR(c.fov_y, kPi / 3, 1e-15);
  // Top-left pixel: a = -5/6, b = 3/4; right = forward x up = (-1, 0, 0), h = tan(30°).
  const Vec3 d = camera_ray(c, 0, 0);
  const double h = std::tan(kPi / 6), ax = -5.0 / 6 * h * 1.5, by = 0.75 * h;
  const double len = std::sqrt(1 + ax * ax + by * by);
  EXPECT_NEAR(d.x, -ax / len, 1e-12);
  EXPECT_NEAR(d.y, by / len, 1e-12);
  EXPECT_NEAR(d.z, 1 / len, 1e-12);
}

// An eye at a view's centre looking down -Z with a square 90° frustum of face-size pixels sees
// the -Z face mirrored left-right: pixel (i, j) is texel (n - 1 - i, j), each ray through a texel
// centre, so bilinear filtering returns the texel itself.
TEST(CaptureViews, ReprojectionAtTheViewpointShowsTheTexels) {
  const capture::ViewFrame f = frame_for(0, false);
  const Expected<View> v = view_from_capture_frame(f, {0.25, 0.5, 0.75}, "");
  ASSERT_TRUE(v.ok());
  Camera cam;
  cam.position = v->position();
  cam.forward = {0, 0, -1};
  cam.fov_y = kPi / 2;
  cam.width = cam.height = 4;
  const RenderedImage img = reproject_view(*v, cam);
  ASSERT_EQ(img.color.size(), 48u);
  for (uint32_t j = 0; j < 4; ++j) {
    for (uint32_t i = 0; i < 4; ++i) {
      const size_t k = j * 4 + i;
      const float* want = v->colour_at(CubeFace::kNegZ, 3 - i, j);
      for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(img.color[3 * k + ch], want[ch], 1e-6);
      EXPECT_NEAR(img.depth[k], 1.0 + (5 + (3 - i) + 2.0 * j) / 8, 1e-3);
    }
  }
}

}  // namespace
}  // namespace calf::player
