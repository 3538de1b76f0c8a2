// Capture manifest (calf/capture/capture_set.h, format/CAPTURE.md "Manifest"): exact round trip,
// and one test per rule of the validator, each checking the error id and what the message names.
#include <gtest/gtest.h>

#include <limits>
#include <string>

#include "calf/capture/capture_set.h"

namespace calf::capture {
namespace {

CaptureManifest sample_manifest() {
  CaptureManifest m;
  m.frame_count = 24;
  m.fps = 23.976;
  m.face_size = 128;
  m.view_volume = {{-0.1, 1.3, -0.5}, {0.1, 1.9, 0.5}};
  // Doubles that do not print exactly in decimal: the round trip must keep every bit.
  m.viewpoints = {{"centre", {0.1, 1.6, 1.0 / 3}}, {"corner", {-1e-300, 2.5e10, -3.75}}};
  m.material = true;
  m.scene = "mirror-box";
  m.generator = "test";
  return m;
}

// A valid manifest as JSON text with one substitution applied ("" = unchanged).
std::string manifest_json(const std::string& from = "", const std::string& to = "") {
  std::string text = serialize_manifest(sample_manifest());
  if (!from.empty()) {
    size_t at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    if (at != std::string::npos) text.replace(at, from.size(), to);
  }
  return text;
}

void expect_error(const std::string& json, ErrorId id, const std::string& needle) {
  auto m = parse_manifest(json, "set/manifest.json");
  ASSERT_FALSE(m.ok()) << json;
  EXPECT_EQ(m.status().id(), id) << m.status().to_string();
  EXPECT_NE(m.status().message().find(needle), std::string::npos) << m.status().to_string();
  EXPECT_EQ(m.status().message().rfind("set/manifest.json", 0), 0u) << m.status().to_string();
}

TEST(CaptureManifest, RoundTripIsExact) {
  CaptureManifest m = sample_manifest();
  ASSERT_TRUE(validate_manifest(m).ok()) << validate_manifest(m).to_string();
  std::string text = serialize_manifest(m);
  auto back = parse_manifest(text, "x");
  ASSERT_TRUE(back.ok()) << back.status().to_string();
  EXPECT_EQ(*back, m);
  EXPECT_EQ(serialize_manifest(*back), text);
}

TEST(CaptureManifest, FileNames) {
  CaptureManifest m = sample_manifest();
  EXPECT_EQ(capture_file_name(m, 3, 17), "view003_frame00017.exr");
  m.file_pattern = "f{frame}-v{view:02}.exr";
  EXPECT_EQ(capture_file_name(m, 3, 1234), "f1234-v03.exr");
}

TEST(CaptureManifest, OptionalFieldsAndExtensions) {
  // No material, scene, generator or viewpoint names; an x- extension key is ignored.
  std::string json = R"({"format": "calf-capture-set", "version": 1, "frame_count": 2, "fps": 30,
    "face_size": 16, "file_pattern": "v{view}_f{frame}.exr", "x-renderer": {"spp": 64},
    "view_volume": {"min": [0, 0, 0], "max": [1, 1, 1]},
    "viewpoints": [{"position": [0, 0, 0]}, {"position": [1, 1, 1]}]})";
  auto m = parse_manifest(json, "m");
  ASSERT_TRUE(m.ok()) << m.status().to_string();
  EXPECT_FALSE(m->material);
  EXPECT_EQ(m->viewpoints[1].name, "view1");
  EXPECT_EQ(m->fps, 30.0);
}

TEST(CaptureManifest, SyntaxError) {
  expect_error("{\"format\": ", ErrorId::kManifestSyntax, "byte");
  expect_error("[1, 2]", ErrorId::kManifestSyntax, "JSON object");
  expect_error("", ErrorId::kManifestSyntax, "not valid JSON");
}

TEST(CaptureManifest, FormatAndVersion) {
  expect_error(manifest_json("\"calf-capture-set\"", "\"seurat\""), ErrorId::kManifestVersion,
               "seurat");
  expect_error(manifest_json("\"version\": 1", "\"version\": 3"), ErrorId::kManifestVersion,
               "version 3");
}

TEST(CaptureManifest, FieldErrorsNameTheField) {
  expect_error(manifest_json("\"fps\": 23.976,", ""), ErrorId::kManifestField, "'fps': missing");
  expect_error(manifest_json("\"face_size\": 128", "\"face_size\": \"128\""),
               ErrorId::kManifestField, "'face_size': expected an integer");
  expect_error(manifest_json("\"face_size\": 128", "\"face_size\": -4"), ErrorId::kManifestField,
               "'face_size'");
  expect_error(manifest_json("\"face_size\": 128", "\"face_size\": 0"), ErrorId::kManifestField,
               "'face_size': is 0");
  expect_error(manifest_json("\"frame_count\": 24", "\"frame_count\": 0"), ErrorId::kManifestField,
               "'frame_count'");
  expect_error(manifest_json("\"fps\": 23.976", "\"fps\": 0"), ErrorId::kManifestField, "'fps'");
  expect_error(manifest_json("\"material\": true", "\"material\": 1"), ErrorId::kManifestField,
               "'material'");
  expect_error(manifest_json("\"material\": true", "\"material\": true, \"colour\": 1"),
               ErrorId::kManifestField, "'colour': unknown key");
  expect_error(manifest_json("\"name\": \"corner\"", "\"name\": \"corner\", \"fov\": 90"),
               ErrorId::kManifestField, "'viewpoints[1].fov'");
  expect_error(manifest_json("-3.75", "\"a\""), ErrorId::kManifestField,
               "'viewpoints[1].position[2]'");
  expect_error(manifest_json("\"viewpoints\": [", "\"viewpoints\": [1, "), ErrorId::kManifestField,
               "viewpoints[0]");
}

// One coordinate bound (calf/format/coordinates.h): a finite viewpoint at 1e300 is refused when
// the manifest is read, naming the field, instead of reaching the encoder and player.
TEST(CaptureManifest, CoordinatesBeyondTheBoundAreRefused) {
  expect_error(manifest_json("-3.75", "1e300"), ErrorId::kManifestField,
               "'viewpoints[1].position': (-1e-300, 2.5e+10, 1e+300) is not finite and within "
               "+-1e+12");
  expect_error(manifest_json("-3.75", "-1.0000001e12"), ErrorId::kManifestField,
               "'viewpoints[1].position'");
  auto at_bound = parse_manifest(manifest_json("-3.75", "-1e12"), "m");
  EXPECT_TRUE(at_bound.ok()) << at_bound.status().to_string();
  CaptureManifest m = sample_manifest();
  m.view_volume.max.y = 2e12;
  Status st = validate_manifest(m);
  EXPECT_EQ(st.id(), ErrorId::kManifestField);
  EXPECT_NE(st.message().find("'view_volume.max'"), std::string::npos) << st.to_string();
}

TEST(CaptureManifest, Limits) {
  expect_error(manifest_json("\"face_size\": 128", "\"face_size\": 16385"), ErrorId::kCaptureLimit,
               "16384");
  expect_error(manifest_json("\"frame_count\": 24", "\"frame_count\": 1000001"),
               ErrorId::kCaptureLimit, "frame_count");
  std::string many = "\"viewpoints\": [";
  for (int i = 0; i < 4097; ++i)
    many += std::string(i ? "," : "") + "{\"position\": [" + std::to_string(i) + ", 0, 0]}";
  std::string json = manifest_json();
  size_t at = json.find("\"viewpoints\": [");
  json = json.substr(0, at) + many + "]}";
  expect_error(json, ErrorId::kCaptureLimit, "4096");
}

TEST(CaptureManifest, Inconsistencies) {
  expect_error(manifest_json("\"corner\"", "\"centre\""), ErrorId::kManifestInconsistent,
               "'viewpoints[1].name'");
  CaptureManifest m = sample_manifest();
  m.viewpoints[1].position = m.viewpoints[0].position;
  expect_error(serialize_manifest(m), ErrorId::kManifestInconsistent, "'viewpoints[1].position'");
  m = sample_manifest();
  m.view_volume.min.y = 5;
  expect_error(serialize_manifest(m), ErrorId::kManifestInconsistent, "view_volume");
  for (const char* bad : {"view{view}.exr", "{view}{frame}.exr", "a/{view}_{frame}.exr",
                          "{view}_{frame}.png", ".{view}_{frame}.exr", "{view}_{frame}_{view}.exr",
                          "{view:3}_{frame}.exr", "{view}_{frame}_{pose}.exr", "{view}_{frame.exr",
                          "{view} {frame}.exr", "{view}1{frame}.exr"}) {
    m = sample_manifest();
    m.file_pattern = bad;
    expect_error(serialize_manifest(m), ErrorId::kManifestInconsistent, "file_pattern");
  }
}

TEST(CaptureManifest, ValidateInMemory) {
  CaptureManifest m = sample_manifest();
  m.viewpoints.clear();
  EXPECT_EQ(validate_manifest(m).id(), ErrorId::kManifestField);
  m = sample_manifest();
  m.viewpoints[0].name = "";
  EXPECT_EQ(validate_manifest(m).id(), ErrorId::kManifestField);
  m = sample_manifest();
  m.viewpoints[1].position.x = std::numeric_limits<double>::infinity();
  EXPECT_EQ(validate_manifest(m).id(), ErrorId::kManifestField);
  m = sample_manifest();
  m.version = 7;
  EXPECT_EQ(validate_manifest(m).id(), ErrorId::kManifestVersion);
}

}  // namespace
}  // namespace calf::capture
