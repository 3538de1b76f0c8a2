// Base-colour textures in the sample scenes (calf/samples/texture.h, the tracer's albedo lookup,
// assimp loading and the scene-file export): filtered lookups against texels computed here from
// the sRGB curve, UV orientation of glTF and OBJ through assimp, mip filtering of a far checker,
// the missing / undecodable texture errors, and the export round trip.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <OpenImageIO/imageio.h>

#include "../scratch_dir.h"
#include "calf/capture/scene_file.h"
#include "calf/format/colour.h"
#include "calf/samples/render.h"
#include "calf/samples/scene.h"
#include "calf/samples/scene_export.h"
#include "calf/samples/texture.h"

namespace calf::samples {
namespace {

namespace fs = std::filesystem;

const fs::path& dir() {
  return test::scratch_dir("calf_texture_test");
}

// An image of w x h texels from a function of (x, y) giving sRGB bytes (alpha 255).
template <typename Fn>
capture::SceneTexture image(uint32_t w, uint32_t h, Fn fn) {
  capture::SceneTexture t;
  t.width = w, t.height = h;
  t.rgba.resize(size_t{w} * h * 4);
  for (uint32_t y = 0; y < h; ++y) {
    for (uint32_t x = 0; x < w; ++x) {
      const glm::u8vec3 c = fn(x, y);
      uint8_t* p = &t.rgba[(size_t{y} * w + x) * 4];
      p[0] = c.r, p[1] = c.g, p[2] = c.b, p[3] = 255;
    }
  }
  return t;
}

// The linear colour of texel (x, y), by the sRGB curve (not by the code under test).
glm::vec3 texel(const capture::SceneTexture& t, uint32_t x, uint32_t y) {
  const uint8_t* p = &t.rgba[(size_t{y} * t.width + x) * 4];
  return {linear_from_srgb8(p[0]), linear_from_srgb8(p[1]), linear_from_srgb8(p[2])};
}

// A 4 x 4 image of 16 distinct colours.
capture::SceneTexture distinct4() {
  return image(4, 4, [](uint32_t x, uint32_t y) {
    return glm::u8vec3(static_cast<uint8_t>(20 + 60 * x), static_cast<uint8_t>(20 + 60 * y),
                       static_cast<uint8_t>(200 - 40 * x - 10 * y));
  });
}

void write_png(const fs::path& path, const capture::SceneTexture& t) {
  auto out = OIIO::ImageOutput::create("png");
  ASSERT_TRUE(out);
  OIIO::ImageSpec spec(static_cast<int>(t.width), static_cast<int>(t.height), 4,
                       OIIO::TypeDesc::UINT8);
  ASSERT_TRUE(out->open(path.string(), spec));
  ASSERT_TRUE(out->write_image(OIIO::TypeDesc::UINT8, t.rgba.data()));
  ASSERT_TRUE(out->close());
}

void write_text(const fs::path& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

// Lit by a unit ambient term only (no sun, no lights, no AO), so a diffuse surface's radiance is
// its reflectance: the texture's filtered linear value times the albedo.
void ambient_only(Scene* s) {
  s->lights.clear();
  s->sky.sun_irradiance = glm::vec3(0);
  s->ambient = glm::vec3(1);
}

// The quad z = `z`, x and y in [-1, 1], facing +Z, with UVs (0, 0) at its top-left corner
// (-1, 1) and (`span`, `span`) at its bottom-right: a scene file's convention, v down.
Scene quad_scene(capture::SceneTexture tex, float span, float z) {
  Scene s;
  s.name = "textured-quad";
  Material m;
  m.albedo = glm::vec3(1);
  m.base_color_texture = 0;
  s.materials = {m};
  s.textures = {make_texture(std::move(tex))};
  Object o;
  o.name = "quad";
  add_quad(&o.mesh, {-1, 1, z}, {-1, -1, z}, {1, -1, z}, {1, 1, z});
  o.mesh.uvs = {{0, 0}, {0, span}, {span, span}, {span, 0}};
  s.objects.push_back(std::move(o));
  ambient_only(&s);
  s.default_rig = ring_rig(1, 0.1, {0, 0, 0});
  return s;
}

// One sample through each pixel centre, no AO, no noise: these tests check the texture lookup at
// a ray (pixel anti-aliasing, LightfieldRenderOptions::spp, is tests/samples/antialias_test.cc's).
LightfieldRenderOptions centre_ray_options() {
  LightfieldRenderOptions o{1, 1, 0, 2, 0};
  o.spp = 1;
  return o;
}

// A camera at `eye` looking down -Z with a 90-degree field of view: the quad z = eye.z - 1,
// x, y in [-1, 1] fills its square image exactly, pixel i's centre at x = 2 (i + 0.5) / n - 1.
capture::PerspectiveImage render_front(const Scene& s, uint32_t n, glm::dvec3 eye = {0, 0, 1}) {
  auto tracer = FrameTracer::create(s, 0, centre_ray_options());
  EXPECT_TRUE(tracer.ok()) << tracer.status().to_string();
  capture::PerspectiveImage img;
  if (!tracer.ok()) return img;
  (*tracer)->render_perspective(look_at_pose(0, eye, eye - glm::dvec3(0, 0, 1), 90), n, n, 0, &img);
  return img;
}

glm::vec3 pixel(const capture::PerspectiveImage& img, uint32_t i, uint32_t j) {
  const float* p = &img.color[(size_t{j} * img.width + i) * 3];
  return {p[0], p[1], p[2]};
}

void expect_near(const glm::vec3& got, const glm::vec3& want, float tol, const std::string& what) {
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[c], want[c], tol) << what << " channel " << c;
}

// ---- the texture itself ----

TEST(Texture, TexelCentresAreExactAndEdgesWrap) {
  const capture::SceneTexture src = distinct4();
  auto t = make_texture(src);
  for (uint32_t y = 0; y < 4; ++y) {
    for (uint32_t x = 0; x < 4; ++x) {
      const glm::vec2 uv((x + 0.5f) / 4, (y + 0.5f) / 4);
      expect_near(sample_texture(*t, uv, 0), texel(src, x, y), 1e-6f, "texel centre");
      // Repeat: a whole number of periods away reads the same texel.
      expect_near(sample_texture(*t, uv + glm::vec2(3, -2), 0), texel(src, x, y), 1e-5f, "wrap");
    }
  }
  // u = 0 lies between the last column and the first: half of each (repeat, bilinear).
  expect_near(sample_texture(*t, {0, 0.125f}, 0), 0.5f * (texel(src, 0, 0) + texel(src, 3, 0)),
              1e-6f, "wrapped edge");
}

TEST(Texture, MipChainKeepsTheMeanAtEverySize) {
  // Odd sizes too: a box reduction by exact areas keeps every level's mean that of level 0.
  for (const glm::uvec2 size : {glm::uvec2(8, 8), glm::uvec2(5, 3), glm::uvec2(7, 1)}) {
    const capture::SceneTexture src = image(size.x, size.y, [](uint32_t x, uint32_t y) {
      return glm::u8vec3(static_cast<uint8_t>((x * 37 + y * 91) % 256),
                         static_cast<uint8_t>((x + y) % 2 ? 255 : 0), static_cast<uint8_t>(y * 30));
    });
    glm::dvec3 mean(0);
    for (uint32_t y = 0; y < size.y; ++y) {
      for (uint32_t x = 0; x < size.x; ++x) mean += glm::dvec3(texel(src, x, y));
    }
    mean /= static_cast<double>(size.x * size.y);
    auto t = make_texture(src);
    ASSERT_EQ(t->levels.back().width, 1u);
    ASSERT_EQ(t->levels.back().height, 1u);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(t->levels.back().texels[0][c], mean[c], 1e-5);
    // A lod past the last level reads the 1 x 1 level anywhere.
    expect_near(sample_texture(*t, {0.3f, 0.9f}, 40), glm::vec3(mean), 1e-5f, "top level");
  }
}

TEST(Texture, LevelOfDetailIsTexelsAcrossTheFootprint) {
  auto t = make_texture(image(256, 256, [](uint32_t, uint32_t) { return glm::u8vec3(0); }));
  // A unit square mapped to the whole texture: 256 texels per scene unit (areas doubled).
  const float uv_area = 1, world_area = 1;
  EXPECT_NEAR(texture_lod(*t, 1.0f / 256, 1, uv_area, world_area), 0, 1e-5);
  EXPECT_NEAR(texture_lod(*t, 4.0f / 256, 1, uv_area, world_area), 2, 1e-5);
  // Seen at 60 degrees from the normal, the footprint is twice as long: one level more.
  EXPECT_NEAR(texture_lod(*t, 4.0f / 256, 0.5f, uv_area, world_area), 3, 1e-5);
  // UVs repeating 4 times over the square: 4 times the density.
  EXPECT_NEAR(texture_lod(*t, 1.0f / 256, 1, 16, world_area), 2, 1e-5);
  // A degenerate triangle reads full resolution, never NaN.
  EXPECT_EQ(texture_lod(*t, 1, 1, 0, 0), 0);
  // Pixel spread: 2 / n on the axis; at 60 degrees off axis cos^1.5 = 0.3536.
  EXPECT_NEAR(pixel_spread(0.01f, 1), 0.01f, 1e-9);
  EXPECT_NEAR(pixel_spread(0.01f, 0.5f), 0.01f * 0.35355339f, 1e-8);
}

// ---- rendering ----

TEST(Texture, RenderedTexelsMatchTheTexture) {
  // 12 x 12 pixels over 4 x 4 texels: pixel 3k + 1's centre is texel k's centre exactly, and the
  // footprint (1/3 texel) selects level 0, so the pixel is the texel: only the float error of the
  // ray-quad intersection remains (about 1e-6 texel), hence 1e-4.
  const capture::SceneTexture src = distinct4();
  const Scene s = quad_scene(src, 1, 0);
  const capture::PerspectiveImage img = render_front(s, 12);
  ASSERT_EQ(img.color.size(), 12u * 12u * 3u);
  for (uint32_t y = 0; y < 4; ++y) {
    for (uint32_t x = 0; x < 4; ++x) {
      expect_near(pixel(img, 3 * x + 1, 3 * y + 1), texel(src, x, y), 1e-4f,
                  "texel " + std::to_string(x) + "," + std::to_string(y));
    }
  }
  // Between texel centres the lookup is bilinear: pixel 3k + 2 lies 1/3 texel past k's centre
  // (u = (3k + 2.5) / 12 = (k + 0.8333) / 4).
  const float f = 1.0f / 3;
  expect_near(pixel(img, 2, 1), texel(src, 0, 0) * (1 - f) + texel(src, 1, 0) * f, 1e-4f,
              "bilinear");
  // Albedo (a glTF base colour factor) multiplies the texture.
  Scene tinted = quad_scene(src, 1, 0);
  tinted.materials[0].albedo = {0.5f, 1, 0.25f};
  const capture::PerspectiveImage t = render_front(tinted, 12);
  expect_near(pixel(t, 4, 7), texel(src, 1, 2) * glm::vec3(0.5f, 1, 0.25f), 1e-4f, "factor");
}

// Mean and largest deviation from `mean` of an image's first channel.
float worst_deviation(const std::vector<float>& rgb, float mean) {
  float worst = 0;
  for (size_t i = 0; i < rgb.size(); i += 3) worst = std::max(worst, std::fabs(rgb[i] - mean));
  return worst;
}

TEST(Texture, FarCheckerConvergesToItsMeanNearOneKeepsItsContrast) {
  // An 8 x 8 checker of black and white texels: linear mean exactly 0.5.
  const capture::SceneTexture checker = image(
      8, 8, [](uint32_t x, uint32_t y) { return (x + y) % 2 ? glm::u8vec3(255) : glm::u8vec3(0); });
  // Far: the UVs repeat 61.3 times over the quad, 490 texels across 32 pixels (15 per pixel):
  // point or bilinear sampling of level 0 would give anything in [0, 1] per pixel (an aliased
  // pattern; a whole number of repeats would put every pixel centre on a texel corner, where
  // bilinear happens to give 0.5); the mip chain gives 0.5 exactly from level 1 on (every 2 x 2
  // box of a one-texel checker averages 0.5; lod 3.9 here). Perspective and cube faces alike.
  const Scene far = quad_scene(checker, 61.3f, 0);
  const capture::PerspectiveImage img = render_front(far, 32);
  EXPECT_LT(worst_deviation(img.color, 0.5f), 1e-4f);
  auto tracer = FrameTracer::create(far, 0, centre_ray_options());
  ASSERT_TRUE(tracer.ok());
  capture::ViewFrame cube;
  // From (0, 0, 1) the quad z = 0 fills the -Z face exactly.
  (*tracer)->render_cube({0, 0, 1}, 0, 0, 32, false, &cube);
  const size_t face = 5, texels = 32 * 32;
  std::vector<float> neg_z(cube.color.begin() + face * texels * 3,
                           cube.color.begin() + (face + 1) * texels * 3);
  EXPECT_LT(worst_deviation(neg_z, 0.5f), 1e-4f);

  // Near: 8 texels across 32 pixels (lod -2, level 0, bilinear): texel centres keep 0 and 1.
  const Scene near = quad_scene(checker, 1, 0);
  const capture::PerspectiveImage n = render_front(near, 32);
  // Pixel 4k + 2 is 1/8 texel right of and below texel k's centre: weights 49, 7, 7 and 1 / 64.
  // Texel (0, 0) is black, (1, 0) and (0, 1) white, (1, 1) black: 14 / 64; one texel right,
  // the opposite: 50 / 64. Point sampling would give 0 and 1, a box over the pixel 1/4 and 3/4.
  EXPECT_NEAR(pixel(n, 2, 2).x, 14.0f / 64, 1e-4);
  EXPECT_NEAR(pixel(n, 6, 2).x, 50.0f / 64, 1e-4);
}

TEST(Texture, ConvergedPixelsFilterATextureEdgeOnlyOverThePixel) {
  // A 256 x 256 texture, black left of u = 0.5 and white right of it, over the quad seen at 32 x
  // 32: 8 texels per pixel, the edge exactly on the boundary of pixels 15 and 16. A box filter of
  // the texture over each pixel gives 0 and 1 on either side. The samples are that box filter, so
  // each sample's own texture filter must be narrower than the pixel: a whole pixel's footprint
  // per sample (mip level 3, 1-pixel texels, read bilinearly) spreads the edge half a pixel into
  // pixel 15, 0.125 of the step by the tent's area; the first round's stratum (1 / sqrt(8) of a
  // pixel) spreads it about a quarter pixel.
  const capture::SceneTexture edge =
      image(256, 256, [](uint32_t x, uint32_t) { return glm::u8vec3(x < 128 ? 0 : 255); });
  const Scene s = quad_scene(edge, 1, 0);
  LightfieldRenderOptions o{1, 1, 0, 2, 0};
  o.spp = 64;
  o.min_spp = 8;
  o.tolerance = 0;
  auto tracer = FrameTracer::create(s, 0, o);
  ASSERT_TRUE(tracer.ok()) << tracer.status().to_string();
  capture::PerspectiveImage img;
  const glm::dvec3 eye(0, 0, 1);
  (*tracer)->render_perspective(look_at_pose(0, eye, eye - glm::dvec3(0, 0, 1), 90), 32, 32, 0,
                                &img);
  for (uint32_t j : {8u, 16u, 24u}) {
    EXPECT_LT(pixel(img, 14, j).x, 0.01f) << "row " << j;
    EXPECT_LT(pixel(img, 15, j).x, 0.08f) << "row " << j;
    EXPECT_GT(pixel(img, 16, j).x, 0.92f) << "row " << j;
    EXPECT_GT(pixel(img, 17, j).x, 0.99f) << "row " << j;
  }
}

// ---- models through assimp ----

// 2 x 2: top row red, green; bottom row blue, white.
capture::SceneTexture corners() {
  return image(2, 2, [](uint32_t x, uint32_t y) {
    const glm::u8vec3 c[2][2] = {{{255, 0, 0}, {0, 255, 0}}, {{0, 0, 255}, {255, 255, 255}}};
    return c[y][x];
  });
}

// The unit quad z = 0, x, y in [-1, 1], facing +Z, as glTF: UV (0, 0) at the top-left corner
// (glTF's UV origin is the image's top-left). An external .bin and image.
std::string quad_gltf(const fs::path& folder, const std::string& image_uri,
                      const std::string& factor) {
  const float positions[12] = {-1, 1, 0, -1, -1, 0, 1, -1, 0, 1, 1, 0};
  const float uvs[8] = {0, 0, 0, 1, 1, 1, 1, 0};
  const uint16_t indices[6] = {0, 1, 2, 0, 2, 3};
  std::string bin(reinterpret_cast<const char*>(positions), sizeof positions);
  bin.append(reinterpret_cast<const char*>(uvs), sizeof uvs);
  bin.append(reinterpret_cast<const char*>(indices), sizeof indices);
  write_text(folder / "quad.bin", bin);
  return R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
  "nodes": [{"mesh": 0}],
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "indices": 2,
    "material": 0}]}],
  "materials": [{"name": "quad", "pbrMetallicRoughness": {"baseColorFactor": )" +
         factor + R"(, "baseColorTexture": {"index": 0}, "metallicFactor": 0}}],
  "textures": [{"source": 0}], "images": [{"uri": ")" +
         image_uri + R"("}],
  "buffers": [{"uri": "quad.bin", "byteLength": 92}],
  "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 48},
    {"buffer": 0, "byteOffset": 48, "byteLength": 32},
    {"buffer": 0, "byteOffset": 80, "byteLength": 12}],
  "accessors": [
    {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
     "min": [-1, -1, 0], "max": [1, 1, 0]},
    {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC2"},
    {"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"}]})";
}

// The same quad as OBJ: OBJ's UV origin is the image's bottom-left, so the top-left corner has
// vt (0, 1).
std::string quad_obj(const std::string& mtl) {
  return "mtllib " + mtl +
         "\nv -1 1 0\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\n"
         "vt 0 1\nvt 0 0\nvt 1 0\nvt 1 1\nusemtl quad\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n";
}

// Renders a loaded model (ambient only) from (0, 0, 1) at 6 x 6: pixel 3k + 1 is texel k's
// centre of a 2 x 2 texture.
capture::PerspectiveImage render_model(const fs::path& file) {
  auto scene = load_scene_file(file);
  EXPECT_TRUE(scene.ok()) << scene.status().to_string();
  if (!scene.ok()) return {};
  ambient_only(&*scene);
  return render_front(*scene, 6);
}

TEST(Texture, GltfAndObjUvOriginsAgreeThroughAssimp) {
  const fs::path folder = dir() / "orientation";
  fs::create_directories(folder);
  const capture::SceneTexture tex = corners();
  write_png(folder / "corners.png", tex);
  write_text(folder / "quad.gltf", quad_gltf(folder, "corners.png", "[1, 1, 1, 1]"));
  write_text(folder / "quad.mtl", "newmtl quad\nKd 1 1 1\nmap_Kd corners.png\n");
  write_text(folder / "quad.obj", quad_obj("quad.mtl"));
  for (const char* name : {"quad.gltf", "quad.obj"}) {
    const capture::PerspectiveImage img = render_model(folder / name);
    ASSERT_EQ(img.width, 6u) << name;
    // The image's top row is at the quad's top in both formats; left is left.
    for (uint32_t y = 0; y < 2; ++y) {
      for (uint32_t x = 0; x < 2; ++x) {
        expect_near(pixel(img, 3 * x + 1, 3 * y + 1), texel(tex, x, y), 1e-4f,
                    std::string(name) + " texel " + std::to_string(x) + "," + std::to_string(y));
      }
    }
  }
  // glTF's base colour factor multiplies the texture.
  write_text(folder / "tinted.gltf", quad_gltf(folder, "corners.png", "[0.5, 0.25, 1, 1]"));
  const capture::PerspectiveImage tinted = render_model(folder / "tinted.gltf");
  ASSERT_EQ(tinted.width, 6u);
  expect_near(pixel(tinted, 4, 4), glm::vec3(0.5f, 0.25f, 1), 1e-4f, "white texel x factor");
}

TEST(Texture, MissingOrUndecodableTextureIsAnErrorNamingIt) {
  const fs::path folder = dir() / "errors";
  fs::create_directories(folder);
  write_text(folder / "missing.mtl", "newmtl quad\nKd 1 1 1\nmap_Kd nowhere.png\n");
  write_text(folder / "missing.obj", quad_obj("missing.mtl"));
  auto missing = load_scene_file(folder / "missing.obj");
  ASSERT_FALSE(missing.ok());
  EXPECT_EQ(missing.status().id(), ErrorId::kModelTextureMissing);
  EXPECT_NE(missing.status().message().find("nowhere.png"), std::string::npos)
      << missing.status().message();
  EXPECT_NE(missing.status().message().find("'quad'"), std::string::npos)
      << missing.status().message();

  write_text(folder / "garbage.png", "this is not an image at all");
  write_text(folder / "garbage.mtl", "newmtl quad\nKd 1 1 1\nmap_Kd garbage.png\n");
  write_text(folder / "garbage.obj", quad_obj("garbage.mtl"));
  auto garbage = load_scene_file(folder / "garbage.obj");
  ASSERT_FALSE(garbage.ok());
  EXPECT_EQ(garbage.status().id(), ErrorId::kModelTexture);
  EXPECT_NE(garbage.status().message().find("garbage.png"), std::string::npos)
      << garbage.status().message();

  // A Windows path from another machine: found by its name alone beside the model.
  write_png(folder / "corners.png", corners());
  write_text(folder / "windows.mtl", "newmtl quad\nmap_Kd C:\\Users\\someone\\corners.png\n");
  write_text(folder / "windows.obj", quad_obj("windows.mtl"));
  auto windows = load_scene_file(folder / "windows.obj");
  ASSERT_TRUE(windows.ok()) << windows.status().to_string();
  EXPECT_EQ(windows->textures.size(), 1u);
}

// Debian's assimp-testmodels (tools/setup.sh installs it; skipped where absent): the same box as
// glTF with an external PNG, as GLB (the PNG in the binary chunk: assimp's embedded texture) and
// as glTF with a data URI decode to the same texture, and the textured truck loads.
TEST(Texture, AssimpTestModelsExternalAndEmbeddedAgree) {
  const fs::path root = "/usr/share/assimp/models";
  const fs::path box = root / "glTF2/BoxTextured-glTF/BoxTextured.gltf";
  if (!fs::exists(box)) GTEST_SKIP() << "assimp-testmodels is not installed";
  std::vector<capture::SceneTexture> images;
  for (const fs::path& file : {box, root / "glTF2/BoxTextured-glTF-Binary/BoxTextured.glb",
                               root / "glTF2/BoxTextured-glTF-Embedded/BoxTextured.gltf"}) {
    auto scene = load_scene_file(file);
    ASSERT_TRUE(scene.ok()) << scene.status().to_string();
    ASSERT_EQ(scene->textures.size(), 1u) << file;
    ASSERT_FALSE(scene->objects.empty());
    EXPECT_EQ(scene->objects[0].mesh.uvs.size(), scene->objects[0].mesh.positions.size()) << file;
    images.push_back(scene->textures[0]->image);
  }
  EXPECT_GT(images[0].width, 1u);
  EXPECT_EQ(images[0].rgba, images[1].rgba);
  EXPECT_EQ(images[0].rgba, images[2].rgba);
  const fs::path truck = root / "glTF/CesiumMilkTruck/CesiumMilkTruck.gltf";
  if (fs::exists(truck)) {
    auto scene = load_scene_file(truck);
    ASSERT_TRUE(scene.ok()) << scene.status().to_string();
    EXPECT_EQ(scene->textures.size(), 1u);
  }
}

// ---- export ----

TEST(Texture, ExportCarriesUvsAndTexturesIntoSceneFiles) {
  const fs::path folder = dir() / "export";
  fs::create_directories(folder);
  const capture::SceneTexture tex = corners();
  write_png(folder / "corners.png", tex);
  write_text(folder / "quad.gltf", quad_gltf(folder, "corners.png", "[1, 1, 1, 1]"));
  auto scene = load_scene_file(folder / "quad.gltf");
  ASSERT_TRUE(scene.ok()) << scene.status().to_string();
  ASSERT_TRUE(write_scene(*scene, 1, folder / "scene").ok());
  auto file = capture::read_scene_file(folder / "scene");
  ASSERT_TRUE(file.ok()) << file.status().to_string();
  ASSERT_EQ(file->textures.size(), 1u);
  EXPECT_EQ(file->textures[0].width, 2u);
  EXPECT_EQ(file->textures[0].rgba, tex.rgba);  // the bytes as loaded, through PNG
  ASSERT_EQ(file->objects.size(), 1u);          // (assimp adds a default material after the file's)
  EXPECT_EQ(file->materials[file->objects[0].material].base_color_texture, 0u);
  ASSERT_EQ(file->meshes.size(), 1u);
  const capture::SceneMesh& mesh = file->meshes[0];
  ASSERT_EQ(mesh.uvs.size(), 2 * mesh.vertex_count());
  // Each vertex keeps its UV in the scene file's convention (v down from the top row): the
  // top-left corner (-1, 1) has (0, 0), the bottom-right (1, -1) has (1, 1).
  for (size_t v = 0; v < mesh.vertex_count(); ++v) {
    const float x = mesh.positions[3 * v], y = mesh.positions[3 * v + 1];
    EXPECT_FLOAT_EQ(mesh.uvs[2 * v], (x + 1) / 2) << v;
    EXPECT_FLOAT_EQ(mesh.uvs[2 * v + 1], (1 - y) / 2) << v;
  }
}

}  // namespace
}  // namespace calf::samples
