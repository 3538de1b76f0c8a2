// Scene files (calf/capture/scene_file.h, format/SCENE.md): an exact round trip of a scene using
// every feature, a hand-written file read to known values, and one test per malformed case, each
// checking the error id and what the message names.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "calf/capture/scene_file.h"

namespace calf::capture {
namespace {

namespace fs = std::filesystem;

// A scene with every feature: a textured quad with normals, colours, UVs, per-triangle materials
// and two vertex states, instanced twice (static and per-frame transforms); a sphere-only mesh;
// a light with a constant position and a per-frame intensity.
SceneFile sample_scene() {
  SceneFile s;
  s.name = "sample";
  s.description = "every feature once";
  s.generator = "scene_file_test";
  s.fps = 23.976;
  s.frame_count = 3;
  s.view_volume = {{-0.5, 1.25, 1.0 / 3}, {0.5, 1.75, 1}};
  s.environment.sun_irradiance = {2, 1.5f, 1};
  s.environment.ambient = {0.1f, 0.2f, 0.3f};
  s.textures.push_back({"textures/checker.png",
                        2,
                        2,
                        {255, 0, 0, 255, 0, 255, 0, 255,  //
                         0, 0, 255, 128, 10, 20, 30, 0}});
  SceneMaterial textured;
  textured.name = "checker";
  textured.base_color = {1, 1, 1};
  textured.base_color_texture = 0;
  SceneMaterial mirror;
  mirror.name = "mirror";
  mirror.base_color = {0.1f, 0.2f, 0.3f};
  mirror.emission = {5, 0, 0.25f};
  mirror.reflect = 0.75f;
  mirror.refract = 0.25f;
  mirror.ior = 1.33f;
  s.materials = {textured, mirror};
  SceneMesh quad;
  quad.name = "quad";
  quad.positions = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
  quad.normals = {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0.6f, 0.8f};
  quad.colors = {1, 0, 0, 0, 1, 0, 0, 0, 1, 0.5f, 0.5f, 0.5f};
  quad.uvs = {0, 0, 1, 0, 1, 1, 0, 1};
  quad.indices = {0, 1, 2, 0, 2, 3};
  quad.triangle_materials = {0, 1};
  quad.state_times = {0, 0.5f};
  quad.state_positions = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0,  //
                          0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1};
  SceneMesh ball;
  ball.name = "ball";
  ball.spheres = {{{0, 1, 2}, 0.5f}, {{-1e-30f, 3e30f, 0}, 1e-3f}};
  s.meshes = {quad, ball};
  SceneObject a{"quad-a", 0, 0, {{1, 0, 0, 2, 0, 1, 0, 0, 0, 0, 1, -1}}};
  SceneObject b{"quad-b", 0, 1, {}};
  for (int f = 0; f < 3; ++f) b.transforms.push_back({1, 0, 0, 0.1f * f, 0, 1, 0, 0, 0, 0, 1, 0});
  SceneObject c{"ball", 1, 1, {}};
  s.objects = {a, b, c};
  s.lights.push_back({"lamp", {{0, 3, 0}}, {{1, 1, 1}, {2, 2, 2}, {3, 3, 3.5f}}});
  return s;
}

// ---- bytes written by hand, independent of the writer ----

void put_f32(std::string* out, float v) {
  uint32_t bits;
  std::memcpy(&bits, &v, 4);
  for (int i = 0; i < 4; ++i) out->push_back(static_cast<char>(bits >> (8 * i) & 0xff));
}
void put_u32(std::string* out, uint32_t v) {
  for (int i = 0; i < 4; ++i) out->push_back(static_cast<char>(v >> (8 * i) & 0xff));
}

// One triangle, one material, one object translated by (0, 0, -3): bytes [0, 36) positions,
// [36, 48) the triangle, [48, 96) the transform.
std::string minimal_buffer() {
  std::string b;
  for (float v : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f}) put_f32(&b, v);
  for (uint32_t i : {0u, 1u, 2u}) put_u32(&b, i);
  for (float v : {1.f, 0.f, 0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 0.f, 1.f, -3.f}) put_f32(&b, v);
  return b;
}

const char* const kMinimalJson = R"({
  "format": "calf-scene", "version": 1, "name": "minimal", "fps": 24, "frame_count": 2,
  "view_region": {"min": [0, 1, 0], "max": [1, 2, 1]},
  "buffers": [{"uri": "scene.bin", "byte_length": 96}],
  "materials": [{"base_color": [0.5, 0.25, 1], "ior": 1.25}],
  "meshes": [{"positions": {"buffer": 0, "offset": 0, "count": 3},
              "triangles": {"buffer": 0, "offset": 36, "count": 1}}],
  "objects": [{"mesh": 0, "material": 0, "transforms": {"buffer": 0, "offset": 48, "count": 1}}]
})";

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

Expected<SceneFile> parse(const std::string& json, const std::string& buffer) {
  std::string_view views[1] = {buffer};
  return parse_scene_file(json, views, "dir/scene.json");
}

void expect_error(const Expected<SceneFile>& s, ErrorId id, const std::string& needle) {
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.status().id(), id) << s.status().to_string();
  EXPECT_NE(s.status().message().find(needle), std::string::npos) << s.status().to_string();
}

void expect_json_error(const std::string& from, const std::string& to, ErrorId id,
                       const std::string& needle) {
  SCOPED_TRACE(to);
  auto s = parse(replaced(kMinimalJson, from, to), minimal_buffer());
  expect_error(s, id, needle);
  if (!s.ok()) {
    EXPECT_EQ(s.status().message().rfind("dir/scene.json", 0), 0u);
  }
}

class SceneFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("calf_scene_file_test_" +
            std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  void write(const std::string& name, const std::string& bytes) {
    fs::create_directories((dir_ / name).parent_path());
    std::ofstream(dir_ / name, std::ios::binary) << bytes;
  }
  void write_minimal() {
    write("scene.json", kMinimalJson);
    write("scene.bin", minimal_buffer());
  }
  fs::path dir_;
};

TEST(SceneFile, SampleSceneIsValid) {
  SceneFile s = sample_scene();
  EXPECT_TRUE(validate_scene_file(s).ok()) << validate_scene_file(s).to_string();
  EXPECT_EQ(s.triangle_count(), 4u);       // two instances of two triangles
  EXPECT_EQ(s.mesh_triangle_count(), 2u);  // the prototype once
}

TEST_F(SceneFileTest, RoundTripThroughFilesIsExact) {
  SceneFile s = sample_scene();
  ASSERT_TRUE(write_scene_file(s, dir_).ok());
  EXPECT_TRUE(fs::is_regular_file(dir_ / "scene.json"));
  EXPECT_TRUE(fs::is_regular_file(dir_ / "scene.bin"));
  EXPECT_TRUE(fs::is_regular_file(dir_ / "textures/checker.png"));
  for (const auto& entry : fs::recursive_directory_iterator(dir_)) {
    // No temporary file (calf/format/files.h names them <file>.tmp-<host>-<pid>-<n>).
    EXPECT_EQ(entry.path().filename().string().find(".tmp"), std::string::npos) << entry.path();
  }
  auto back = read_scene_file(dir_);
  ASSERT_TRUE(back.ok()) << back.status().to_string();
  EXPECT_EQ(*back, s);
  // Deterministic: the scene read back encodes to the same bytes.
  auto first = encode_scene_file(s), second = encode_scene_file(*back);
  ASSERT_TRUE(first.ok() && second.ok());
  EXPECT_EQ(first->manifest, second->manifest);
  EXPECT_EQ(first->buffer, second->buffer);
}

TEST(SceneFile, InMemoryRoundTripKeepsTexturePathsOnly) {
  SceneFile s = sample_scene();
  auto encoded = encode_scene_file(s);
  ASSERT_TRUE(encoded.ok()) << encoded.status().to_string();
  auto back = parse(encoded->manifest, encoded->buffer);
  ASSERT_TRUE(back.ok()) << back.status().to_string();
  s.textures[0] = {"textures/checker.png", 0, 0, {}};
  EXPECT_EQ(*back, s);
}

TEST(SceneFile, ManifestIsReadableJson) {
  auto encoded = encode_scene_file(sample_scene());
  ASSERT_TRUE(encoded.ok());
  const std::string& m = encoded->manifest;
  EXPECT_EQ(m.rfind("{\n  \"format\": \"calf-scene\",\n  \"version\": 1,", 0), 0u) << m;
  EXPECT_NE(m.find("\"ior\": 1.33\n"), std::string::npos)
      << "floats print as their shortest decimal";
  // Buffer bytes: the quad's positions first, little-endian.
  std::string expected;
  for (float v : {0.f, 0.f, 0.f, 1.f}) put_f32(&expected, v);
  EXPECT_EQ(encoded->buffer.substr(0, 16), expected);
}

// The surfel mode's factory: 20 M triangles counting instances. Instances share their
// prototype, so the file holds one 20,000-triangle part and 1,000 transforms.
TEST(SceneFile, InstancedTwentyMillionTriangles) {
  SceneFile s;
  s.frame_count = 1;
  s.materials.resize(1);
  SceneMesh part;
  const uint32_t n = 100;  // n x n quads
  for (uint32_t y = 0; y <= n; ++y) {
    for (uint32_t x = 0; x <= n; ++x)
      part.positions.insert(part.positions.end(), {1.f * x, 1.f * y, 0});
  }
  for (uint32_t y = 0; y < n; ++y) {
    for (uint32_t x = 0; x < n; ++x) {
      uint32_t a = y * (n + 1) + x, b = a + 1, c = a + n + 2, d = a + n + 1;
      part.indices.insert(part.indices.end(), {a, b, c, a, c, d});
    }
  }
  s.meshes.push_back(std::move(part));
  for (int i = 0; i < 1000; ++i) {
    s.objects.push_back({"", 0, 0, {{1, 0, 0, 200.f * i, 0, 1, 0, 0, 0, 0, 1, 0}}});
  }
  ASSERT_EQ(s.triangle_count(), 20000000u);
  auto encoded = encode_scene_file(s);
  ASSERT_TRUE(encoded.ok()) << encoded.status().to_string();
  EXPECT_EQ(encoded->buffer.size(), 101u * 101 * 12 + 20000 * 12 + 1000 * 48);
  EXPECT_LT(encoded->manifest.size(), 200000u);
  auto back = parse(encoded->manifest, encoded->buffer);
  ASSERT_TRUE(back.ok()) << back.status().to_string();
  EXPECT_EQ(back->triangle_count(), 20000000u);
  EXPECT_EQ(back->mesh_triangle_count(), 20000u);
}

TEST(SceneFile, SamplesAtTimes) {
  SceneFile s = sample_scene();
  // Quad states: z = 0 at t = 0, z = 1 at t = 0.5; held outside.
  std::vector<float> p;
  positions_at(s.meshes[0], 0.25, &p);
  ASSERT_EQ(p.size(), 12u);
  EXPECT_FLOAT_EQ(p[2], 0.5f);
  EXPECT_FLOAT_EQ(p[3], 1.0f);  // x of vertex 1 stays 1
  positions_at(s.meshes[0], -1, &p);
  EXPECT_EQ(p[2], 0.0f);
  positions_at(s.meshes[0], 0.5, &p);
  EXPECT_EQ(p[2], 1.0f);
  positions_at(s.meshes[0], 9, &p);
  EXPECT_EQ(p[11], 1.0f);
  positions_at(s.meshes[1], 0.3, &p);  // no states, no vertices
  EXPECT_TRUE(p.empty());
  SceneMesh still;
  still.positions = {1, 2, 3};
  positions_at(still, 7, &p);
  EXPECT_EQ(p, (std::vector<float>{1, 2, 3}));
  EXPECT_EQ(transform_at(s.objects[2], 1), kSceneIdentity);
  EXPECT_EQ(transform_at(s.objects[0], 2)[3], 2.0f);  // static
  EXPECT_FLOAT_EQ(transform_at(s.objects[1], 2)[3], 0.2f);
  EXPECT_FLOAT_EQ(transform_at(s.objects[1], 7)[3], 0.2f);  // clamped to the last frame
  EXPECT_EQ(sample_at(s.lights[0].positions, 2), (SceneFloat3{0, 3, 0}));
  EXPECT_EQ(sample_at(s.lights[0].intensities, 2), (SceneFloat3{3, 3, 3.5f}));
}

TEST_F(SceneFileTest, HandWrittenMinimalFile) {
  write_minimal();
  auto s = read_scene_file(dir_);
  ASSERT_TRUE(s.ok()) << s.status().to_string();
  EXPECT_EQ(s->name, "minimal");
  EXPECT_EQ(s->fps, 24);
  EXPECT_EQ(s->frame_count, 2u);
  EXPECT_EQ(s->view_volume, (Box3{{0, 1, 0}, {1, 2, 1}}));
  ASSERT_EQ(s->materials.size(), 1u);
  EXPECT_EQ(s->materials[0].base_color, (SceneFloat3{0.5f, 0.25f, 1}));
  EXPECT_EQ(s->materials[0].ior, 1.25f);
  EXPECT_EQ(s->materials[0].reflect, 0);
  EXPECT_EQ(s->materials[0].base_color_texture, kNoTexture);
  ASSERT_EQ(s->meshes.size(), 1u);
  EXPECT_EQ(s->meshes[0].positions, (std::vector<float>{0, 0, 0, 1, 0, 0, 0, 1, 0}));
  EXPECT_EQ(s->meshes[0].indices, (std::vector<uint32_t>{0, 1, 2}));
  EXPECT_TRUE(s->meshes[0].normals.empty());
  ASSERT_EQ(s->objects.size(), 1u);
  ASSERT_EQ(s->objects[0].transforms.size(), 1u);
  EXPECT_EQ(s->objects[0].transforms[0][11], -3.0f);
  EXPECT_EQ(s->objects[0].transforms[0][0], 1.0f);
  EXPECT_TRUE(s->lights.empty());
  // Defaults of the absent environment.
  EXPECT_EQ(s->environment, SceneEnvironment{});
}

TEST(SceneFile, VersionAndSyntax) {
  expect_json_error("\"version\": 1", "\"version\": 2", ErrorId::kSceneFileVersion, "version");
  expect_json_error("\"format\": \"calf-scene\"", "\"format\": \"calf-capture-set\"",
                    ErrorId::kSceneFileVersion, "format");
  expect_json_error("\"fps\": 24,", "\"fps\": 24", ErrorId::kSceneFileSyntax, "not valid JSON");
  expect_error(parse("[1, 2]", ""), ErrorId::kSceneFileSyntax, "top level");
}

TEST(SceneFile, Fields) {
  expect_json_error("\"fps\": 24", "\"fps\": 24, \"colour\": 1", ErrorId::kSceneFileField,
                    "'colour': unknown key");
  EXPECT_TRUE(
      parse(replaced(kMinimalJson, "\"fps\": 24", "\"fps\": 24, \"x-note\": 1"), minimal_buffer())
          .ok())
      << "keys starting x- are extensions";
  expect_json_error("\"fps\": 24", "\"fps\": \"24\"", ErrorId::kSceneFileField, "'fps'");
  expect_json_error("\"fps\": 24", "\"fps\": 0", ErrorId::kSceneFileField, "fps 0");
  expect_json_error("\"frame_count\": 2", "\"frame_count\": 0", ErrorId::kSceneFileField,
                    "frame_count");
  expect_json_error("\"frame_count\": 2", "\"frame_count\": 1000001", ErrorId::kSceneFileLimit,
                    "frame_count");
  expect_json_error("\"max\": [1, 2, 1]", "\"max\": [1, 0, 1]", ErrorId::kSceneFileField,
                    "min exceeds max");
  expect_json_error("\"base_color\": [0.5, 0.25, 1]", "\"base_color\": [0.5, 0.25, 2]",
                    ErrorId::kSceneFileValue, "materials[0]");
  expect_json_error("\"ior\": 1.25", "\"ior\": 1e39", ErrorId::kSceneFileValue, "materials[0].ior");
  // Two transforms in a three-frame scene: neither static nor one per frame.
  std::string json =
      replaced(kMinimalJson, "\"offset\": 48, \"count\": 1", "\"offset\": 48, \"count\": 2");
  json = replaced(json, "\"byte_length\": 96", "\"byte_length\": 144");
  json = replaced(json, "\"frame_count\": 2", "\"frame_count\": 3");
  expect_error(parse(json, minimal_buffer() + minimal_buffer().substr(48)),
               ErrorId::kSceneFileField, "objects[0]: 2 transforms");
}

TEST(SceneFile, Indices) {
  expect_json_error("\"mesh\": 0", "\"mesh\": 1", ErrorId::kSceneFileIndex, "objects[0]: mesh 1");
  expect_json_error("\"material\": 0", "\"material\": 3", ErrorId::kSceneFileIndex,
                    "objects[0]: material 3");
  expect_json_error("\"ior\": 1.25", "\"ior\": 1.25, \"base_color_texture\": 0",
                    ErrorId::kSceneFileIndex, "base_color_texture 0 of 0");
  std::string buffer = minimal_buffer();
  buffer[40] = 3;  // the second index: vertex 3 of 3
  expect_error(parse(kMinimalJson, buffer), ErrorId::kSceneFileIndex,
               "meshes[0]: triangle 0 names vertex 3 of 3");
}

TEST(SceneFile, NonFiniteValues) {
  std::string buffer = minimal_buffer();
  std::string nan;
  put_f32(&nan, std::numeric_limits<float>::quiet_NaN());
  buffer.replace(12, 4, nan);  // vertex 1, x
  expect_error(parse(kMinimalJson, buffer), ErrorId::kSceneFileValue,
               "vertex 1: position is not finite");
  buffer = minimal_buffer();
  std::string inf;
  put_f32(&inf, std::numeric_limits<float>::infinity());
  buffer.replace(92, 4, inf);  // the transform's translation z
  expect_error(parse(kMinimalJson, buffer), ErrorId::kSceneFileValue,
               "objects[0]: transform 0 is not finite");
}

// Transforms are rigid or uniformly scaled: a singular, zero or absurdly scaled one, or one that
// translates beyond the coordinate bound, is refused naming the object.
TEST(SceneFile, DegenerateTransforms) {
  struct Case {
    SceneTransform t;
    const char* what;
  };
  const Case cases[] = {
      {{0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0}, "zero"},
      {{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0}, "singular"},
      {{1e30f, 0, 0, 0, 0, 1e30f, 0, 0, 0, 0, 1e30f, 0}, "1e30"},
      {{1e-8f, 0, 0, 0, 0, 1e-8f, 0, 0, 0, 0, 1e-8f, 0}, "1e-8"},
      {{1, 0, 0, 2e12f, 0, 1, 0, 0, 0, 0, 1, 0}, "far"},
  };
  for (const Case& c : cases) {
    SceneFile s = sample_scene();
    s.objects[0].transforms.assign(1, c.t);
    const Status st = validate_scene_file(s);
    EXPECT_EQ(st.id(), ErrorId::kSceneFileValue) << c.what << ": " << st.to_string();
    EXPECT_NE(st.message().find("objects[0]: transform 0"), std::string::npos) << st.to_string();
  }
  // Rigid, mirrored and uniformly scaled ones stay valid.
  for (const SceneTransform& t : {SceneTransform{0, -1, 0, 5, 1, 0, 0, 0, 0, 0, 1, -3},
                                  SceneTransform{-1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0},
                                  SceneTransform{1e3f, 0, 0, 0, 0, 1e3f, 0, 0, 0, 0, 1e3f, 0}}) {
    SceneFile s = sample_scene();
    s.objects[0].transforms.assign(1, t);
    EXPECT_TRUE(validate_scene_file(s).ok()) << validate_scene_file(s).to_string();
  }
}

TEST(SceneFile, Views) {
  expect_json_error("\"offset\": 36, \"count\": 1", "\"offset\": 36, \"count\": 6",
                    ErrorId::kSceneFileView, "meshes[0].triangles");
  expect_json_error("\"offset\": 36, \"count\": 1", "\"offset\": 37, \"count\": 1",
                    ErrorId::kSceneFileView, "not a multiple of 4");
  expect_json_error("\"offset\": 36, \"count\": 1", "\"offset\": 32, \"count\": 1",
                    ErrorId::kSceneFileView, "overlaps 'meshes[0].positions'");
  expect_json_error("\"buffer\": 0, \"offset\": 48", "\"buffer\": 1, \"offset\": 48",
                    ErrorId::kSceneFileView, "names buffer 1 of 1");
  expect_json_error("\"offset\": 48, \"count\": 1", "\"offset\": 48, \"count\": 1099511627777",
                    ErrorId::kSceneFileLimit, "count");
  expect_json_error("\"offset\": 48, \"count\": 1", "\"offset\": 48, \"count\": -1",
                    ErrorId::kSceneFileField, "count");
  expect_json_error("\"offset\": 0, \"count\": 3", "\"offset\": 0, \"count\": 3, \"stride\": 16",
                    ErrorId::kSceneFileField, "stride");
}

TEST(SceneFile, BufferSizes) {
  std::string buffer = minimal_buffer();
  expect_error(parse(kMinimalJson, buffer.substr(0, 95)), ErrorId::kSceneFileBufferSize,
               "holds 95 bytes, byte_length says 96");
  expect_error(parse(kMinimalJson, buffer + "x"), ErrorId::kSceneFileBufferSize, "97 bytes");
}

TEST(SceneFile, Paths) {
  for (const char* bad : {"../scene.bin", "/tmp/scene.bin", "a/../scene.bin", "a//b.bin", ".hidden",
                          "a\\\\b.bin", "scene.json", "c:scene.bin", ""}) {
    expect_json_error("\"uri\": \"scene.bin\"", std::string("\"uri\": \"") + bad + "\"",
                      ErrorId::kSceneFilePath, "buffers[0].uri");
  }
  expect_json_error("\"buffers\": [", "\"textures\": [{\"uri\": \"scene.bin\"}], \"buffers\": [",
                    ErrorId::kSceneFileField, "used twice");
}

TEST(SceneFile, StatesAndMeshes) {
  SceneFile s = sample_scene();
  s.meshes[0].state_times = {0.5f, 0.5f};
  EXPECT_EQ(validate_scene_file(s).id(), ErrorId::kSceneFileValue);
  s = sample_scene();
  s.meshes[0].state_positions.pop_back();
  EXPECT_EQ(validate_scene_file(s).id(), ErrorId::kSceneFileWriterMisuse);
  s = sample_scene();
  s.meshes[1].spheres[0].radius = 0;
  EXPECT_EQ(validate_scene_file(s).id(), ErrorId::kSceneFileValue);
  s = sample_scene();
  s.meshes[1].spheres.clear();
  EXPECT_EQ(validate_scene_file(s).id(), ErrorId::kSceneFileField);
  s = sample_scene();
  s.meshes[0].normals[3] = 0;
  s.meshes[0].normals[4] = 0;
  s.meshes[0].normals[5] = 0;
  EXPECT_EQ(validate_scene_file(s).id(), ErrorId::kSceneFileValue);
  s = sample_scene();
  s.meshes[0].triangle_materials[1] = 2;
  EXPECT_EQ(validate_scene_file(s).id(), ErrorId::kSceneFileIndex);
  s = sample_scene();
  s.lights[0].intensities.pop_back();  // 2 of 3 frames
  EXPECT_EQ(validate_scene_file(s).id(), ErrorId::kSceneFileWriterMisuse);
}

TEST_F(SceneFileTest, WriterRefusesMisuseAndWritesNothing) {
  SceneFile s = sample_scene();
  s.meshes[0].positions.push_back(1);  // not a multiple of 3
  Status st = write_scene_file(s, dir_);
  EXPECT_EQ(st.id(), ErrorId::kSceneFileWriterMisuse) << st.to_string();
  EXPECT_FALSE(fs::exists(dir_ / "scene.json"));
  s = sample_scene();
  s.textures[0].rgba.clear();
  s.textures[0].width = s.textures[0].height = 0;
  EXPECT_EQ(write_scene_file(s, dir_).id(), ErrorId::kSceneFileWriterMisuse);
  EXPECT_FALSE(fs::exists(dir_ / "scene.json"));
}

TEST_F(SceneFileTest, RewriteRemovesTheOldManifestFirst) {
  ASSERT_TRUE(write_scene_file(sample_scene(), dir_).ok());
  SceneFile s = sample_scene();
  s.name = "second";
  ASSERT_TRUE(write_scene_file(s, dir_).ok());
  auto back = read_scene_file(dir_);
  ASSERT_TRUE(back.ok());
  EXPECT_EQ(back->name, "second");
}

TEST_F(SceneFileTest, FileErrors) {
  {
    auto s = read_scene_file(dir_);
    expect_error(s, ErrorId::kFileOpen, "scene.json");
  }
  write_minimal();
  write("scene.bin", minimal_buffer().substr(0, 90));
  expect_error(read_scene_file(dir_), ErrorId::kSceneFileBufferSize, "(truncated)");
  fs::remove(dir_ / "scene.bin");
  expect_error(read_scene_file(dir_), ErrorId::kSceneFileMissing, "buffer is missing");
  // A link inside the folder that leads out of it.
  write("outside/scene.bin", minimal_buffer());
  fs::create_directories(dir_ / "inside");
  write("inside/scene.json", kMinimalJson);
  fs::create_symlink(dir_ / "outside/scene.bin", dir_ / "inside/scene.bin");
  expect_error(read_scene_file(dir_ / "inside"), ErrorId::kSceneFilePath,
               "resolves outside the scene folder");
}

TEST_F(SceneFileTest, TextureErrors) {
  SceneFile s = sample_scene();
  ASSERT_TRUE(write_scene_file(s, dir_).ok());
  fs::remove(dir_ / "textures/checker.png");
  expect_error(read_scene_file(dir_), ErrorId::kSceneFileMissing, "texture is missing");
  write("textures/checker.png", "not a png");
  expect_error(read_scene_file(dir_), ErrorId::kSceneFileTexture, "checker.png");
}

}  // namespace
}  // namespace calf::capture
