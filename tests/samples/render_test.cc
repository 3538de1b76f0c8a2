// The calf-capture ray tracer (calf/samples/render.h): cube-face convention and radial depth
// against analytic shapes, sky, determinism across thread counts, animation, material channels,
// ground truth, and the all-or-nothing behaviour of the drivers.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <string>

#include "calf/capture/capture_set.h"
#include "calf/capture/eye_path.h"
#include "calf/format/cube.h"
#include "calf/samples/render.h"
#include "calf/samples/scene.h"

namespace calf::samples {
namespace {

namespace fs = std::filesystem;

fs::path temp_dir(const std::string& name) {
  fs::path p = fs::temp_directory_path() / ("calf_render_test_" + name);
  fs::remove_all(p);
  return p;
}

// One red sphere of radius r at distance d on +X, nothing else: sky everywhere else.
Scene sphere_scene(double d, double r) {
  Scene s;
  s.name = "sphere";
  Material red;
  red.albedo = {0.9f, 0.1f, 0.1f};
  s.materials = {red};
  Object o;
  o.name = "ball";
  o.spheres.push_back({glm::vec3(static_cast<float>(d), 0, 0), static_cast<float>(r)});
  s.objects.push_back(o);
  s.sky.sun_irradiance = glm::vec3(2.0f);
  s.sky.sun_direction = {1, 0.2f, 0};
  return s;
}

// Exact radial distance along a unit ray from the origin to a sphere, in double.
double ray_sphere(const Vec3& dir, double cx, double r) {
  double b = dir.x * cx;
  double c = cx * cx - r * r;
  return b - std::sqrt(b * b - c);
}

TEST(Render, SphereOnPlusXAppearsOnFacePlusXWithExactDepth) {
  const double d = 3, r = 1;
  Scene s = sphere_scene(d, r);
  auto tracer = FrameTracer::create(s, 0, LightfieldRenderOptions{1, 1, 0, 6, 0});
  ASSERT_TRUE(tracer.ok()) << tracer.status().to_string();
  capture::ViewFrame f;
  const uint32_t n = 24;
  (*tracer)->render_cube({0, 0, 0}, 0, 0, n, false, &f);
  Texel centre = texel_from_direction({1, 0, 0}, n);
  ASSERT_EQ(centre.face, CubeFace::kPosX);
  size_t ci = f.texel_index(CubeFace::kPosX, centre.x, centre.y);
  // Roughly d - r at the centre texel, exactly the ray-sphere distance of that texel's ray.
  EXPECT_NEAR(f.depth[ci], d - r, 0.02);
  EXPECT_GT(f.color[3 * ci], 3 * f.color[3 * ci + 1]);  // red
  size_t hits = 0;
  double worst = 0;
  for (int face = 0; face < 6; ++face) {
    for (uint32_t y = 0; y < n; ++y) {
      for (uint32_t x = 0; x < n; ++x) {
        CubeFace cf = cube_face_from_index(face);
        Vec3 dir = direction_from_texel(cf, x, y, n);
        float z = f.depth[f.texel_index(cf, x, y)];
        // The sphere subtends 19.5 degrees: only +X sees it; a texel sees it iff its ray hits.
        double disc = dir.x * d * dir.x * d - (d * d - r * r);
        bool expect_hit = dir.x > 0 && disc > 1e-6;
        bool grazing = dir.x > 0 && std::fabs(disc) <= 1e-6;
        if (grazing) continue;
        ASSERT_EQ(std::isfinite(z), expect_hit) << cube_face_name(cf) << " " << x << "," << y;
        if (expect_hit) {
          ++hits;
          double exact = ray_sphere(dir, d, r);
          worst = std::max(worst, std::fabs(z - exact) / exact);
        } else {
          EXPECT_TRUE(std::isinf(z) && z > 0);  // sky is +inf
        }
      }
    }
  }
  EXPECT_GT(hits, 20u);
  EXPECT_LT(worst, 1e-5) << "radial depth of the sphere";
}

TEST(Render, RoomDepthIsExactOnEveryTexelAndContinuousAcrossSeams) {
  // Inside an off-centre box room: every texel's depth is the distance to the first wall along
  // its ray. Across a seam the two texels see the same wall, so depth is continuous there.
  Scene s;
  s.name = "room";
  s.materials = {Material{}};
  Object o;
  o.name = "room";
  const glm::vec3 lo(-2, -1.5f, -3), hi(3, 2, 2.5f);
  add_room(&o.mesh, lo, hi);
  s.objects.push_back(o);
  auto tracer = FrameTracer::create(s, 0, LightfieldRenderOptions{2, 1, 2, 6, 0});
  ASSERT_TRUE(tracer.ok()) << tracer.status().to_string();
  ASSERT_FALSE((*tracer)->inside_geometry({0, 0, 0}));
  capture::ViewFrame f;
  const uint32_t n = 20;
  (*tracer)->render_cube({0, 0, 0}, 0, 0, n, false, &f);
  double worst = 0;
  for (int face = 0; face < 6; ++face) {
    for (uint32_t y = 0; y < n; ++y) {
      for (uint32_t x = 0; x < n; ++x) {
        CubeFace cf = cube_face_from_index(face);
        Vec3 dir = direction_from_texel(cf, x, y, n);
        double t = INFINITY;
        const double dv[3] = {dir.x, dir.y, dir.z};
        for (int a = 0; a < 3; ++a) {
          if (dv[a] > 0) t = std::min(t, hi[a] / dv[a]);
          if (dv[a] < 0) t = std::min(t, lo[a] / dv[a]);
        }
        float z = f.depth[f.texel_index(cf, x, y)];
        worst = std::max(worst, std::fabs(z - t) / t);
      }
    }
  }
  EXPECT_LT(worst, 1e-5);
}

TEST(Render, InsideGeometryIsDetected) {
  auto scene = make_builtin_scene("turntable");
  ASSERT_TRUE(scene.ok());
  auto tracer = FrameTracer::create(*scene, 0, LightfieldRenderOptions{});
  ASSERT_TRUE(tracer.ok());
  EXPECT_TRUE((*tracer)->inside_geometry({0, 0, 0}));  // inside the hull
  EXPECT_FALSE((*tracer)->inside_geometry({0, 0, 3}));
  Rig rig = list_rig({{0, 0, 3}, {0, 0.0, 0.1}});
  Status st = check_viewpoints(*scene, rig, 1, 30, LightfieldRenderOptions{});
  EXPECT_EQ(st.id(), ErrorId::kViewpointInsideGeometry);
  EXPECT_NE(st.message().find("viewpoint 1"), std::string::npos) << st.to_string();
}

std::map<std::string, std::string> read_all(const fs::path& dir) {
  std::map<std::string, std::string> files;
  for (const auto& e : fs::directory_iterator(dir)) {
    std::ifstream in(e.path(), std::ios::binary);
    files[e.path().filename().string()] =
        std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  return files;
}

TEST(Render, SameBytesForAnyThreadCount) {
  auto scene = make_builtin_scene("mirror-box");
  ASSERT_TRUE(scene.ok());
  CaptureRequest req;
  req.face_size = 16;
  req.frames = 2;
  req.rig = list_rig({{0, 1.75, 0}, {0.5, 1.5, -0.4}});
  req.render.noise = 0.05f;  // the noise path must be deterministic too
  std::map<std::string, std::string> first;
  for (uint32_t threads : {1u, 2u, 3u}) {
    req.render.threads = threads;
    fs::path dir = temp_dir("threads" + std::to_string(threads));
    auto stats = render_capture_set(*scene, req, dir, nullptr);
    ASSERT_TRUE(stats.ok()) << stats.status().to_string();
    EXPECT_GT(stats->rays, 2u * 2 * 6 * 16 * 16);
    auto files = read_all(dir);
    EXPECT_EQ(files.size(), 5u);  // 2 views x 2 frames + manifest
    if (first.empty()) {
      first = files;
    } else {
      EXPECT_TRUE(files == first) << "output differs with " << threads << " threads";
    }
    fs::remove_all(dir);
  }
}

TEST(Render, AnimationChangesDepthAndShadingWhereDepthStaysStill) {
  auto scene = make_builtin_scene("interior");
  ASSERT_TRUE(scene.ok());
  capture::ViewFrame a, b;
  LightfieldRenderOptions opt{2, 1, 4, 6, 0};
  const Vec3 centre = scene->default_rig.viewpoints[0].position;
  auto t0 = FrameTracer::create(*scene, 0.0, opt);
  auto t1 = FrameTracer::create(*scene, 10 / scene->fps, opt);
  ASSERT_TRUE(t0.ok() && t1.ok());
  (*t0)->render_cube(centre, 0, 0, 24, false, &a);
  (*t1)->render_cube(centre, 0, 10, 24, false, &b);
  size_t depth_changed = 0, shading_only = 0, static_same = 0;
  for (size_t i = 0; i < a.texel_count(); ++i) {
    if (a.depth[i] != b.depth[i]) {
      ++depth_changed;
    } else if (std::memcmp(&a.color[3 * i], &b.color[3 * i], 3 * sizeof(float)) != 0) {
      ++shading_only;
    } else {
      ++static_same;
    }
  }
  EXPECT_GT(depth_changed, 0u) << "moving objects";
  EXPECT_GT(shading_only, 50u) << "the pulsing lamp and moving shadows";
  // Static geometry keeps its exact depth from frame to frame (no jitter from re-building).
  size_t same_depth = a.texel_count() - depth_changed;
  EXPECT_GT(same_depth, a.texel_count() * 9 / 10);
  (void)static_same;
}

TEST(Render, MaterialChannelsOnlyWhereMirrorOrGlass) {
  for (const SceneInfo& info : builtin_scenes()) {
    auto scene = make_builtin_scene(info.name);
    ASSERT_TRUE(scene.ok());
    EXPECT_EQ(scene->has_mirror_or_glass(), std::string(info.name) == "mirror-box") << info.name;
  }
  auto scene = make_builtin_scene("mirror-box");
  CaptureRequest req;
  req.face_size = 24;
  req.frames = 1;
  req.rig = list_rig({{0, 1.75, 0}});
  fs::path dir = temp_dir("material");
  ASSERT_TRUE(render_capture_set(*scene, req, dir, nullptr).ok());
  auto reader = capture::CaptureSetReader::open(dir);
  ASSERT_TRUE(reader.ok());
  EXPECT_TRUE(reader->manifest().material);
  capture::ViewFrame f;
  ASSERT_TRUE(reader->read(0, 0, &f).ok());
  size_t mirror = 0, glass = 0, plain = 0;
  for (size_t i = 0; i < f.texel_count(); ++i) {
    const float* m = &f.material[3 * i];
    if (m[0] == 0.8999023f || std::fabs(m[0] - 0.9f) < 1e-3f) ++mirror;
    if (std::fabs(m[1] - 0.92f) < 1e-3f && std::fabs(m[2] - 1.5f) < 1e-3f) ++glass;
    if (m[0] == 0 && m[1] == 0 && m[2] == 1) ++plain;
  }
  EXPECT_GT(mirror, 0u);
  EXPECT_GT(glass, 0u);
  EXPECT_GT(plain, f.texel_count() / 2);
  fs::remove_all(dir);

  auto turntable = make_builtin_scene("turntable");
  req.rig = list_rig({{0, 0, 3}});
  dir = temp_dir("no_material");
  ASSERT_TRUE(render_capture_set(*turntable, req, dir, nullptr).ok());
  reader = capture::CaptureSetReader::open(dir);
  ASSERT_TRUE(reader.ok());
  EXPECT_FALSE(reader->manifest().material);
  fs::remove_all(dir);
}

TEST(Render, FailedCaptureLeavesNoCompleteLookingSet) {
  auto scene = make_builtin_scene("turntable");
  CaptureRequest req;
  req.face_size = 8;
  req.frames = 1;
  req.rig = list_rig({{0, 0, 3}, {0, 0, 0}});  // the second is inside the hull
  fs::path dir = temp_dir("inside");
  auto r = render_capture_set(*scene, req, dir, nullptr);
  EXPECT_EQ(r.status().id(), ErrorId::kViewpointInsideGeometry);
  EXPECT_FALSE(fs::exists(dir / capture::kManifestFileName));
  req.face_size = 0;
  EXPECT_EQ(render_capture_set(*scene, req, dir, nullptr).status().id(), ErrorId::kCaptureOption);
  fs::remove_all(dir);
}

TEST(Render, GroundTruthAlongTheValidationPath) {
  auto scene = make_builtin_scene("mirror-box");
  ASSERT_TRUE(scene.ok());
  capture::EyePath path = scene->validation_path(2, scene->fps, 12, 8);
  fs::path dir = temp_dir("gt");
  auto r = render_ground_truth(*scene, path, LightfieldRenderOptions{2, 1, 2, 6, 0}, dir, nullptr);
  ASSERT_TRUE(r.ok()) << r.status().to_string();
  auto back = capture::read_eye_path(dir / capture::kEyePathFileName);
  ASSERT_TRUE(back.ok()) << back.status().to_string();
  EXPECT_EQ(back->poses.size(), 2u);
  EXPECT_EQ(back->image_pattern, capture::kDefaultImagePattern);
  auto img = capture::read_perspective_image(dir / capture::eye_image_file_name(*back, 1));
  ASSERT_TRUE(img.ok()) << img.status().to_string();
  EXPECT_EQ(img->width, 12u);
  EXPECT_EQ(img->height, 8u);
  // The eye is inside a closed box: every pixel hits something at a finite distance.
  for (float z : img->depth) EXPECT_TRUE(std::isfinite(z) && z > 0);
  fs::remove_all(dir);
}

TEST(Render, PerspectiveCentrePixelDepth) {
  // Looking straight at the sphere from the origin with an odd image size: the centre pixel's ray
  // is the axis, its depth exactly d - r.
  Scene s = sphere_scene(4, 0.5);
  auto tracer = FrameTracer::create(s, 0, LightfieldRenderOptions{1, 1, 0, 6, 0});
  ASSERT_TRUE(tracer.ok());
  capture::PerspectiveImage img;
  capture::EyePose pose = look_at_pose(0, {0, 0, 0}, {1, 0, 0}, 30);
  (*tracer)->render_perspective(pose, 9, 7, 0, &img);
  EXPECT_NEAR(img.depth[3 * 9 + 4], 3.5, 3.5e-6);
  EXPECT_TRUE(std::isinf(img.depth[0]));
}

TEST(Render, OptionsAreValidated) {
  EXPECT_EQ(validate_render_options(LightfieldRenderOptions{300, 1, 8, 6, 0}).id(),
            ErrorId::kCaptureOption);
  EXPECT_EQ(validate_render_options(LightfieldRenderOptions{1, 1, 8, 6, 2}).id(),
            ErrorId::kCaptureOption);
  EXPECT_EQ(validate_render_options(LightfieldRenderOptions{1, 1, 999, 6, 0}).id(),
            ErrorId::kCaptureOption);
  EXPECT_TRUE(validate_render_options(LightfieldRenderOptions{}).ok());
}

}  // namespace
}  // namespace calf::samples
