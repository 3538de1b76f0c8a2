// The built-in "factory" scene (samples/src/factory_scene.cc, the surfel mode's heavy scene):
// it holds the >= 20 M triangles its listing promises, exactly; the unique geometry is a small
// share of it, made of parts of 10k-200k triangles each; it is generated the same way every time;
// its parts are wound outward (rays from outside meet front faces first: brute force); the gears
// turn and everything else stands still; the view region is free at eye height.
#include <gtest/gtest.h>

#include <cctype>
#include <cmath>
#include <map>
#include <set>
#include <string>

#include <glm/glm.hpp>

#include "calf/capture/scene_file.h"
#include "calf/samples/render.h"
#include "calf/samples/scene.h"
#include "calf/samples/scene_export.h"

namespace calf::samples {
namespace {

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

// The shared meshes of the scene by name, each once.
std::map<std::string, const TriangleMesh*> parts_of(const Scene& s) {
  std::map<std::string, const TriangleMesh*> out;
  for (const Object& o : s.objects) {
    if (o.shared_mesh) out[o.shared_mesh->name] = o.shared_mesh.get();
  }
  return out;
}

TEST(FactoryScene, HoldsTheTrianglesItsListingPromisesMostlyInstanced) {
  auto scene = make_builtin_scene("factory");
  ASSERT_TRUE(scene.ok());
  ASSERT_TRUE(validate_scene(*scene).ok());
  const SceneInfo* info = nullptr;
  for (const SceneInfo& i : builtin_scenes()) {
    if (std::string(i.name) == "factory") info = &i;
  }
  ASSERT_NE(info, nullptr);
  EXPECT_EQ(triangles_in(info->description), scene->triangle_count());
  EXPECT_EQ(triangles_in(scene->description), scene->triangle_count());
  EXPECT_GE(scene->triangle_count(), 20000000u) << "the factory: >= 20 M triangles with instances";
  size_t unique = 0, instanced_objects = 0;
  std::set<const TriangleMesh*> seen;
  for (const Object& o : scene->objects) {
    if (!o.shared_mesh) {
      unique += o.mesh.triangles.size();
      continue;
    }
    ++instanced_objects;
    if (seen.insert(o.shared_mesh.get()).second) unique += o.shared_mesh->triangles.size();
  }
  EXPECT_LT(unique * 50, scene->triangle_count()) << unique << " unique triangles";
  EXPECT_GT(instanced_objects, 1000u);
  // The machine parts are detailed: 10k-200k triangles each.
  const auto parts = parts_of(*scene);
  for (const char* name : {"machine-bed", "motor", "gear-24", "gear-40", "gear-32", "stud-m36",
                           "pipe-0", "pipe-1", "conveyor"}) {
    ASSERT_TRUE(parts.count(name)) << name;
    EXPECT_GE(parts.at(name)->triangles.size(), 9000u) << name;
    EXPECT_LE(parts.at(name)->triangles.size(), 200000u) << name;
  }
  // The view region: a slab at eye height in the aisle, its viewpoints outside geometry.
  const Box3& region = scene->default_rig.view_volume;
  EXPECT_LE(region.min.y, 1.7);
  EXPECT_GE(region.max.y, 1.7);
  EXPECT_LE(region.max.y - region.min.y, 0.25);
  auto tracer = FrameTracer::create(*scene, 0, LightfieldRenderOptions{2, 1, 0, 6, 0});
  ASSERT_TRUE(tracer.ok()) << tracer.status().to_string();
  for (const auto& v : scene->default_rig.viewpoints) {
    EXPECT_FALSE((*tracer)->inside_geometry(v.position)) << v.name;
  }
  const capture::EyePath path = scene->validation_path(4, scene->fps, 64, 64);
  for (const capture::EyePose& pose : path.poses) {
    EXPECT_FALSE((*tracer)->inside_geometry(pose.position));
  }
}

TEST(FactoryScene, IsGeneratedTheSameEveryTime) {
  auto a = make_builtin_scene("factory");
  auto b = make_builtin_scene("factory");
  ASSERT_TRUE(a.ok() && b.ok());
  auto fa = export_scene(*a, 2), fb = export_scene(*b, 2);
  ASSERT_TRUE(fa.ok() && fb.ok()) << fa.status().to_string();
  EXPECT_TRUE(*fa == *fb);
  EXPECT_EQ(fa->triangle_count(), a->triangle_count());
  EXPECT_EQ(fa->meshes.size(), 18u);  // 15 shared parts and floor, walls, lines
}

// Rays from 24 directions around each part towards points near its middle: the nearest
// triangle each meets is a front face (counter-clockwise seen from outside).
TEST(FactoryScene, PartsAreWoundOutward) {
  auto scene = make_builtin_scene("factory");
  ASSERT_TRUE(scene.ok());
  for (const auto& [name, mesh] : parts_of(*scene)) {
    glm::vec3 lo(INFINITY), hi(-INFINITY);
    for (const glm::vec3& p : mesh->positions) lo = glm::min(lo, p), hi = glm::max(hi, p);
    const glm::vec3 centre = (lo + hi) * 0.5f;
    const float radius = glm::length(hi - lo);
    size_t hits = 0, front = 0;
    for (int k = 0; k < 24; ++k) {
      // A Fibonacci sphere of directions; targets spread over the middle half of the box.
      const float z = 1 - (2 * k + 1) / 24.0f, phi = 2.39996323f * static_cast<float>(k);
      const float s = std::sqrt(1 - z * z);
      const glm::vec3 d(s * std::cos(phi), z, s * std::sin(phi));
      const glm::vec3 target = centre + (hi - lo) * 0.25f *
                                            glm::vec3(std::sin(3.1f * k), std::sin(1.7f * k + 1),
                                                      std::sin(2.3f * k + 2));
      const glm::vec3 o = target - d * radius;
      float best = INFINITY;
      float facing = 0;
      for (const glm::uvec3& t : mesh->triangles) {
        const glm::vec3 a = mesh->positions[t.x], b = mesh->positions[t.y],
                        c = mesh->positions[t.z];
        const glm::vec3 e1 = b - a, e2 = c - a, pv = glm::cross(d, e2);
        const float det = glm::dot(e1, pv);
        if (std::fabs(det) < 1e-12f) continue;
        const glm::vec3 tv = o - a;
        const float u = glm::dot(tv, pv) / det;
        if (u < 0 || u > 1) continue;
        const glm::vec3 qv = glm::cross(tv, e1);
        const float v = glm::dot(d, qv) / det;
        if (v < 0 || u + v > 1) continue;
        const float dist = glm::dot(e2, qv) / det;
        if (dist > 0 && dist < best) {
          best = dist;
          facing = glm::dot(glm::cross(e1, e2), d);
        }
      }
      if (std::isfinite(best)) {
        ++hits;
        front += facing < 0;
      }
    }
    EXPECT_GE(hits, 5u) << name;
    EXPECT_EQ(front, hits) << name << ": rays from outside meet back faces first";
  }
}

TEST(FactoryScene, GearsTurnEverythingElseStandsStill) {
  auto scene = make_builtin_scene("factory");
  ASSERT_TRUE(scene.ok());
  size_t gears = 0;
  for (const Object& o : scene->objects) {
    const glm::mat4 a = o.transform ? o.transform(0) : glm::mat4(1);
    const glm::mat4 b = o.transform ? o.transform(0.5) : glm::mat4(1);
    const bool gear = o.name.find("-gear-") != std::string::npos;
    gears += gear;
    EXPECT_EQ(a != b, gear) << o.name;
    if (gear) {
      // Turning about its axle (+Z or -Z in the hall): the axle point and direction stay put.
      EXPECT_LT(glm::length(glm::vec3(a[3]) - glm::vec3(b[3])), 1e-5f) << o.name;
      EXPECT_LT(glm::length(glm::vec3(a[1]) - glm::vec3(b[1])), 1e-5f) << o.name;
    }
  }
  EXPECT_EQ(gears, 3u * 96);
}

}  // namespace
}  // namespace calf::samples
