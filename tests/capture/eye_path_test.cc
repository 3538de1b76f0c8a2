// Eye paths (calf/capture/eye_path.h, format/CAPTURE.md "Eye paths"): the three orientation
// forms, exact round trip, ground-truth image I/O, and one test per parse error.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <string>

#include "calf/capture/eye_path.h"

namespace calf::capture {
namespace {

std::string path_json(const std::string& pose, const std::string& top = "") {
  return R"({"format": "calf-eye-path", "version": 1, "width": 64, "height": 48, )" + top +
         R"("poses": [)" + pose + "]}";
}

void expect_near(const Vec3& a, const Vec3& b) {
  EXPECT_NEAR(a.x, b.x, 1e-12);
  EXPECT_NEAR(a.y, b.y, 1e-12);
  EXPECT_NEAR(a.z, b.z, 1e-12);
}

void expect_error(const std::string& json, ErrorId id, const std::string& needle) {
  auto p = parse_eye_path(json, "gt/eye_path.json");
  ASSERT_FALSE(p.ok()) << json;
  EXPECT_EQ(p.status().id(), id) << p.status().to_string();
  EXPECT_NE(p.status().message().find(needle), std::string::npos) << p.status().to_string();
}

TEST(EyePath, OrientationForms) {
  auto p =
      parse_eye_path(path_json(R"({"time": 0, "position": [0, 1, 0], "forward": [2, 0, 0]},
                   {"time": 0.5, "position": [0, 1, 0], "look_at": [0, 1, -5], "up": [0, 3, 1],
                    "fov_y_degrees": 90, "eye": "left"},
                   {"time": 1, "position": [1, 2, 3], "orientation": [0.7071067811865476, 0, 0.7071067811865476, 0],
                    "eye": "right"})",
                               R"("fov_y_degrees": 45, "image_pattern": "gt_{pose:04}.exr", )"),
                     "p");
  ASSERT_TRUE(p.ok()) << p.status().to_string();
  ASSERT_EQ(p->poses.size(), 3u);
  EXPECT_EQ(p->width, 64u);
  EXPECT_EQ(p->height, 48u);
  expect_near(p->poses[0].forward, {1, 0, 0});
  expect_near(p->poses[0].up, {0, 1, 0});
  EXPECT_EQ(p->poses[0].fov_y_degrees, 45);  // the path's default
  EXPECT_EQ(p->poses[0].eye, Eye::kMono);
  expect_near(p->poses[1].forward, {0, 0, -1});
  expect_near(p->poses[1].up, {0, 1, 0});  // re-orthogonalised against forward
  EXPECT_EQ(p->poses[1].fov_y_degrees, 90);
  EXPECT_EQ(p->poses[1].eye, Eye::kLeft);
  // A quarter turn about +Y takes the camera's -Z to -X.
  expect_near(p->poses[2].forward, {-1, 0, 0});
  expect_near(p->poses[2].up, {0, 1, 0});
  EXPECT_EQ(p->poses[2].eye, Eye::kRight);
  EXPECT_EQ(eye_image_file_name(*p, 7), "gt_0007.exr");
}

// A pose becomes the one camera model with the path's image size; degrees become radians as
// (degrees * pi) / 180.
TEST(EyePath, CameraFromPose) {
  EyePath path;
  path.width = 640;
  path.height = 360;
  EyePose pose;
  pose.position = {1, 2, 3};
  pose.forward = {0, 0, -1};
  pose.up = {0, 1, 0};
  pose.fov_y_degrees = 90;
  path.poses = {pose, pose};
  path.poses[1].fov_y_degrees = 60;
  const Camera c = camera_from_pose(pose, 8, 4);
  EXPECT_EQ(c.position, (Vec3{1, 2, 3}));
  EXPECT_EQ(c.forward, (Vec3{0, 0, -1}));
  EXPECT_EQ(c.up, (Vec3{0, 1, 0}));
  EXPECT_DOUBLE_EQ(c.fov_y, 1.5707963267948966);  // pi / 2
  EXPECT_EQ(c.width, 8u);
  EXPECT_EQ(c.height, 4u);
  const Camera d = camera_from_pose(path, 1);
  EXPECT_DOUBLE_EQ(d.fov_y, 1.0471975511965976);  // pi / 3
  EXPECT_EQ(d.width, 640u);
  EXPECT_EQ(d.height, 360u);
  EXPECT_TRUE(validate_camera(d).ok());
}

TEST(EyePath, RoundTripIsExact) {
  auto p = parse_eye_path(
      path_json(R"({"time": 0.1, "position": [0.1, 1.7, -0.3], "look_at": [1, 0.2, -3]},
                   {"time": 0.2, "position": [0.2, 1.6, -0.2], "orientation": [0.9, 0.1, 0.3, 0.2989983]})"),
      "p");
  ASSERT_TRUE(p.ok()) << p.status().to_string();
  std::string text = serialize_eye_path(*p);
  auto back = parse_eye_path(text, "q");
  ASSERT_TRUE(back.ok()) << back.status().to_string();
  EXPECT_EQ(*back, *p);
  EXPECT_EQ(serialize_eye_path(*back), text);
}

TEST(EyePath, Errors) {
  const std::string pos = R"("time": 0, "position": [0, 0, 0])";
  expect_error("{", ErrorId::kManifestSyntax, "byte");
  expect_error(R"({"format": "calf-eye-path", "version": 3, "poses": []})",
               ErrorId::kManifestVersion, "version 3");
  std::string zero_width = path_json("{" + pos + R"(, "forward": [0, 0, -1]})");
  zero_width.replace(zero_width.find("\"width\": 64"), 11, "\"width\": 0");
  expect_error(zero_width, ErrorId::kEyePathField, "'width'");
  expect_error(path_json(""), ErrorId::kEyePathField, "'poses'");
  expect_error(path_json(R"({"position": [0, 0, 0], "forward": [0, 0, -1]})"),
               ErrorId::kEyePathField, "'poses[0].time': missing");
  expect_error(path_json("{" + pos + "}"), ErrorId::kEyePathField, "exactly one of");
  expect_error(path_json("{" + pos + R"(, "forward": [0, 0, -1], "look_at": [0, 0, 1]})"),
               ErrorId::kEyePathField, "exactly one of");
  expect_error(path_json("{" + pos + R"(, "forward": [0, 0, 0]})"), ErrorId::kEyePathField,
               "parallel");
  expect_error(path_json("{" + pos + R"(, "forward": [0, 2, 0]})"), ErrorId::kEyePathField,
               "parallel");
  expect_error(path_json("{" + pos + R"(, "look_at": [0, 0, 0]})"), ErrorId::kEyePathField,
               "parallel");
  expect_error(path_json("{" + pos + R"(, "orientation": [1, 1, 0, 0]})"), ErrorId::kEyePathField,
               "not 1");
  expect_error(path_json("{" + pos + R"(, "orientation": [1, 0, 0]})"), ErrorId::kEyePathField,
               "'poses[0].orientation'");
  expect_error(path_json("{" + pos + R"(, "orientation": [1, 0, 0, 0], "up": [0, 1, 0]})"),
               ErrorId::kEyePathField, "'poses[0].up'");
  expect_error(path_json("{" + pos + R"(, "forward": [0, 0, -1], "fov_y_degrees": 180})"),
               ErrorId::kEyePathField, "fov_y_degrees");
  expect_error(path_json("{" + pos + R"(, "forward": [0, 0, -1], "eye": "centre"})"),
               ErrorId::kEyePathField, "'poses[0].eye'");
  expect_error(path_json("{" + pos + R"(, "forward": [0, 0, -1], "roll": 3})"),
               ErrorId::kEyePathField, "'poses[0].roll': unknown key");
  expect_error(
      path_json("{" + pos + R"(, "forward": [0, 0, -1]})", R"("image_pattern": "gt.exr", )"),
      ErrorId::kEyePathField, "image_pattern");
  expect_error(path_json("{" + pos + R"(, "forward": [0, "a", -1]})"), ErrorId::kEyePathField,
               "'poses[0].forward[1]'");
}

// One coordinate bound (calf/format/coordinates.h) for positions and look_at targets; a direction
// is not a coordinate: [1e300, 1e300, 0] has a finite direction even though its length overflows.
TEST(EyePath, CoordinatesAndHugeDirections) {
  expect_error(path_json(R"({"time": 0, "position": [1e20, 1.6, 0], "forward": [0, 0, -1]})"),
               ErrorId::kEyePathField,
               "'poses[0].position': (1e+20, 1.6, 0) is not finite and within +-1e+12");
  expect_error(path_json(R"({"time": 0, "position": [0, 1.6, 0], "look_at": [0, 1e300, -1]})"),
               ErrorId::kEyePathField, "'poses[0].look_at'");
  auto p = parse_eye_path(
      path_json(R"({"time": 0, "position": [1e12, 1.6, -1e12], "forward": [1e300, 1e300, 0]},
                   {"time": 0, "position": [0, 0, 0], "forward": [0, 0, -1e-300], "up": [0, 1e308, 0]})"),
      "p");
  ASSERT_TRUE(p.ok()) << p.status().to_string();
  expect_near(p->poses[0].forward, {std::sqrt(0.5), std::sqrt(0.5), 0});
  expect_near(p->poses[0].up, {-std::sqrt(0.5), std::sqrt(0.5), 0});
  expect_near(p->poses[1].forward, {0, 0, -1});
  expect_near(p->poses[1].up, {0, 1, 0});
  // Zero stays zero, and a huge direction parallel to up is still parallel.
  expect_error(path_json(R"({"time": 0, "position": [0, 0, 0], "forward": [0, 1e300, 0]})"),
               ErrorId::kEyePathField, "parallel");
}

// A directory or a missing file given as an eye path (or as a capture set's manifest) is a clear
// open error naming it (libstdc++'s filebuf throws on reading a directory; nothing may escape).
TEST(EyePath, NonFilesAreOpenErrorsNamingThePath) {
  const auto dir = std::filesystem::temp_directory_path() / "calf_eye_path_test_dir";
  std::filesystem::create_directories(dir);
  auto r = read_eye_path(dir);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().id(), ErrorId::kFileOpen);
  EXPECT_NE(r.status().message().find(dir.string() + ": cannot open (a directory)"),
            std::string::npos)
      << r.status().message();
  // A capture set whose manifest.json is a directory: the same error, not an exception.
  std::filesystem::create_directories(dir / "manifest.json");
  auto set = CaptureSetReader::open(dir);
  ASSERT_FALSE(set.ok());
  EXPECT_EQ(set.status().id(), ErrorId::kFileOpen);
  EXPECT_NE(set.status().message().find("manifest.json: cannot open (a directory)"),
            std::string::npos)
      << set.status().message();
  std::filesystem::remove_all(dir);
  r = read_eye_path(dir / "eye_path.json");
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().id(), ErrorId::kFileOpen);
  EXPECT_NE(r.status().message().find("eye_path.json: cannot open"), std::string::npos);
}

TEST(EyePath, GroundTruthImageRoundTrip) {
  PerspectiveImage img;
  img.width = 5;
  img.height = 3;
  img.color.resize(45);
  img.depth.resize(15);
  for (size_t i = 0; i < 15; ++i) {
    for (int c = 0; c < 3; ++c) img.color[3 * i + c] = static_cast<float>(i + c) * 0.5f;
    img.depth[i] =
        i == 4 ? std::numeric_limits<float>::infinity() : 1.0f + static_cast<float>(i) / 7;
  }
  auto file = std::filesystem::temp_directory_path() / "calf_eye_path_test_gt.exr";
  ASSERT_TRUE(write_perspective_image(file, img).ok());
  auto back = read_perspective_image(file);
  ASSERT_TRUE(back.ok()) << back.status().to_string();
  EXPECT_EQ(back->width, 5u);
  EXPECT_EQ(back->height, 3u);
  EXPECT_EQ(back->color, img.color);
  EXPECT_EQ(back->depth, img.depth);
  std::filesystem::remove(file);
  EXPECT_EQ(read_perspective_image(file).status().id(), ErrorId::kCaptureFileMissing);
}

}  // namespace
}  // namespace calf::capture
