// A small scene file made by code for the mesh track's tests, conformance clip and fuzz seeds:
// a quad with normals, colours and per-triangle materials placed twice (one static instance, one
// moving per frame), a strip with piecewise-linear vertex states, a mesh of one triangle and two
// analytic spheres and a mesh that is one sphere alone. Without `spheres` (the small conformance
// clips and fuzz seeds) the spheres are left out and the last mesh is a tetrahedron with
// normals; a panel reuses the quad's triangles. Deterministic: the same floats on every machine.
#pragma once

#include <cstdint>
#include <vector>

#include "calf/capture/scene_file.h"

namespace calf::test {

inline capture::SceneFile make_mesh_test_scene(uint32_t frame_count = 3, bool spheres = true) {
  capture::SceneFile s;
  s.name = "mesh-test";
  s.fps = 24;
  s.frame_count = frame_count;
  s.view_volume = {{-1, 1.5, -1}, {1, 1.7, 1}};
  s.materials.push_back({"grey", {0.5f, 0.5f, 0.5f}, capture::kNoTexture, {0, 0, 0}, 0, 0, 1.5f});
  s.materials.push_back({"lamp", {1, 0.75f, 0.25f}, capture::kNoTexture, {4, 3, 2}, 0, 0, 1.5f});
  s.materials.push_back(
      {"blue", {0.1f, 0.2f, 0.9f}, capture::kNoTexture, {0, 0, 0}, 0.5f, 0, 1.5f});

  capture::SceneMesh quad;
  quad.name = "quad";
  quad.positions = {-1, 0, -1, 1, 0, -1, 1, 0, 1, -1, 0, 1};
  quad.normals = {0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0};
  quad.colors = {1, 0, 0, 0, 1, 0, 0, 0, 1, 0.5f, 0.25f, 0.125f};
  quad.indices = {0, 2, 1, 0, 3, 2};
  quad.triangle_materials = {0, 2};
  s.meshes.push_back(quad);

  capture::SceneMesh strip;  // a 6-triangle strip that sways: 3 states
  strip.name = "strip";
  for (int i = 0; i < 4; ++i) {
    const float x = static_cast<float>(i) * 0.3f - 0.45f;
    strip.positions.insert(strip.positions.end(), {x, 0.0f, 3.0f, x, 1.0f, 3.0f});
  }
  for (uint32_t i = 0; i < 3; ++i) {
    const uint32_t a = 2 * i, b = a + 1, c = a + 2, d = a + 3;
    strip.indices.insert(strip.indices.end(), {a, c, b, b, c, d});
  }
  strip.state_times = {0.0f, 0.05f, 0.1f};
  for (int k = 0; k < 3; ++k) {
    for (size_t v = 0; v < strip.positions.size(); v += 3) {
      const bool top = strip.positions[v + 1] > 0.5f;
      strip.state_positions.push_back(strip.positions[v] +
                                      (top ? 0.1f * static_cast<float>(k) : 0));
      strip.state_positions.push_back(strip.positions[v + 1]);
      strip.state_positions.push_back(strip.positions[v + 2]);
    }
  }
  s.meshes.push_back(strip);

  capture::SceneMesh balls;  // one triangle of its own, then two spheres
  balls.name = "balls";
  balls.positions = {0, 0, -4, 0.5f, 0, -4, 0, 0.5f, -4};
  balls.indices = {0, 1, 2};
  if (spheres) balls.spheres = {{{0, 1, -5}, 0.5f}, {{1.5f, 0.75f, -5}, 0.25f}};
  s.meshes.push_back(balls);

  capture::SceneMesh ball;  // a sphere alone: stored with its normals
  ball.name = "ball";
  if (spheres) {
    ball.spheres = {{{0, 0, 0}, 1}};
  } else {
    ball.positions = {1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0};
    ball.normals = {1, 0, 0, 0, 1, 0, 0, 0, 1, -1, -1, -1};
    ball.indices = {0, 1, 2, 0, 3, 1, 1, 3, 2, 2, 3, 0};
  }
  s.meshes.push_back(ball);

  capture::SceneMesh panel;  // the quad's triangles on other vertices: shares its triangles chunk
  panel.name = "panel";
  panel.positions = {0, 0, 0, 2, 0, 0, 2, 1, 0, 0, 1, 0};
  panel.indices = quad.indices;
  panel.triangle_materials = quad.triangle_materials;
  s.meshes.push_back(panel);

  capture::SceneObject floor{"floor", 0, 0, {}};  // identity
  capture::SceneObject tile{"tile", 0, 1, {{1, 0, 0, 2, 0, 1, 0, 0, 0, 0, 1, 0}}};
  capture::SceneObject mover{"mover", 0, 2, {}};
  for (uint32_t f = 0; f < frame_count; ++f) {
    mover.transforms.push_back(
        {1, 0, 0, 0.25f * static_cast<float>(f), 0, 1, 0, 0.5f, 0, 0, 1, -2});
  }
  capture::SceneObject grass{"grass", 1, 0, {}};
  capture::SceneObject toys{"toys", 2, 2, {}};
  capture::SceneObject sun{"sun", 3, 1, {{2, 0, 0, 5, 0, 2, 0, 9, 0, 0, 2, 5}}};
  capture::SceneObject sign{"sign", 4, 1, {{1, 0, 0, 0, 0, 1, 0, 2, 0, 0, 1, -6}}};
  s.objects = {floor, tile, mover, grass, toys, sun, sign};
  return s;
}

// A textured scene (mesh track layout 2): a quad with UVs beyond [0, 1] (repeat) drawing an 8 x 4
// texture through its object's material, a strip with UVs whose triangle materials mix a 3 x 5
// texture (not a power of two), the untextured material and the 8 x 4 one, an untextured
// tetrahedron without UVs placed with the textured material (drawn untextured), and a texture no
// material uses. Texels are a deterministic pattern with varying alpha.
inline capture::SceneFile make_textured_mesh_test_scene() {
  capture::SceneFile s;
  s.name = "mesh-textured";
  s.fps = 24;
  s.frame_count = 2;
  s.view_volume = {{-1, 1.5, -1}, {1, 1.7, 1}};
  const auto texture = [](const char* path, uint32_t w, uint32_t h, uint32_t seed) {
    capture::SceneTexture t;
    t.path = path;
    t.width = w;
    t.height = h;
    for (uint32_t y = 0; y < h; ++y) {
      for (uint32_t x = 0; x < w; ++x) {
        const uint32_t k = (x * 37 + y * 101 + seed * 53) % 256;
        t.rgba.insert(t.rgba.end(), {static_cast<uint8_t>(k), static_cast<uint8_t>(255 - k),
                                     static_cast<uint8_t>((x * 255) / (w > 1 ? w - 1 : 1)),
                                     static_cast<uint8_t>(255 - 16 * y)});
      }
    }
    return t;
  };
  s.textures = {texture("textures/checker.png", 8, 4, 1), texture("textures/odd.png", 3, 5, 2),
                texture("textures/unused.png", 2, 2, 3)};
  s.materials.push_back({"plain", {0.5f, 0.5f, 0.5f}, capture::kNoTexture, {0, 0, 0}, 0, 0, 1.5f});
  s.materials.push_back({"checker", {1, 1, 1}, 0, {0, 0, 0}, 0, 0, 1.5f});
  s.materials.push_back({"odd", {0.9f, 0.8f, 0.7f}, 1, {0.1f, 0, 0}, 0, 0, 1.5f});

  capture::SceneMesh quad;
  quad.name = "quad";
  quad.positions = {-1, 0, -1, 1, 0, -1, 1, 0, 1, -1, 0, 1};
  quad.normals = {0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0};
  quad.uvs = {0, 0, 2, 0, 2, 1.5f, -0.5f, 1.5f};
  quad.indices = {0, 2, 1, 0, 3, 2};
  s.meshes.push_back(quad);

  capture::SceneMesh strip;
  strip.name = "strip";
  for (int i = 0; i < 4; ++i) {
    const float x = static_cast<float>(i) * 0.3f - 0.45f;
    strip.positions.insert(strip.positions.end(), {x, 0.0f, 3.0f, x, 1.0f, 3.0f});
    strip.uvs.insert(strip.uvs.end(), {static_cast<float>(i) / 3, 1, static_cast<float>(i) / 3, 0});
  }
  strip.colors.assign(strip.positions.size(), 0.75f);
  for (uint32_t i = 0; i < 3; ++i) {
    const uint32_t a = 2 * i, b = a + 1, c = a + 2, d = a + 3;
    strip.indices.insert(strip.indices.end(), {a, c, b, b, c, d});
  }
  strip.triangle_materials = {2, 2, 0, 0, 1, 1};
  s.meshes.push_back(strip);

  capture::SceneMesh tetra;
  tetra.name = "tetra";
  tetra.positions = {1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0};
  tetra.indices = {0, 1, 2, 0, 3, 1, 1, 3, 2, 2, 3, 0};
  s.meshes.push_back(tetra);

  capture::SceneObject floor{"floor", 0, 1, {}};
  capture::SceneObject banner{"banner", 1, 1, {{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, -1}}};
  capture::SceneObject rock{"rock", 2, 2, {{1, 0, 0, 0.5f, 0, 1, 0, 0, 0, 0, 1, -2}}};
  s.objects = {floor, banner, rock};
  return s;
}

}  // namespace calf::test
