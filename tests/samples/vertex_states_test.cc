// Vertex states and shared meshes in the sample scene model (calf/samples/scene.h): validation,
// positions at a time (the same floats as the scene-file reader's), the ray tracer following the
// states from frame to frame (own and instanced meshes), instancing rendering what copies render,
// and the scene-file export storing a shared mesh once and its states exactly.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

#include "calf/capture/scene_file.h"
#include "calf/format/cube.h"
#include "calf/samples/render.h"
#include "calf/samples/scene.h"
#include "calf/samples/scene_export.h"

namespace calf::samples {
namespace {

namespace fs = std::filesystem;

// A 1 m x 1 m square facing +Z on the plane z = -2 that slides from x in [-1.2, -0.2] at t = 0 to
// x in [0.2, 1.2] at t = 1 s (y in [-0.5, 0.5]), held after: two states.
TriangleMesh sliding_square() {
  TriangleMesh m;
  add_quad(&m, {-1.2f, -0.5f, -2}, {-0.2f, -0.5f, -2}, {-0.2f, 0.5f, -2}, {-1.2f, 0.5f, -2});
  m.state_times = {0.0f, 1.0f};
  for (float dx : {0.0f, 1.4f}) {
    for (const glm::vec3& p : m.positions) m.state_positions.push_back(p + glm::vec3(dx, 0, 0));
  }
  // The rest pose is somewhere else entirely: with states the tracer must not use it.
  for (glm::vec3& p : m.positions) p.y += 10;
  return m;
}

Scene states_scene(bool shared) {
  Scene s;
  s.name = shared ? "states-shared" : "states";
  s.materials = {Material{}};
  s.fps = 1;
  s.frame_count = 2;
  s.sky.sun_irradiance = glm::vec3(1.0f);
  Object o;
  o.name = "square";
  if (shared) {
    auto mesh = std::make_shared<TriangleMesh>(sliding_square());
    mesh->name = "square-mesh";
    o.shared_mesh = mesh;
    // The instance moves the square 1 m further away: the plane is at z = -3.
    o.transform = [](double) { return glm::translate(glm::mat4(1), {0, 0, -1}); };
  } else {
    o.mesh = sliding_square();
  }
  s.objects.push_back(o);
  return s;
}

// The x range of the square at time t (plane z = -2, or -3 for the shared one).
void square_at(double t, double* x0, double* x1) {
  const double k = std::clamp(t, 0.0, 1.0);
  *x0 = -1.2 + 1.4 * k;
  *x1 = -0.2 + 1.4 * k;
}

// Renders face -Z from the origin at `time` and checks every texel whose ray meets the plane away
// from the square's edges: depth = the exact distance inside the square, +inf outside. Returns the
// texels inside.
size_t check_square(const Scene& scene, double time, double plane_z, std::vector<float>* depth) {
  auto tracer = FrameTracer::create(scene, time, LightfieldRenderOptions{1, 1, 0, 6, 0});
  EXPECT_TRUE(tracer.ok()) << tracer.status().to_string();
  if (!tracer.ok()) return 0;
  const uint32_t n = 48;
  capture::ViewFrame frame;
  (*tracer)->render_cube({0, 0, 0}, 0, 0, n, false, &frame);
  double x0, x1;
  square_at(time, &x0, &x1);
  size_t inside = 0;
  depth->clear();
  for (uint32_t y = 0; y < n; ++y) {
    for (uint32_t x = 0; x < n; ++x) {
      const Vec3 d = direction_from_texel(CubeFace::kNegZ, x, y, n);
      const double t = plane_z / d.z;  // d is unit, so t is the radial distance
      const double px = t * d.x, py = t * d.y;
      const float got = frame.depth[frame.texel_index(CubeFace::kNegZ, x, y)];
      depth->push_back(got);
      const double margin = 0.02;
      if (px > x0 + margin && px < x1 - margin && std::fabs(py) < 0.5 - margin) {
        EXPECT_NEAR(got, t, 1e-4 * t) << "texel " << x << "," << y << " at time " << time;
        ++inside;
      } else if (px < x0 - margin || px > x1 + margin || std::fabs(py) > 0.5 + margin) {
        EXPECT_TRUE(std::isinf(got)) << "texel " << x << "," << y << " at time " << time;
      }
    }
  }
  return inside;
}

TEST(VertexStates, PositionsAtMatchTheSceneFileReader) {
  TriangleMesh m = sliding_square();
  m.state_times = {0.25f, 0.5f, 1.75f};
  m.state_positions.clear();
  for (int k = 0; k < 3; ++k) {
    for (int v = 0; v < 4; ++v) {
      m.state_positions.emplace_back(0.1f * static_cast<float>(v) + 0.37f * static_cast<float>(k),
                                     std::sin(static_cast<float>(k + v)), 1.0f / (1 + k + v));
    }
  }
  capture::SceneMesh file;
  for (const glm::vec3& p : m.positions)
    file.positions.insert(file.positions.end(), {p.x, p.y, p.z});
  file.state_times = m.state_times;
  for (const glm::vec3& p : m.state_positions) {
    file.state_positions.insert(file.state_positions.end(), {p.x, p.y, p.z});
  }
  std::vector<glm::vec3> ours;
  std::vector<float> theirs;
  for (double t : {0.0, 0.25, 0.3, 1.0 / 3, 0.5, 0.9, 1.7, 1.75, 2.0, 100.0}) {
    positions_at(m, t, &ours);
    capture::positions_at(file, t, &theirs);
    ASSERT_EQ(ours.size() * 3, theirs.size());
    for (size_t i = 0; i < ours.size(); ++i) {
      EXPECT_EQ(ours[i].x, theirs[3 * i]) << t;
      EXPECT_EQ(ours[i].y, theirs[3 * i + 1]) << t;
      EXPECT_EQ(ours[i].z, theirs[3 * i + 2]) << t;
    }
  }
  // Held before the first state and after the last; exact at a state's time.
  positions_at(m, 0.0, &ours);
  EXPECT_EQ(ours[2], m.state_positions[2]);
  positions_at(m, 0.5, &ours);
  EXPECT_EQ(ours[1], m.state_positions[5]);
  positions_at(m, 9.0, &ours);
  EXPECT_EQ(ours[3], m.state_positions[11]);
  // Without states: the positions.
  m.state_times.clear();
  m.state_positions.clear();
  positions_at(m, 0.7, &ours);
  EXPECT_EQ(ours, m.positions);
}

TEST(VertexStates, ValidationNamesTheFault) {
  Scene s = states_scene(false);
  ASSERT_TRUE(validate_scene(s).ok()) << validate_scene(s).to_string();
  auto expect_bad = [&](Scene bad, const std::string& words) {
    Status st = validate_scene(bad);
    EXPECT_EQ(st.id(), ErrorId::kSceneGeometry) << words;
    EXPECT_NE(st.to_string().find(words), std::string::npos) << st.to_string();
  };
  Scene bad = s;
  bad.objects[0].mesh.state_times = {1.0f, 0.5f};
  expect_bad(bad, "strictly increasing");
  bad = s;
  bad.objects[0].mesh.state_times = {-1.0f, 0.5f};
  expect_bad(bad, "state 0 at time");
  bad = s;
  bad.objects[0].mesh.state_times[1] = NAN;
  expect_bad(bad, "state 1");
  bad = s;
  bad.objects[0].mesh.state_positions.pop_back();
  expect_bad(bad, "7 state positions for 2 states of 4 vertices");
  bad = s;
  bad.objects[0].mesh.state_positions[6].z = INFINITY;
  expect_bad(bad, "vertex 2 in state 1");
  bad = s;
  bad.objects[0].mesh.state_times.assign(4097, 0.0f);
  for (size_t k = 0; k < 4097; ++k) bad.objects[0].mesh.state_times[k] = static_cast<float>(k);
  expect_bad(bad, "4097 vertex states");
  // A shared mesh is checked too, and an object cannot have both a shared mesh and its own.
  Scene shared = states_scene(true);
  ASSERT_TRUE(validate_scene(shared).ok());
  auto broken = std::make_shared<TriangleMesh>(*shared.objects[0].shared_mesh);
  broken->triangles.push_back({0, 1, 9});
  bad = shared;
  bad.objects[0].shared_mesh = broken;
  expect_bad(bad, "(shared mesh) has triangle 2");
  bad = shared;
  bad.objects[0].spheres.push_back({glm::vec3(0), 1});
  expect_bad(bad, "also triangles or spheres");
}

TEST(VertexStates, TheTracerFollowsTheStates) {
  for (bool shared : {false, true}) {
    SCOPED_TRACE(shared ? "shared mesh" : "own mesh");
    const Scene scene = states_scene(shared);
    const double plane = shared ? -3 : -2;
    std::vector<float> at0, at1, between;
    const size_t in0 = check_square(scene, 0.0, plane, &at0);
    const size_t in1 = check_square(scene, 1.0, plane, &at1);
    const size_t in_half = check_square(scene, 0.5, plane, &between);
    EXPECT_GT(in0, 50u);
    EXPECT_GT(in1, 50u);
    EXPECT_GT(in_half, 50u);
    // The motion: texels hit at frame 0 and sky at frame 1, and the other way round.
    size_t left = 0, right = 0;
    for (size_t i = 0; i < at0.size(); ++i) {
      left += std::isfinite(at0[i]) && std::isinf(at1[i]);
      right += std::isinf(at0[i]) && std::isfinite(at1[i]);
    }
    EXPECT_GT(left, 50u);
    EXPECT_GT(right, 50u);
  }
}

// Three placements of one mesh (one of them mirrored) against three copies transformed into the
// objects' own meshes: the same hits, depth and shading up to float rounding.
TEST(SharedMesh, InstancesRenderAsCopies) {
  TriangleMesh prototype;
  add_box(&prototype, {-0.3f, 0, -0.3f}, {0.3f, 0.8f, 0.3f});
  add_cylinder(&prototype,
               glm::scale(glm::translate(glm::mat4(1), {0, 1.1f, 0}), {0.1f, 0.3f, 0.1f}), 8);
  const glm::mat4 placements[] = {
      glm::translate(glm::mat4(1), {1.5f, -0.5f, 0}),
      glm::rotate(glm::translate(glm::mat4(1), {-1, -0.5f, -1.2f}), 0.7f, glm::vec3(0, 1, 0)),
      glm::scale(glm::translate(glm::mat4(1), {0, -0.5f, 1.6f}), {-1.3f, 1.3f, 1.3f})};
  Scene instanced, copies;
  for (Scene* s : {&instanced, &copies}) {
    s->name = "instances";
    s->materials = {Material{}, Material{}};
    s->materials[1].albedo = {0.2f, 0.5f, 0.9f};
    s->sky.sun_irradiance = glm::vec3(2.0f);
    Object floor;
    floor.name = "floor";
    add_quad(&floor.mesh, {-5, -0.5f, -5}, {-5, -0.5f, 5}, {5, -0.5f, 5}, {5, -0.5f, -5});
    s->objects.push_back(floor);
  }
  auto shared = std::make_shared<const TriangleMesh>(prototype);
  for (size_t i = 0; i < std::size(placements); ++i) {
    const glm::mat4 m = placements[i];
    Object a;
    a.name = "instance-" + std::to_string(i);
    a.material = 1;
    a.shared_mesh = shared;
    a.transform = [m](double) { return m; };
    instanced.objects.push_back(a);
    Object b;
    b.name = a.name;
    b.material = 1;
    b.mesh.triangles = prototype.triangles;
    for (const glm::vec3& p : prototype.positions)
      b.mesh.positions.emplace_back(m * glm::vec4(p, 1));
    copies.objects.push_back(b);
  }
  EXPECT_EQ(instanced.triangle_count(), copies.triangle_count());
  const LightfieldRenderOptions options{2, 7, 4, 6, 0};
  auto a = FrameTracer::create(instanced, 0, options);
  auto b = FrameTracer::create(copies, 0, options);
  ASSERT_TRUE(a.ok() && b.ok());
  capture::ViewFrame fa, fb;
  (*a)->render_cube({0, 0.4, 0}, 0, 0, 32, false, &fa);
  (*b)->render_cube({0, 0.4, 0}, 0, 0, 32, false, &fb);
  size_t hits = 0, differing = 0;
  for (size_t i = 0; i < fa.texel_count(); ++i) {
    ASSERT_EQ(std::isinf(fa.depth[i]), std::isinf(fb.depth[i])) << i;
    if (std::isinf(fa.depth[i])) continue;
    ++hits;
    EXPECT_NEAR(fa.depth[i], fb.depth[i], 1e-4f * fb.depth[i]) << i;
    // AO rays start a hair apart, so an odd texel may flip one AO sample: count, do not fail.
    for (int c = 0; c < 3; ++c) {
      differing += std::fabs(fa.color[3 * i + c] - fb.color[3 * i + c]) > 1e-3f;
    }
  }
  EXPECT_GT(hits, fa.texel_count() / 3);
  EXPECT_LT(differing, hits / 50) << "shading differs on " << differing << " channels";
  // Normals (which way a face points) as the copies': inside the instances is inside. The mirrored
  // copy is inside out (its winding flips with the mirror), and so must the instance be.
  for (size_t i = 0; i < std::size(placements); ++i) {
    const glm::vec3 c = glm::vec3(placements[i] * glm::vec4(0, 0.4f, 0, 1));
    const Vec3 centre{c.x, c.y, c.z};
    EXPECT_EQ((*a)->inside_geometry(centre), (*b)->inside_geometry(centre)) << i;
    if (i < 2) {
      EXPECT_TRUE((*a)->inside_geometry(centre)) << i;
    }
  }
  EXPECT_FALSE((*a)->inside_geometry({0, 0.4, 0}));
}

TEST(SharedMesh, ExportStoresTheMeshOnceAndTheStatesExactly) {
  Scene s = states_scene(true);
  Object second = s.objects[0];
  second.name = "square-2";
  second.transform = [](double t) {
    return glm::translate(glm::mat4(1), {0, static_cast<float>(t), -1});
  };
  s.objects.push_back(second);
  Object own;
  own.name = "own";
  own.mesh = sliding_square();
  s.objects.push_back(own);
  ASSERT_TRUE(validate_scene(s).ok());
  auto file = export_scene(s, 2);
  ASSERT_TRUE(file.ok()) << file.status().to_string();
  ASSERT_EQ(file->meshes.size(), 2u);
  ASSERT_EQ(file->objects.size(), 3u);
  EXPECT_EQ(file->objects[0].mesh, 0u);
  EXPECT_EQ(file->objects[1].mesh, 0u);
  EXPECT_EQ(file->objects[2].mesh, 1u);
  EXPECT_EQ(file->meshes[0].name, "square-mesh");
  EXPECT_EQ(file->meshes[1].name, "own");
  EXPECT_EQ(file->objects[0].transforms.size(), 1u);  // static
  EXPECT_EQ(file->objects[1].transforms.size(), 2u);  // moving
  EXPECT_EQ(file->triangle_count(), 6u);
  EXPECT_EQ(file->mesh_triangle_count(), 4u);

  const fs::path dir =
      fs::temp_directory_path() / ("calf_vertex_states_" + std::to_string(getpid()));
  fs::remove_all(dir);
  ASSERT_TRUE(write_scene(s, 2, dir).ok());
  auto back = capture::read_scene_file(dir);
  ASSERT_TRUE(back.ok()) << back.status().to_string();
  EXPECT_EQ(*back, *file);
  for (size_t m = 0; m < 2; ++m) {
    const TriangleMesh& source = m == 0 ? *s.objects[0].shared_mesh : s.objects[2].mesh;
    const capture::SceneMesh& got = back->meshes[m];
    EXPECT_EQ(got.state_times, source.state_times);
    ASSERT_EQ(got.state_positions.size(), source.state_positions.size() * 3);
    for (size_t i = 0; i < source.state_positions.size(); ++i) {
      EXPECT_EQ(got.state_positions[3 * i], source.state_positions[i].x);
      EXPECT_EQ(got.state_positions[3 * i + 1], source.state_positions[i].y);
      EXPECT_EQ(got.state_positions[3 * i + 2], source.state_positions[i].z);
    }
    // The reader's positions at a time are the tracer's.
    std::vector<glm::vec3> ours;
    std::vector<float> theirs;
    positions_at(source, 0.3, &ours);
    capture::positions_at(got, 0.3, &theirs);
    ASSERT_EQ(theirs.size(), ours.size() * 3);
    for (size_t i = 0; i < ours.size(); ++i) EXPECT_EQ(theirs[3 * i], ours[i].x);
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace calf::samples
