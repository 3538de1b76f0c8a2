// Sample scenes and rigs (calf/samples/scene.h): the --rig syntax, default rigs and validation
// paths of the built-in scenes, and assimp loading of small OBJ and animated glTF files written
// here, with the error for each kind of bad file.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "calf/format/cube.h"
#include "calf/samples/render.h"
#include "calf/samples/scene.h"

namespace calf::samples {
namespace {

namespace fs = std::filesystem;

double distance(const Vec3& a, const Vec3& b) {
  return std::sqrt((a.x - b.x) * (a.x - b.x) + (a.y - b.y) * (a.y - b.y) +
                   (a.z - b.z) * (a.z - b.z));
}

bool inside(const Box3& b, const Vec3& p) {
  return p.x >= b.min.x && p.x <= b.max.x && p.y >= b.min.y && p.y <= b.max.y && p.z >= b.min.z &&
         p.z <= b.max.z;
}

TEST(Rig, Forms) {
  auto box = parse_rig("box:0,1.6,0,0.5,0.3,0.5");
  ASSERT_TRUE(box.ok()) << box.status().to_string();
  ASSERT_EQ(box->viewpoints.size(), 9u);
  EXPECT_EQ(box->viewpoints[0].position, (Vec3{0, 1.6, 0}));
  EXPECT_LT(distance(box->viewpoints[8].position, {0.5, 1.9, 0.5}), 1e-12);
  EXPECT_EQ(box->view_volume.min, (Vec3{-0.5, 1.3, -0.5}));
  auto ring = parse_rig("ring:8,2,0,1,0");
  ASSERT_TRUE(ring.ok());
  ASSERT_EQ(ring->viewpoints.size(), 8u);
  for (const auto& v : ring->viewpoints) {
    EXPECT_NEAR(distance(v.position, {0, 1, 0}), 2, 1e-12);
    EXPECT_EQ(v.position.y, 1);
  }
  auto sphere = parse_rig("sphere:14,3,0,0,0");
  ASSERT_TRUE(sphere.ok());
  ASSERT_EQ(sphere->viewpoints.size(), 14u);
  for (const auto& v : sphere->viewpoints) EXPECT_NEAR(distance(v.position, {0, 0, 0}), 3, 1e-12);
  auto grid = parse_rig("grid:4,2,2,-1,1,-1,1,2,1");
  ASSERT_TRUE(grid.ok());
  EXPECT_EQ(grid->viewpoints.size(), 16u);
  EXPECT_EQ(grid->viewpoints.back().position, (Vec3{1, 2, 1}));
  auto list = parse_rig("list:0,1,0/1,1,-2.5");
  ASSERT_TRUE(list.ok());
  ASSERT_EQ(list->viewpoints.size(), 2u);
  EXPECT_EQ(list->viewpoints[1].position, (Vec3{1, 1, -2.5}));
  EXPECT_EQ(list->view_volume.max, (Vec3{1, 1, 0}));
  // Numbers that six decimals would round away (a grid 1e-300 wide, a ring of radius 1e-7).
  auto tiny = parse_rig("grid:3,1,1,0,0,0,1e-300,0,0");
  ASSERT_TRUE(tiny.ok()) << tiny.status().to_string();
  auto thin = parse_rig("ring:5,1e-7,0.1,0.2,0.3");
  ASSERT_TRUE(thin.ok()) << thin.status().to_string();
  // A rig's description parses back to the same rig, position for position.
  for (const Rig* r : {&*box, &*ring, &*sphere, &*grid, &*list, &*tiny, &*thin}) {
    auto again = parse_rig(r->description);
    ASSERT_TRUE(again.ok()) << r->description;
    EXPECT_EQ(again->viewpoints, r->viewpoints) << r->description;
    EXPECT_EQ(again->view_volume, r->view_volume) << r->description;
    EXPECT_EQ(again->description, r->description);
  }
  EXPECT_EQ(box->description, "box:0,1.6,0,0.5,0.3,0.5");
}

// Finite numbers whose rig a capture manifest would refuse are --rig errors naming the problem.
TEST(Rig, OverflowingOrRepeatedViewpointsAreSyntaxErrors) {
  for (const char* bad :
       {"box:1e308,0,0,1e308,1,1", "grid:2,1,1,-1e308,0,0,1e308,0,0", "ring:4,1e308,1e308,0,0",
        "list:0,0,0/0,0,0", "list:1,2,3/4,5,6/1,2,3", "grid:3,1,1,0,0,0,5e-324,0,0"}) {
    auto r = parse_rig(bad);
    ASSERT_FALSE(r.ok()) << bad;
    EXPECT_EQ(r.status().id(), ErrorId::kRigSyntax) << bad;
    EXPECT_NE(r.status().message().find(bad), std::string::npos) << r.status().message();
  }
  auto twice = parse_rig("list:0,0,0/0,0,0");
  EXPECT_NE(twice.status().message().find("(0, 0, 0) is used by an earlier viewpoint"),
            std::string::npos)
      << twice.status().message();
}

// Large finite positions and extents used to reach Embree and abort on ray.valid(); the
// coordinate bound (calf/format/coordinates.h) refuses them at the --rig text.
TEST(Rig, PositionsBeyondTheCoordinateBoundAreSyntaxErrors) {
  for (const char* bad :
       {"list:2e18,1.6,0", "ring:3,1e300,0,1.6,0", "sphere:4,1e300,0,1.6,0",
        "box:0,1.6,0,1e300,1,1", "grid:2,1,1,-2e12,0,0,0,0,0", "list:0,1e12,0/0,-1.5e12,0"}) {
    auto r = parse_rig(bad);
    ASSERT_FALSE(r.ok()) << bad;
    EXPECT_EQ(r.status().id(), ErrorId::kRigSyntax) << bad;
    EXPECT_NE(r.status().message().find("coordinate bound"), std::string::npos)
        << r.status().message();
  }
  auto at_bound = parse_rig("list:1e12,1.6,-1e12");
  EXPECT_TRUE(at_bound.ok()) << at_bound.status().to_string();
}

TEST(Rig, SyntaxErrors) {
  for (const char* bad :
       {"", "box", "box:1,2,3", "box:0,0,0,0,1,1", "ring:0,1,0,0,0", "ring:2.5,1,0,0,0",
        "ring:4,-1,0,0,0", "sphere:4,1,0,0", "grid:2,2,2,0,0,0,1,1", "grid:2,1,1,0,0,0,0,1,1",
        "list:", "list:1,2", "list:1,2,3/", "cone:1,2", "box:a,b,c,d,e,f", "ring:4,1,0,0,nan",
        "ring:5000,1,0,0,0"}) {
    auto r = parse_rig(bad);
    ASSERT_FALSE(r.ok()) << bad;
    EXPECT_EQ(r.status().id(), ErrorId::kRigSyntax) << bad;
  }
}

TEST(Scenes, BuiltinsAreValidWithPathsAwayFromTheirViewpoints) {
  ASSERT_GE(builtin_scenes().size(), 3u);
  for (const SceneInfo& info : builtin_scenes()) {
    auto scene = make_builtin_scene(info.name);
    ASSERT_TRUE(scene.ok()) << info.name;
    EXPECT_TRUE(validate_scene(*scene).ok()) << info.name;
    EXPECT_GE(scene->default_rig.viewpoints.size(), 9u) << info.name;
    // Every default viewpoint is outside geometry at every default frame (the first only for the
    // scenes of millions of triangles, whose last frame visibility_scenes_test checks).
    const uint32_t frames = scene->triangle_count() > 1000000 ? 1 : scene->frame_count;
    Status st = check_viewpoints(*scene, scene->default_rig, frames, scene->fps,
                                 LightfieldRenderOptions{2, 1, 0, 6, 0});
    EXPECT_TRUE(st.ok()) << st.to_string();
    capture::EyePath path = scene->validation_path(scene->frame_count, scene->fps, 32, 32);
    ASSERT_EQ(path.poses.size(), scene->frame_count);
    for (const capture::EyePose& pose : path.poses) {
      EXPECT_TRUE(inside(scene->default_rig.view_volume, pose.position)) << info.name;
      for (const auto& v : scene->default_rig.viewpoints) {
        EXPECT_GT(distance(pose.position, v.position), 0.25) << info.name << " " << v.name;
      }
    }
  }
  EXPECT_EQ(make_builtin_scene("sponza").status().id(), ErrorId::kSceneUnknown);
  EXPECT_EQ(load_scene("sponza").status().id(), ErrorId::kSceneUnknown);
}

TEST(Scenes, ValidationCatchesBadScenes) {
  Scene s;
  s.name = "bad";
  s.materials = {Material{}};
  EXPECT_EQ(validate_scene(s).id(), ErrorId::kSceneEmpty);
  Object o;
  o.spheres.push_back({glm::vec3(0), -1.0f});
  s.objects.push_back(o);
  EXPECT_EQ(validate_scene(s).id(), ErrorId::kSceneGeometry);
  s.objects[0].spheres[0].radius = 1;
  s.objects[0].material = 3;
  EXPECT_EQ(validate_scene(s).id(), ErrorId::kSceneGeometry);
  s.objects[0].material = 0;
  s.materials[0].reflect = 0.7f;
  s.materials[0].refract = 0.7f;
  EXPECT_EQ(validate_scene(s).id(), ErrorId::kSceneGeometry);
  s.materials[0] = Material{};
  ASSERT_TRUE(validate_scene(s).ok());
  // Camera placement divides by the length scale and measures from the keep-out ball.
  for (double bad : {0.0, -1.0, std::nan(""), double{INFINITY}}) {
    s.length_scale = bad;
    EXPECT_EQ(validate_scene(s).id(), ErrorId::kSceneGeometry) << bad;
  }
  s.length_scale = 1;
  for (double bad : {-1.0, std::nan(""), double{INFINITY}}) {
    s.default_rig.keep_out_radius = bad;
    EXPECT_EQ(validate_scene(s).id(), ErrorId::kSceneGeometry) << bad;
  }
  s.default_rig.keep_out_radius = 0;
  EXPECT_TRUE(validate_scene(s).ok());
}

class AssimpTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / "calf_scene_test_assimp";
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path write(const std::string& name, const std::string& text) {
    std::ofstream(dir_ / name, std::ios::binary) << text;
    return dir_ / name;
  }
  fs::path dir_;
};

TEST_F(AssimpTest, ObjCube) {
  // A unit cube, outward-wound quads; assimp triangulates them.
  fs::path file = write("cube.obj",
                        "v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\n"
                        "v -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\n"
                        "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 4 8 7 3\nf 1 5 8 4\nf 2 3 7 6\n");
  auto scene = load_scene(file.string());
  ASSERT_TRUE(scene.ok()) << scene.status().to_string();
  ASSERT_EQ(scene->objects.size(), 1u);
  EXPECT_EQ(scene->objects[0].mesh.triangles.size(), 12u);
  EXPECT_EQ(scene->frame_count, 1u);
  ASSERT_EQ(scene->default_rig.viewpoints.size(), 8u);
  auto tracer = FrameTracer::create(*scene, 0, LightfieldRenderOptions{1, 1, 2, 6, 0});
  ASSERT_TRUE(tracer.ok());
  EXPECT_TRUE((*tracer)->inside_geometry({0, 0, 0}));
  // From +X at distance 4, the centre of face -X sees the cube's +X side at distance 3.
  capture::ViewFrame f;
  (*tracer)->render_cube({4, 0, 0}, 0, 0, 16, false, &f);
  Vec3 d = direction_from_texel(CubeFace::kNegX, 8, 8, 16);
  EXPECT_NEAR(f.depth[f.texel_index(CubeFace::kNegX, 8, 8)], 3.0 / std::fabs(d.x), 1e-5);
  EXPECT_TRUE(std::isinf(f.depth[f.texel_index(CubeFace::kPosX, 8, 8)]));
}

// base64 for a small glTF with an embedded buffer.
std::string base64(const std::vector<uint8_t>& bytes) {
  static const char* abc = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (size_t i = 0; i < bytes.size(); i += 3) {
    uint32_t v = bytes[i] << 16;
    if (i + 1 < bytes.size()) v |= bytes[i + 1] << 8;
    if (i + 2 < bytes.size()) v |= bytes[i + 2];
    out += abc[(v >> 18) & 63];
    out += abc[(v >> 12) & 63];
    out += i + 1 < bytes.size() ? abc[(v >> 6) & 63] : '=';
    out += i + 2 < bytes.size() ? abc[v & 63] : '=';
  }
  return out;
}

TEST_F(AssimpTest, GltfNodeAnimation) {
  // One triangle on a node that translates from x = 0 at t = 0 to x = 2 at t = 1 s.
  std::vector<float> floats = {0, 0, 0, 1, 0, 0, 0, 1, 0,  // positions (36 bytes)
                               0, 1,                       // times (8 bytes)
                               0, 0, 0, 2, 0, 0};          // translations (24 bytes)
  std::vector<uint8_t> bytes(floats.size() * 4);
  std::memcpy(bytes.data(), floats.data(), bytes.size());
  std::string gltf = R"({
    "asset": {"version": "2.0"},
    "scene": 0, "scenes": [{"nodes": [0]}],
    "nodes": [{"name": "mover", "mesh": 0}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
    "buffers": [{"byteLength": 68, "uri": "data:application/octet-stream;base64,)" +
                     base64(bytes) + R"("}],
    "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36},
                    {"buffer": 0, "byteOffset": 36, "byteLength": 8},
                    {"buffer": 0, "byteOffset": 44, "byteLength": 24}],
    "accessors": [
      {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
       "min": [0, 0, 0], "max": [1, 1, 0]},
      {"bufferView": 1, "componentType": 5126, "count": 2, "type": "SCALAR", "min": [0], "max": [1]},
      {"bufferView": 2, "componentType": 5126, "count": 2, "type": "VEC3"}],
    "animations": [{"channels": [{"sampler": 0, "target": {"node": 0, "path": "translation"}}],
                    "samplers": [{"input": 1, "output": 2, "interpolation": "LINEAR"}]}]
  })";
  fs::path file = write("mover.gltf", gltf);
  auto scene = load_scene_file(file);
  ASSERT_TRUE(scene.ok()) << scene.status().to_string();
  ASSERT_EQ(scene->objects.size(), 1u);
  EXPECT_EQ(scene->frame_count, 31u);  // 1 s at 30 fps, both ends
  const TransformAt& at = scene->objects[0].transform;
  ASSERT_TRUE(at);
  EXPECT_NEAR(at(0)[3][0], 0, 1e-5);
  EXPECT_NEAR(at(0.5)[3][0], 1, 1e-5);
  EXPECT_NEAR(at(1)[3][0], 2, 1e-5);
  EXPECT_NEAR(at(5)[3][0], 2, 1e-5);  // held after the last key
}

TEST_F(AssimpTest, BadFiles) {
  EXPECT_EQ(load_scene_file(dir_ / "missing.obj").status().id(), ErrorId::kFileOpen);
  EXPECT_EQ(load_scene_file(write("model.xyz123", "hello")).status().id(), ErrorId::kSceneFormat);
  EXPECT_EQ(load_scene_file(write("broken.gltf", "{\"asset\": ")).status().id(),
            ErrorId::kSceneLoad);
  // Vertices but no faces: nothing to render.
  Status empty = load_scene_file(write("points.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n")).status();
  EXPECT_TRUE(empty.id() == ErrorId::kSceneEmpty || empty.id() == ErrorId::kSceneLoad)
      << empty.to_string();
}

}  // namespace
}  // namespace calf::samples
