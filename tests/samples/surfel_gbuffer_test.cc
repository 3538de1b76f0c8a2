// The surfel-candidate G-buffers (calf/samples/surfel_candidates.h): candidates lie on the mesh
// (brute-force distance to the nearest triangle), a cube seen from its 8 corners shows all 6 faces
// in equal shares and as many candidates as its projected area predicts, hidden surfaces give
// none, spheres are exact, colour sets follow the materials of the objects placing a mesh, the
// output is the same for any thread count, and a whole scene writes a file that reads back and
// matches it.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "calf/capture/surfel_candidates.h"
#include "calf/samples/scene.h"
#include "calf/samples/scene_export.h"
#include "calf/samples/surfel_candidates.h"

namespace calf::samples {
namespace {

namespace fs = std::filesystem;
using capture::SceneFile;
using capture::SceneMesh;

// The outward box [lo, hi] as a scene-file mesh (add_box's winding).
SceneMesh box_mesh(const glm::vec3& lo, const glm::vec3& hi) {
  TriangleMesh t;
  add_box(&t, lo, hi);
  SceneMesh m;
  for (const glm::vec3& p : t.positions) m.positions.insert(m.positions.end(), {p.x, p.y, p.z});
  for (const glm::uvec3& i : t.triangles) m.indices.insert(m.indices.end(), {i.x, i.y, i.z});
  return m;
}

SceneFile one_mesh_scene(SceneMesh mesh, std::vector<uint32_t> object_materials) {
  SceneFile s;
  s.name = "test";
  for (int i = 0; i < 3; ++i) {
    capture::SceneMaterial m;
    m.base_color = {1, 0.5f, 0};
    if (i == 1) m.base_color = {0, 0, 1};
    if (i == 2) m.base_color = {0.25f, 1, 1};
    s.materials.push_back(m);
  }
  s.meshes.push_back(std::move(mesh));
  for (uint32_t material : object_materials) s.objects.push_back({"o", 0, material, {}});
  return s;
}

glm::vec3 at(const std::vector<float>& a, size_t i) {
  return {a[3 * i], a[3 * i + 1], a[3 * i + 2]};
}

// Distance from p to triangle abc (Ericson, Real-Time Collision Detection 5.1.5), in double.
double point_triangle(glm::dvec3 p, glm::dvec3 a, glm::dvec3 b, glm::dvec3 c) {
  const glm::dvec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return glm::length(p - a);
  const glm::dvec3 bp = p - b;
  const double d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return glm::length(p - b);
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return glm::length(p - (a + ab * (d1 / (d1 - d3))));
  const glm::dvec3 cp = p - c;
  const double d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return glm::length(p - c);
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return glm::length(p - (a + ac * (d2 / (d2 - d6))));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    return glm::length(p - (b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)))));
  }
  const double denom = 1 / (va + vb + vc);
  return glm::length(p - (a + ab * (vb * denom) + ac * (vc * denom)));
}

double distance_to_mesh(const SceneMesh& m, const glm::vec3& p) {
  double best = INFINITY;
  for (size_t t = 0; t < m.triangle_count(); ++t) {
    glm::dvec3 v[3];
    for (int k = 0; k < 3; ++k) {
      const uint32_t i = m.indices[3 * t + k];
      v[k] = {m.positions[3 * i], m.positions[3 * i + 1], m.positions[3 * i + 2]};
    }
    best = std::min(best, point_triangle(glm::dvec3(p), v[0], v[1], v[2]));
  }
  return best;
}

SurfelCandidateOptions options(uint32_t resolution, uint32_t threads = 2) {
  SurfelCandidateOptions o;
  o.resolution = resolution;
  o.threads = threads;
  return o;
}

TEST(SurfelGBuffer, CubeFromItsCornersShowsAllSixFacesOnItsSurface) {
  const glm::vec3 centre(1, 2, 3);
  const SceneFile scene = one_mesh_scene(box_mesh(centre - 1.0f, centre + 1.0f), {0});
  constexpr uint32_t kR = 64;
  auto c = surfel_candidates_of_mesh(scene, 0, options(kR));
  ASSERT_TRUE(c.ok()) << c.status().to_string();
  ASSERT_EQ(c->views.size(), 8u);
  // Each view sees three faces: a hexagon of area 3 * 4 / sqrt(3) in a window whose side is
  // twice the hexagon's larger half extent (4 / sqrt 6 along the view's up) plus 1/1000.
  const double side = 2 * 4 / std::sqrt(6.0) * 1.001;
  const double expected = 12 / std::sqrt(3.0) / (side * side) * kR * kR;  // ~2655
  for (const capture::SurfelCandidateView& v : c->views) {
    EXPECT_NEAR(v.candidate_count, expected, 0.03 * expected);
    EXPECT_NEAR(v.pixel_size, side / kR, 1e-5);
    const glm::vec3 d(v.direction[0], v.direction[1], v.direction[2]);
    EXPECT_NEAR(std::fabs(d.x), 1 / std::sqrt(3.0), 1e-6);  // a cube diagonal
    EXPECT_NEAR(std::fabs(d.y), 1 / std::sqrt(3.0), 1e-6);
  }
  size_t per_face[6] = {};
  for (size_t i = 0; i < c->candidate_count(); ++i) {
    const glm::vec3 p = at(c->positions, i), n = at(c->normals, i);
    ASSERT_LE(distance_to_mesh(scene.meshes[0], p), 1e-5) << i;
    // The face: the axis on which the point is 1 from the centre; its outward normal.
    const glm::vec3 q = p - centre;
    int axis = 0;
    for (int a = 1; a < 3; ++a) {
      if (std::fabs(q[a]) > std::fabs(q[axis])) axis = a;
    }
    ASSERT_NEAR(std::fabs(q[axis]), 1, 1e-5) << i;
    glm::vec3 outward(0);
    outward[axis] = q[axis] > 0 ? 1 : -1;
    EXPECT_GT(glm::dot(n, outward), 0.99999f) << i;
    ++per_face[2 * axis + (q[axis] > 0 ? 0 : 1)];
  }
  // By symmetry each face is seen by 4 of the 8 views at the same angle: equal shares.
  for (size_t f = 0; f < 6; ++f) {
    EXPECT_NEAR(per_face[f], c->candidate_count() / 6.0, 0.02 * c->candidate_count() / 6) << f;
  }
  // One colour set, the base colour (1, 0.5, 0) sRGB-encoded: 0.5 -> 0.7354 -> 188.
  ASSERT_EQ(c->colour_sets.size(), 1u);
  EXPECT_EQ(c->colour_sets[0].material, 0u);
  for (size_t i = 0; i < c->candidate_count(); ++i) {
    ASSERT_EQ(c->colour_sets[0].colours[3 * i], 255);
    ASSERT_EQ(c->colour_sets[0].colours[3 * i + 1], 188);
    ASSERT_EQ(c->colour_sets[0].colours[3 * i + 2], 0);
  }
  EXPECT_EQ(c->mesh_hash, capture::surfel_mesh_hash(scene.meshes[0]));
}

TEST(SurfelGBuffer, HiddenSurfacesGiveNoCandidates) {
  SceneMesh m = box_mesh({-1, -1, -1}, {1, 1, 1});
  const SceneMesh inner = box_mesh({-0.2f, -0.2f, -0.2f}, {0.2f, 0.2f, 0.2f});
  const uint32_t base = static_cast<uint32_t>(m.vertex_count());
  m.positions.insert(m.positions.end(), inner.positions.begin(), inner.positions.end());
  for (uint32_t i : inner.indices) m.indices.push_back(base + i);
  auto c = surfel_candidates_of_mesh(one_mesh_scene(m, {0}), 0, options(32));
  ASSERT_TRUE(c.ok());
  ASSERT_GT(c->candidate_count(), 1000u);
  for (size_t i = 0; i < c->candidate_count(); ++i) {
    const glm::vec3 p = at(c->positions, i);
    ASSERT_GT(std::max({std::fabs(p.x), std::fabs(p.y), std::fabs(p.z)}), 0.99f) << i;
  }
}

TEST(SurfelGBuffer, SphereCandidatesLieOnTheSphere) {
  SceneMesh m;
  m.spheres.push_back({{0.5f, -1, 2}, 0.75f});
  auto c = surfel_candidates_of_mesh(one_mesh_scene(m, {1}), 0, options(32));
  ASSERT_TRUE(c.ok());
  // Per view a disc of radius r in a window of side 2 * (4 / sqrt 6) r * 1.001 (the enclosing
  // cube's projection along a diagonal).
  const double side = 2 * 4 / std::sqrt(6.0) * 1.001;
  for (const capture::SurfelCandidateView& v : c->views) {
    EXPECT_NEAR(v.candidate_count, 3.14159265 / (side * side) * 32 * 32, 0.04 * 301);
  }
  const glm::vec3 centre(0.5f, -1, 2);
  for (size_t i = 0; i < c->candidate_count(); ++i) {
    const glm::vec3 p = at(c->positions, i);
    ASSERT_NEAR(glm::length(p - centre), 0.75f, 1e-5f) << i;
    ASSERT_GT(glm::dot(at(c->normals, i), glm::normalize(p - centre)), 0.9999f) << i;
    ASSERT_EQ(c->colour_sets[0].colours[3 * i + 2], 255);  // material 1: blue
  }
}

TEST(SurfelGBuffer, ColourSetsFollowTheObjectsMaterials) {
  SceneMesh m = box_mesh({0, 0, 0}, {1, 1, 1});
  // Vertex colours of 0.25 multiply the base colour: material 0's (1, 0.5, 0) -> (0.25, 0.125, 0)
  // -> sRGB bytes 137, 99, 0; material 2's (0.25, 1, 1) -> (0.0625, 0.25, 0.25) -> 71, 137, 137.
  m.colors.assign(3 * m.vertex_count(), 0.25f);
  auto c = surfel_candidates_of_mesh(one_mesh_scene(m, {2, 0, 2}), 0, options(16));
  ASSERT_TRUE(c.ok());
  ASSERT_EQ(c->colour_sets.size(), 2u);
  EXPECT_EQ(c->colour_sets[0].material, 0u);
  EXPECT_EQ(c->colour_sets[1].material, 2u);
  const uint8_t expected[2][3] = {{137, 99, 0}, {71, 137, 137}};
  for (int s = 0; s < 2; ++s) {
    for (size_t i = 0; i < c->candidate_count(); ++i) {
      for (int a = 0; a < 3; ++a) {
        ASSERT_EQ(c->colour_sets[s].colours[3 * i + a], expected[s][a]) << s << " " << i;
      }
    }
  }
  // Triangle materials replace the object's: every triangle material 1 (blue), in every set.
  SceneMesh own = box_mesh({0, 0, 0}, {1, 1, 1});
  own.triangle_materials.assign(own.triangle_count(), 1);
  auto t = surfel_candidates_of_mesh(one_mesh_scene(own, {0, 2}), 0, options(16));
  ASSERT_TRUE(t.ok());
  for (const capture::SurfelColourSet& set : t->colour_sets) {
    for (size_t i = 0; i < t->candidate_count(); ++i) {
      ASSERT_EQ(set.colours[3 * i], 0);
      ASSERT_EQ(set.colours[3 * i + 2], 255);
    }
  }
  // A mesh no object places has no colour set.
  auto none = surfel_candidates_of_mesh(one_mesh_scene(m, {}), 0, options(16));
  ASSERT_TRUE(none.ok());
  EXPECT_TRUE(none->colour_sets.empty());
  EXPECT_GT(none->candidate_count(), 0u);
}

TEST(SurfelGBuffer, DirectionsFromCubeOrBoxCorners) {
  const glm::vec3 lo(-2, 0, -1), hi(2, 0, 1);  // a flat part
  const auto cube = surfel_view_directions(lo, hi, 8, capture::SurfelCorners::kCube);
  const auto box = surfel_view_directions(lo, hi, 8, capture::SurfelCorners::kBox);
  const auto sixteen = surfel_view_directions(lo, hi, 16, capture::SurfelCorners::kCube);
  ASSERT_EQ(cube.size(), 8u);
  ASSERT_EQ(sixteen.size(), 16u);
  for (int k = 0; k < 8; ++k) {
    // Corner k: + on x when bit 0 is set; the view looks from it towards the centre.
    EXPECT_EQ(cube[k].x < 0, (k & 1) != 0) << k;
    EXPECT_EQ(cube[k].y < 0, (k & 2) != 0) << k;
    EXPECT_EQ(cube[k].z < 0, (k & 4) != 0) << k;
    EXPECT_NEAR(std::fabs(cube[k].y), 1 / std::sqrt(3.0f), 1e-6f);
    EXPECT_EQ(box[k].y, 0.0f) << "the paper's corners see a flat part edge-on";
    EXPECT_NEAR(std::fabs(box[k].x), 2 / std::sqrt(5.0f), 1e-6f);
    // 8..15: the same turned 45 degrees about +Y (same height, azimuth + 45 degrees).
    EXPECT_NEAR(sixteen[8 + k].y, cube[k].y, 1e-6f);
    const float y = cube[k].y;
    EXPECT_NEAR(glm::dot(sixteen[8 + k], cube[k]), y * y + (1 - y * y) * std::cos(0.78539816f),
                1e-5f);
  }
  for (int a = 0; a < 16; ++a) {
    for (int b = a + 1; b < 16; ++b) EXPECT_LT(glm::dot(sixteen[a], sixteen[b]), 0.99f) << a << b;
  }
}

TEST(SurfelGBuffer, OptionsOutsideTheirRangeAreRefused) {
  const SceneFile scene = one_mesh_scene(box_mesh({0, 0, 0}, {1, 1, 1}), {0});
  SurfelCandidateOptions o;
  o.resolution = 0;
  EXPECT_EQ(surfel_candidates_of_mesh(scene, 0, o).status().id(), ErrorId::kSurfelOption);
  o.resolution = 4097;
  EXPECT_EQ(validate_surfel_candidate_options(o).id(), ErrorId::kSurfelOption);
  o.resolution = 8;
  o.directions = 12;
  EXPECT_EQ(validate_surfel_candidate_options(o).id(), ErrorId::kSurfelOption);
  o.directions = 16;
  EXPECT_TRUE(validate_surfel_candidate_options(o).ok());
  EXPECT_EQ(surfel_candidates_of_mesh(scene, 1, o).status().id(), ErrorId::kSurfelOption);
}

// The built-in "spheres" scene (triangles, analytic spheres, several materials): the same
// candidates for 1 and 3 threads, and a file that reads back equal and matches the scene.
TEST(SurfelGBuffer, SceneFileIsTheSameForAnyThreadCountAndMatchesTheScene) {
  auto scene = make_builtin_scene("spheres");
  ASSERT_TRUE(scene.ok());
  auto file = export_scene(*scene, 1);
  ASSERT_TRUE(file.ok());
  for (uint32_t m = 0; m < file->meshes.size(); m += 3) {
    auto one = surfel_candidates_of_mesh(*file, m, options(24, 1));
    auto three = surfel_candidates_of_mesh(*file, m, options(24, 3));
    ASSERT_TRUE(one.ok() && three.ok());
    EXPECT_TRUE(*one == *three) << "mesh " << m;
  }
  const fs::path dir = fs::temp_directory_path() / ("calf_surfel_gb_" + std::to_string(getpid()));
  fs::create_directories(dir);
  const std::string path = (dir / "spheres.cand").string();
  SurfelCandidateOptions o = options(16);
  o.directions = 16;
  uint64_t calls = 0, last_total = 0;
  auto stats = write_surfel_candidates(*file, o, path, [&](uint64_t done, uint64_t total) {
    ++calls;
    EXPECT_EQ(done, calls);
    last_total = total;
  });
  ASSERT_TRUE(stats.ok()) << stats.status().to_string();
  EXPECT_EQ(calls, 16 * file->meshes.size());
  EXPECT_EQ(last_total, calls);
  EXPECT_EQ(stats->bytes, fs::file_size(path));
  auto back = capture::read_surfel_candidates(path);
  ASSERT_TRUE(back.ok()) << back.status().to_string();
  EXPECT_EQ(back->header.direction_count, 16u);
  EXPECT_EQ(back->header.scene, "spheres");
  uint64_t total = 0;
  for (const auto& p : back->prototypes) total += p.candidate_count();
  EXPECT_EQ(total, stats->candidates);
  EXPECT_TRUE(
      capture::check_surfel_candidates_match(capture::surfel_candidate_entries(*back), *file, path)
          .ok());
  auto direct = surfel_candidates_of_mesh(*file, 2, o);
  ASSERT_TRUE(direct.ok());
  EXPECT_TRUE(back->prototypes[2] == *direct);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace calf::samples
