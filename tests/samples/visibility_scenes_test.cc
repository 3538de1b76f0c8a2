// The built-in scenes of the visible-set mode (city, blades, spheres; samples/src/*_scene.cc):
// each builds, validates and holds at least the triangles it promises (the count its
// --list-scenes line prints, exactly), is generated the same way twice (same scene.bin bytes),
// exports to a scene file that reads back equal with each shared mesh stored once, and has the
// view region, motion and eye path the mode needs. The heavy scenes are not ray traced here (too
// slow under ASan) except one cube map of the city at a small face size.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <ostream>
#include <set>
#include <string>

#include "calf/capture/scene_file.h"
#include "calf/format/cube.h"
#include "calf/samples/render.h"
#include "calf/samples/scene.h"
#include "calf/samples/scene_export.h"

namespace calf::samples {
namespace {

namespace fs = std::filesystem;

struct Promise {
  const char* name;
  uint64_t min_triangles;  // city >= 1 M, blades >= 5 M
  size_t min_spheres;
};
// gtest prints a parameter in test names and messages: the scene's name.
void PrintTo(const Promise& p, std::ostream* os) {
  *os << p.name;
}

constexpr Promise kPromises[] = {
    {"city", 1000000, 0}, {"blades", 5000000, 0}, {"spheres", 1000, 10}};

// The number written before " triangles" in `text` ("1,417,070 triangles"), 0 when none.
uint64_t triangles_in(const std::string& text) {
  size_t end = text.find(" triangles");
  if (end == std::string::npos) return 0;
  size_t begin = end;
  while (begin > 0 &&
         (std::isdigit(static_cast<unsigned char>(text[begin - 1])) || text[begin - 1] == ',')) {
    --begin;
  }
  uint64_t n = 0;
  for (size_t i = begin; i < end; ++i) {
    if (text[i] != ',') n = n * 10 + static_cast<uint64_t>(text[i] - '0');
  }
  return n;
}

// FNV-1a, 64 bits: a fingerprint of the bytes for the message.
uint64_t fnv1a(const std::string& bytes) {
  uint64_t h = 0xcbf29ce484222325ull;
  for (unsigned char c : bytes) h = (h ^ c) * 0x100000001b3ull;
  return h;
}

const SceneInfo* info_of(const char* name) {
  for (const SceneInfo& info : builtin_scenes()) {
    if (std::string(info.name) == name) return &info;
  }
  return nullptr;
}

// One test per scene (each a ctest of its own, so that the heavy blades stay apart).
class VisibilityScene : public ::testing::TestWithParam<Promise> {};

INSTANTIATE_TEST_SUITE_P(Builtin, VisibilityScene, ::testing::ValuesIn(kPromises),
                         [](const ::testing::TestParamInfo<Promise>& test) {
                           return std::string(test.param.name);
                         });

TEST_P(VisibilityScene, HoldTheTrianglesTheirListingPromises) {
  const Promise& p = GetParam();
  const SceneInfo* info = info_of(p.name);
  ASSERT_NE(info, nullptr);
  auto scene = make_builtin_scene(p.name);
  ASSERT_TRUE(scene.ok()) << scene.status().to_string();
  Status st = validate_scene(*scene);
  EXPECT_TRUE(st.ok()) << st.to_string();
  EXPECT_EQ(triangles_in(info->description), scene->triangle_count()) << info->description;
  EXPECT_EQ(triangles_in(scene->description), scene->triangle_count()) << scene->description;
  EXPECT_GE(scene->triangle_count(), p.min_triangles);
  EXPECT_GE(scene->sphere_count(), p.min_spheres);
  // Short clips for tests and demos.
  EXPECT_GE(scene->frame_count, 8u);
  EXPECT_LE(scene->frame_count, 30u);
  EXPECT_GT(scene->fps, 0);
  // The view region is a thin slab at eye height (1.6 .. 1.8 m) with the default rig in it.
  const Box3& region = scene->default_rig.view_volume;
  EXPECT_LE(region.min.y, 1.7);
  EXPECT_GE(region.max.y, 1.7);
  EXPECT_LE(region.max.y - region.min.y, 0.25);
  EXPECT_GT(region.max.x - region.min.x, 1.0);
  EXPECT_GT(region.max.z - region.min.z, 1.0);
  for (const auto& v : scene->default_rig.viewpoints) {
    EXPECT_GE(v.position.y, region.min.y);
    EXPECT_LE(v.position.y, region.max.y);
  }
  // The viewpoints are outside geometry at the last frame too (scene_test checks the first).
  const double last = (scene->frame_count - 1) / scene->fps;
  auto tracer = FrameTracer::create(*scene, last, LightfieldRenderOptions{2, 1, 0, 6, 0});
  ASSERT_TRUE(tracer.ok()) << tracer.status().to_string();
  for (const auto& v : scene->default_rig.viewpoints) {
    EXPECT_FALSE((*tracer)->inside_geometry(v.position)) << v.name;
  }
}

TEST_P(VisibilityScene, AreGeneratedTheSameEveryTime) {
  const Promise& p = GetParam();
  capture::EncodedScene first, second;
  for (capture::EncodedScene* out : {&first, &second}) {
    auto scene = make_builtin_scene(p.name);
    ASSERT_TRUE(scene.ok());
    auto file = export_scene(*scene, scene->frame_count);
    ASSERT_TRUE(file.ok()) << file.status().to_string();
    auto encoded = capture::encode_scene_file(*file);
    ASSERT_TRUE(encoded.ok()) << encoded.status().to_string();
    *out = std::move(*encoded);
  }
  EXPECT_GT(first.buffer.size(), 1000u);
  EXPECT_EQ(fnv1a(first.buffer), fnv1a(second.buffer));
  EXPECT_TRUE(first.buffer == second.buffer);
  EXPECT_TRUE(first.manifest == second.manifest);
}

TEST_P(VisibilityScene, ExportAndReadBackWithSharedMeshesStoredOnce) {
  const Promise& p = GetParam();
  auto scene = make_builtin_scene(p.name);
  ASSERT_TRUE(scene.ok());
  const fs::path dir =
      fs::temp_directory_path() /
      ("calf_visibility_scenes_" + std::string(p.name) + "_" + std::to_string(getpid()));
  fs::remove_all(dir);
  ASSERT_TRUE(write_scene(*scene, scene->frame_count, dir).ok());
  auto back = capture::read_scene_file(dir);
  ASSERT_TRUE(back.ok()) << back.status().to_string();
  auto direct = export_scene(*scene, scene->frame_count);
  ASSERT_TRUE(direct.ok());
  EXPECT_TRUE(*back == *direct);
  EXPECT_EQ(back->triangle_count(), scene->triangle_count());
  EXPECT_EQ(back->objects.size(), scene->objects.size());
  size_t spheres = 0;
  for (const capture::SceneObject& o : back->objects)
    spheres += back->meshes[o.mesh].spheres.size();
  EXPECT_EQ(spheres, scene->sphere_count());
  if (p.min_triangles >= 1000000) {
    // Instancing: the file holds each prototype once, a small share of the placed triangles.
    EXPECT_LT(back->mesh_triangle_count() * 10, back->triangle_count());
    EXPECT_LT(back->meshes.size() * 5, back->objects.size());
  }
  const capture::SceneEnvironment& e = back->environment;
  EXPECT_GT(e.sun_irradiance[0], 0) << "a sun";
  EXPECT_EQ(back->view_volume.min.y, scene->default_rig.view_volume.min.y);
  fs::remove_all(dir);
}

TEST(VisibilityScenes, BladesSwayInVertexStates) {
  auto scene = make_builtin_scene("blades");
  ASSERT_TRUE(scene.ok());
  size_t with_states = 0;
  std::set<const TriangleMesh*> checked;
  for (const Object& o : scene->objects) {
    const TriangleMesh& m = o.triangle_mesh();
    if (m.state_times.empty()) continue;
    ++with_states;
    EXPECT_TRUE(o.shared_mesh != nullptr) << o.name;
    EXPECT_EQ(m.state_times.front(), 0.0f);
    // The states cover the default clip and some more.
    EXPECT_GE(m.state_times.back(), (scene->frame_count - 1) / scene->fps);
    if (!checked.insert(&m).second) continue;  // each patch once
    std::vector<glm::vec3> first, last;
    positions_at(m, 0, &first);
    positions_at(m, (scene->frame_count - 1) / scene->fps, &last);
    ASSERT_EQ(first.size(), last.size());
    size_t moved = 0, still = 0;
    for (size_t i = 0; i < first.size(); ++i) {
      const float d = glm::length(first[i] - last[i]);
      moved += d > 0.01f;
      // Blade roots (at y = -0.01) stay where they grow.
      if (first[i].y < 0) {
        ++still;
        EXPECT_EQ(d, 0.0f) << i;
      }
    }
    EXPECT_GT(moved, first.size() / 10) << o.name;
    EXPECT_GT(still, first.size() / 10) << o.name;
  }
  EXPECT_GE(with_states, 256u);
  EXPECT_EQ(checked.size(), 4u) << "patches";
}

TEST(VisibilityScenes, SpheresBounceOnTheFloorOutsideTheRegion) {
  auto scene = make_builtin_scene("spheres");
  ASSERT_TRUE(scene.ok());
  const Box3& region = scene->default_rig.view_volume;
  size_t balls = 0;
  for (const Object& o : scene->objects) {
    if (o.spheres.empty()) continue;
    ++balls;
    ASSERT_TRUE(o.transform) << o.name;
    const float r = o.spheres[0].radius;
    double low = 1e9, high = -1e9;
    for (int i = 0; i <= 240; ++i) {
      const double t = i / 48.0;  // 5 s
      const glm::vec3 c(o.transform(t) * glm::vec4(o.spheres[0].center, 1));
      low = std::min(low, static_cast<double>(c.y - r));
      high = std::max(high, static_cast<double>(c.y - r));
      // Never into the region (grown by the radius) nor under the floor.
      const bool in_region = c.x > region.min.x - r && c.x < region.max.x + r &&
                             c.z > region.min.z - r && c.z < region.max.z + r;
      EXPECT_FALSE(in_region) << o.name << " at " << t;
    }
    EXPECT_GT(low, -1e-5) << o.name;
    EXPECT_LT(low, 0.05) << o.name << " touches the floor";
    EXPECT_GT(high, 0.3) << o.name << " bounces";
  }
  EXPECT_GE(balls, 10u);
}

// From the centre of the crossing, at eye height, the first facades hide the city: only rays
// down the streets travel far. One cube map of 32 x 32 texels per face, no AO.
TEST(VisibilityScenes, CityIsMostlyHiddenFromTheCrossing) {
  auto scene = make_builtin_scene("city");
  ASSERT_TRUE(scene.ok());
  const auto start = std::chrono::steady_clock::now();
  auto tracer = FrameTracer::create(*scene, 0, LightfieldRenderOptions{2, 1, 0, 6, 0});
  ASSERT_TRUE(tracer.ok()) << tracer.status().to_string();
  capture::ViewFrame frame;
  (*tracer)->render_cube({0, 1.7, 0}, 0, 0, 32, false, &frame);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  size_t horizontal = 0, far = 0;
  for (CubeFace face : {CubeFace::kPosX, CubeFace::kNegX, CubeFace::kPosZ, CubeFace::kNegZ}) {
    for (uint32_t y = 0; y < 32; ++y) {
      for (uint32_t x = 0; x < 32; ++x) {
        const Vec3 d = direction_from_texel(face, x, y, 32);
        if (std::fabs(d.y) > 0.05) continue;  // within 3 degrees of the horizon
        ++horizontal;
        const float depth = frame.depth[frame.texel_index(face, x, y)];
        far += depth > 60;  // +inf (sky at the end of a street) included
      }
    }
  }
  ASSERT_GT(horizontal, 100u);
  // The streets are 12 m wide: from their crossing they take 4 x ~20 degrees of 360.
  EXPECT_LT(far * 4, horizontal) << far << " of " << horizontal << " rays travel beyond 60 m";
  std::printf("city: BVH build + one 6 x 32^2 cube map in %.3f s\n", seconds);
}

// Instanced geometry (Embree instances of per-prototype BVHs) keeps the tracer's promise: the
// same bytes whatever the thread count.
TEST(VisibilityScenes, InstancedSceneRendersTheSameForAnyThreadCount) {
  auto scene = make_builtin_scene("city");
  ASSERT_TRUE(scene.ok());
  capture::ViewFrame first;
  for (uint32_t threads : {1u, 3u}) {
    auto tracer = FrameTracer::create(*scene, 0.2, LightfieldRenderOptions{threads, 5, 2, 6, 0});
    ASSERT_TRUE(tracer.ok()) << tracer.status().to_string();
    capture::ViewFrame frame;
    (*tracer)->render_cube({1.0, 1.65, -2.0}, 3, 1, 16, false, &frame);
    if (threads == 1) {
      first = frame;
      continue;
    }
    EXPECT_TRUE(frame.color == first.color);
    EXPECT_TRUE(frame.depth == first.depth);
  }
}

}  // namespace
}  // namespace calf::samples
