// calf/export/mesh_export.h: a mesh track exported to glTF / OBJ and read back by assimp's
// importer. The expected triangle counts and world-space bounds are computed here from the scene
// file itself (capture::transform_at / positions_at and the sphere contract), not from the track.
// The second, independent glTF reader (Khronos' glTF-Validator) runs in the CLI tests.
#include "calf/export/mesh_export.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include <unistd.h>

#include <OpenImageIO/imageio.h>
#include <assimp/scene.h>
#include <gtest/gtest.h>
#include <assimp/Importer.hpp>

#include "../integration/mesh_scene.h"
#include "calf/decoder/mesh_track.h"
#include "calf/encoder/mesh_encode.h"
#include "calf/encoder/sphere_mesh.h"
#include "calf/format/container.h"
#include "glb_reading.h"

namespace calf {
namespace {

using exporter::ExportedFile;
using exporter::MeshExportFormat;

std::vector<uint8_t> encode(const capture::SceneFile& scene,
                            const std::vector<std::vector<uint32_t>>* visible) {
  std::vector<uint8_t> file;
  auto w = container::Writer::create(container::memory_sink(&file));
  EXPECT_TRUE(w.ok());
  const Status st = encoder::encode_mesh_track(scene, visible, {}, &*w);
  EXPECT_TRUE(st.ok()) << st.to_string();
  EXPECT_TRUE(w->finish().ok());
  return file;
}

struct Box {
  std::array<double, 3> lo{std::numeric_limits<double>::infinity(),
                           std::numeric_limits<double>::infinity(),
                           std::numeric_limits<double>::infinity()};
  std::array<double, 3> hi{-std::numeric_limits<double>::infinity(),
                           -std::numeric_limits<double>::infinity(),
                           -std::numeric_limits<double>::infinity()};
  void add(double x, double y, double z) {
    const double p[3] = {x, y, z};
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], p[k]);
      hi[k] = std::max(hi[k], p[k]);
    }
  }
};

// Triangles and world-space bounds of an imported scene, walking its node tree.
void walk(const aiScene* scene, const aiNode* node, const aiMatrix4x4& parent, uint64_t* triangles,
          Box* box) {
  const aiMatrix4x4 m = parent * node->mTransformation;
  for (unsigned i = 0; i < node->mNumMeshes; ++i) {
    const aiMesh* mesh = scene->mMeshes[node->mMeshes[i]];
    *triangles += mesh->mNumFaces;
    for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
      for (unsigned k = 0; k < mesh->mFaces[f].mNumIndices; ++k) {
        const aiVector3D p = m * mesh->mVertices[mesh->mFaces[f].mIndices[k]];
        box->add(p.x, p.y, p.z);
      }
    }
  }
  for (unsigned c = 0; c < node->mNumChildren; ++c)
    walk(scene, node->mChildren[c], m, triangles, box);
}

// The scene's own figures at `frame`: triangles drawn (every triangle of every object, or the
// `visible` lists) and the world bounds of the vertices those triangles use.
void expected(const capture::SceneFile& scene, uint32_t frame,
              const std::vector<std::vector<uint32_t>>* visible, uint64_t* triangles, Box* box) {
  std::vector<float> positions;
  for (size_t o = 0; o < scene.objects.size(); ++o) {
    const capture::SceneObject& object = scene.objects[o];
    const capture::SceneMesh& mesh = scene.meshes[object.mesh];
    const capture::SceneTransform& m = capture::transform_at(object, frame);
    capture::positions_at(mesh, frame / scene.fps, &positions);
    const size_t own = mesh.triangle_count();
    std::vector<uint32_t> list;
    if (visible != nullptr) {
      list = (*visible)[o];
    } else {
      for (uint32_t t = 0; t < own + mesh.spheres.size() * encoder::kSphereTriangles; ++t) {
        list.push_back(t);
      }
    }
    *triangles += list.size();
    for (uint32_t t : list) {
      if (t < own) {
        for (int k = 0; k < 3; ++k) {
          const float* p = &positions[size_t{mesh.indices[size_t{t} * 3 + k]} * 3];
          box->add(m[0] * p[0] + m[1] * p[1] + m[2] * p[2] + m[3],
                   m[4] * p[0] + m[5] * p[1] + m[6] * p[2] + m[7],
                   m[8] * p[0] + m[9] * p[1] + m[10] * p[2] + m[11]);
        }
      } else {  // a sphere's triangle, from the tessellation the track contract names
        const uint32_t k = (t - own) / encoder::kSphereTriangles;
        const capture::SceneSphere& s = mesh.spheres[k];
        std::vector<float> sp, sn;
        std::vector<uint32_t> si;
        encoder::append_sphere_mesh(s.center.data(), s.radius, &sp, &sn, &si);
        const uint32_t local = (t - own) % encoder::kSphereTriangles;
        for (int c = 0; c < 3; ++c) {
          const float* p = &sp[size_t{si[size_t{local} * 3 + c]} * 3];
          box->add(m[0] * p[0] + m[1] * p[1] + m[2] * p[2] + m[3],
                   m[4] * p[0] + m[5] * p[1] + m[6] * p[2] + m[7],
                   m[8] * p[0] + m[9] * p[1] + m[10] * p[2] + m[11]);
        }
      }
    }
  }
}

struct Imported {
  uint64_t triangles = 0;
  Box box;
  unsigned materials = 0;
};

Imported read_scene(const aiScene* scene, const Assimp::Importer& importer) {
  Imported out;
  EXPECT_NE(scene, nullptr) << importer.GetErrorString();
  if (scene == nullptr) return out;
  walk(scene, scene->mRootNode, aiMatrix4x4(), &out.triangles, &out.box);
  // assimp's importers add a default material of their own to some scenes; count calf's.
  for (unsigned m = 0; m < scene->mNumMaterials; ++m) {
    if (std::string(scene->mMaterials[m]->GetName().C_Str()).rfind("material ", 0) == 0) {
      ++out.materials;
    }
  }
  return out;
}

Imported import(const ExportedFile& file, const char* hint) {
  Assimp::Importer importer;
  return read_scene(importer.ReadFileFromMemory(file.bytes.data(), file.bytes.size(), 0, hint),
                    importer);
}

// Writes the files as `<dir>/<stem><suffix>` with the main file's extension `ext`, then imports
// the main file by path, so that its side files are found by the names it gives them.
Imported import_files(const std::vector<ExportedFile>& files, const std::string& stem,
                      const std::string& ext) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("calf_export_test_" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  for (const ExportedFile& f : files) {
    std::ofstream(dir / (stem + (f.suffix.empty() ? ext : f.suffix)), std::ios::binary)
        .write(reinterpret_cast<const char*>(f.bytes.data()),
               static_cast<std::streamsize>(f.bytes.size()));
  }
  Assimp::Importer importer;
  Imported out = read_scene(importer.ReadFile((dir / (stem + ext)).string(), 0), importer);
  std::filesystem::remove_all(dir);
  return out;
}

void expect_boxes_near(const Box& a, const Box& b, double tolerance) {
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(a.lo[k], b.lo[k], tolerance) << "axis " << k;
    EXPECT_NEAR(a.hi[k], b.hi[k], tolerance) << "axis " << k;
  }
}

Expected<std::vector<ExportedFile>> export_clip(const std::vector<uint8_t>& clip, uint32_t frame,
                                                MeshExportFormat format,
                                                exporter::MeshExportStats* stats = nullptr) {
  auto reader = container::Reader::open(container::memory_source(std::span<const uint8_t>(clip)));
  EXPECT_TRUE(reader.ok());
  auto track = decoder::MeshTrack::open(*reader, 0);
  EXPECT_TRUE(track.ok()) << track.status().to_string();
  return exporter::export_mesh_track(*track, frame, format, "scene", stats);
}

TEST(MeshExport, GlbHoldsEveryTriangleAtTheFramesPlace) {
  const capture::SceneFile scene = test::make_mesh_test_scene(3, true);
  const std::vector<uint8_t> clip = encode(scene, nullptr);
  for (uint32_t frame : {0u, 2u}) {
    exporter::MeshExportStats stats;
    auto files = export_clip(clip, frame, MeshExportFormat::kGlb, &stats);
    ASSERT_TRUE(files.ok()) << files.status().to_string();
    ASSERT_EQ(files->size(), 1u);
    EXPECT_EQ(std::memcmp(files->front().bytes.data(), "glTF", 4), 0);
    uint64_t want = 0;
    Box want_box;
    expected(scene, frame, nullptr, &want, &want_box);
    const Imported got = import(files->front(), "glb");
    EXPECT_EQ(got.triangles, want) << "frame " << frame;
    EXPECT_EQ(stats.triangles, want);
    EXPECT_EQ(got.materials, scene.materials.size());
    expect_boxes_near(got.box, want_box, 1e-4);
  }
}

TEST(MeshExport, VisibleSetKeepsOnlyItsTriangles) {
  const capture::SceneFile scene = test::make_mesh_test_scene(3, true);
  // Per object: the first triangle, the last, or nothing.
  std::vector<std::vector<uint32_t>> visible(scene.objects.size());
  for (size_t o = 0; o < scene.objects.size(); ++o) {
    const capture::SceneMesh& mesh = scene.meshes[scene.objects[o].mesh];
    const uint32_t all = static_cast<uint32_t>(mesh.triangle_count() +
                                               mesh.spheres.size() * encoder::kSphereTriangles);
    if (o % 3 == 0) visible[o] = {0};
    if (o % 3 == 1 && all > 1) visible[o] = {0, all - 1};
  }
  const std::vector<uint8_t> clip = encode(scene, &visible);
  auto files = export_clip(clip, 1, MeshExportFormat::kGltf);
  ASSERT_TRUE(files.ok()) << files.status().to_string();
  uint64_t want = 0;
  Box want_box;
  expected(scene, 1, &visible, &want, &want_box);
  ASSERT_EQ(files->size(), 2u);
  EXPECT_EQ((*files)[1].suffix, ".bin");
  const std::string json((*files)[0].bytes.begin(), (*files)[0].bytes.end());
  EXPECT_NE(json.find("\"scene.bin\""), std::string::npos);
  const Imported got = import_files(*files, "scene", ".gltf");
  EXPECT_EQ(got.triangles, want);
  expect_boxes_near(got.box, want_box, 1e-4);
}

TEST(MeshExport, ObjWithItsMaterialLibrary) {
  const capture::SceneFile scene = test::make_mesh_test_scene(2, false);
  const std::vector<uint8_t> clip = encode(scene, nullptr);
  auto files = export_clip(clip, 0, MeshExportFormat::kObj);
  ASSERT_TRUE(files.ok()) << files.status().to_string();
  ASSERT_EQ(files->size(), 2u);
  EXPECT_EQ((*files)[1].suffix, ".mtl");
  const std::string obj((*files)[0].bytes.begin(), (*files)[0].bytes.end());
  EXPECT_NE(obj.find("mtllib scene.mtl\n"), std::string::npos);
  uint64_t want = 0;
  Box want_box;
  expected(scene, 0, nullptr, &want, &want_box);
  const Imported got = import_files(*files, "scene", ".obj");
  EXPECT_EQ(got.materials, scene.materials.size());
  EXPECT_EQ(got.triangles, want);
  expect_boxes_near(got.box, want_box, 1e-4);
}

// The PNG bytes of an export decoded back to RGBA8 (OpenImageIO, alpha unassociated).
// Through a file: this OpenImageIO's PNG reader takes no memory proxy.
std::vector<uint8_t> decode_png(const uint8_t* data, size_t size, uint32_t* w, uint32_t* h) {
  const std::filesystem::path path = std::filesystem::temp_directory_path() /
                                     ("calf_export_png_" + std::to_string(getpid()) + ".png");
  std::ofstream(path, std::ios::binary)
      .write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  OIIO::ImageSpec config;
  config.attribute("oiio:UnassociatedAlpha", 1);
  auto in = OIIO::ImageInput::open(path.string(), &config);
  EXPECT_TRUE(in) << OIIO::geterror();
  if (!in) return {};
  *w = static_cast<uint32_t>(in->spec().width);
  *h = static_cast<uint32_t>(in->spec().height);
  std::vector<uint8_t> rgba(size_t{*w} * *h * 4);
  EXPECT_EQ(in->spec().nchannels, 4);
  EXPECT_TRUE(in->read_image(0, 0, 0, 4, OIIO::TypeDesc::UINT8, rgba.data()));
  in->close();
  std::filesystem::remove(path);
  return rgba;
}

// The UVs of the imported meshes in SCENE.md's convention (assimp's v is up): each mesh's set of
// (u, v) pairs, sorted.
std::vector<std::pair<float, float>> uv_pairs(const aiMesh* m) {
  std::vector<std::pair<float, float>> out;
  if (m->mTextureCoords[0] == nullptr) return out;
  for (unsigned i = 0; i < m->mNumVertices; ++i)
    out.emplace_back(m->mTextureCoords[0][i].x, 1.0f - m->mTextureCoords[0][i].y);
  std::sort(out.begin(), out.end());
  return out;
}

TEST(MeshExport, TexturesAndUvsTravelIntoGlbAndObj) {
  const capture::SceneFile scene = test::make_textured_mesh_test_scene();
  const std::vector<uint8_t> clip = encode(scene, nullptr);
  exporter::MeshExportStats stats;
  auto glb = export_clip(clip, 0, MeshExportFormat::kGlb, &stats);
  ASSERT_TRUE(glb.ok()) << glb.status().to_string();
  ASSERT_EQ(glb->size(), 1u);
  EXPECT_EQ(stats.textures, 2u);  // the unused texture is left out
  Assimp::Importer importer;
  const aiScene* got =
      importer.ReadFileFromMemory(glb->front().bytes.data(), glb->front().bytes.size(), 0, "glb");
  ASSERT_NE(got, nullptr) << importer.GetErrorString();
  ASSERT_EQ(got->mNumTextures, 2u);
  // Each embedded image decodes to the scene's texels, and the material that names it does so.
  for (unsigned t = 0; t < 2; ++t) {
    const aiTexture* tex = got->mTextures[t];
    ASSERT_EQ(tex->mHeight, 0u);
    uint32_t w = 0, h = 0;
    const auto rgba =
        decode_png(reinterpret_cast<const uint8_t*>(tex->pcData), tex->mWidth, &w, &h);
    bool matched = false;
    for (const capture::SceneTexture& st : scene.textures)
      matched = matched || (st.width == w && st.height == h && st.rgba == rgba);
    EXPECT_TRUE(matched) << "embedded texture " << t << " (" << w << " x " << h << ")";
  }
  unsigned textured_materials = 0;
  for (unsigned m = 0; m < got->mNumMaterials; ++m) {
    aiString path;
    if (got->mMaterials[m]->GetTexture(aiTextureType_DIFFUSE, 0, &path) == AI_SUCCESS ||
        got->mMaterials[m]->GetTexture(aiTextureType_BASE_COLOR, 0, &path) == AI_SUCCESS) {
      ++textured_materials;
      EXPECT_EQ(path.C_Str()[0], '*') << path.C_Str();
    }
  }
  EXPECT_EQ(textured_materials, 2u);
  // The tetrahedron has no UVs: its textured material 2 is written as an untextured copy (glTF
  // needs TEXCOORD_0 for a texture; the renderers draw it untextured).
  bool copy = false;
  for (unsigned m = 0; m < got->mNumMaterials; ++m)
    copy = copy || std::string(got->mMaterials[m]->GetName().C_Str()) == "material 2 untextured";
  EXPECT_TRUE(copy);
  // The floor (scene mesh 0, drawn whole with its material) keeps its UVs, beyond [0, 1] too.
  std::vector<std::pair<float, float>> want;
  for (size_t i = 0; i < scene.meshes[0].uvs.size(); i += 2)
    want.emplace_back(scene.meshes[0].uvs[i], scene.meshes[0].uvs[i + 1]);
  std::sort(want.begin(), want.end());
  bool found = false;
  for (unsigned m = 0; m < got->mNumMeshes; ++m) {
    if (got->mMeshes[m]->mNumVertices != 4 || got->mMeshes[m]->mTextureCoords[0] == nullptr)
      continue;
    const auto pairs = uv_pairs(got->mMeshes[m]);
    bool same = pairs.size() == want.size();
    for (size_t i = 0; same && i < pairs.size(); ++i)
      same = std::abs(pairs[i].first - want[i].first) < 1e-6f &&
             std::abs(pairs[i].second - want[i].second) < 1e-6f;
    found = found || same;
  }
  EXPECT_TRUE(found) << "no mesh with the floor's UVs";

  // OBJ: the textures are side files named by map_Kd.
  auto obj = export_clip(clip, 0, MeshExportFormat::kObj);
  ASSERT_TRUE(obj.ok()) << obj.status().to_string();
  ASSERT_EQ(obj->size(), 4u);
  EXPECT_EQ((*obj)[2].suffix, "_texture0.png");
  EXPECT_EQ((*obj)[3].suffix, "_texture1.png");
  const std::string mtl((*obj)[1].bytes.begin(), (*obj)[1].bytes.end());
  EXPECT_NE(mtl.find("map_Kd scene_texture0.png"), std::string::npos) << mtl;
  uint32_t w = 0, h = 0;
  EXPECT_EQ(decode_png((*obj)[3].bytes.data(), (*obj)[3].bytes.size(), &w, &h),
            scene.textures[1].rgba);
  const std::string text((*obj)[0].bytes.begin(), (*obj)[0].bytes.end());
  EXPECT_NE(text.find("\nvt "), std::string::npos);
  const Imported back = import_files(*obj, "scene", ".obj");
  uint64_t triangles = 0;
  Box box;
  expected(scene, 0, nullptr, &triangles, &box);
  EXPECT_EQ(back.triangles, triangles);
}

// calf-play shades a mesh track under fixed lights (docs/PLAYER.md: colour x (0.3 + 0.7 max(0,
// n . L)) with L = (0.3, 0.8, 0.5) normalised, both sides of every triangle, no specular): a
// glTF carries them, so that an engine lights the file the same way.
TEST(MeshExport, GlbCarriesThePlayersLighting) {
  const capture::SceneFile scene = test::make_mesh_test_scene(2, false);
  auto files = export_clip(encode(scene, nullptr), 0, MeshExportFormat::kGlb);
  ASSERT_TRUE(files.ok()) << files.status().to_string();
  const nlohmann::json j = test::read_glb(files->front().bytes).json;
  ASSERT_FALSE(j.is_discarded());
  // The key light: directional, illuminance 0.7 pi lux (a Lambertian surface of albedo c then
  // reflects 0.7 c cos), travelling along -L: glTF's light shines along its node's -Z.
  const nlohmann::json& lights = j["extensions"]["KHR_lights_punctual"]["lights"];
  ASSERT_EQ(lights.size(), 1u);
  EXPECT_EQ(lights[0]["type"], "directional");
  EXPECT_NEAR(lights[0]["intensity"].get<double>(), 0.7 * M_PI, 1e-5);
  int light_nodes = 0;
  for (const auto& node : j["nodes"]) {
    if (!node.contains("extensions")) continue;
    ++light_nodes;
    EXPECT_EQ(node["extensions"]["KHR_lights_punctual"]["light"], 0);
    const std::vector<double> q = node["rotation"];  // x, y, z, w
    // The rotated -Z axis: -(third column of the rotation matrix).
    const double dir[3] = {-2 * (q[0] * q[2] + q[3] * q[1]), -2 * (q[1] * q[2] - q[3] * q[0]),
                           -(1 - 2 * (q[0] * q[0] + q[1] * q[1]))};
    const double n = std::sqrt(0.3 * 0.3 + 0.8 * 0.8 + 0.5 * 0.5);
    EXPECT_NEAR(dir[0], -0.3 / n, 1e-6);
    EXPECT_NEAR(dir[1], -0.8 / n, 1e-6);
    EXPECT_NEAR(dir[2], -0.5 / n, 1e-6);
  }
  EXPECT_EQ(light_nodes, 1);
  // The ambient share: a uniform environment of radiance 0.3, as the scene's extras.
  const nlohmann::json& extras = j["scenes"][0]["extras"];
  ASSERT_EQ(extras["calf_ambient_radiance"].size(), 3u);
  for (double v : extras["calf_ambient_radiance"]) EXPECT_NEAR(v, 0.3, 1e-6);
  // Materials: diffuse only, seen from both sides.
  ASSERT_FALSE(j["materials"].empty());
  for (const auto& m : j["materials"]) {
    EXPECT_EQ(m["extensions"]["KHR_materials_specular"]["specularFactor"], 0.0);
    EXPECT_EQ(m["doubleSided"], true);
  }
  std::vector<std::string> used = j["extensionsUsed"];
  std::sort(used.begin(), used.end());
  EXPECT_EQ(used, (std::vector<std::string>{"KHR_lights_punctual", "KHR_materials_specular"}));
  EXPECT_FALSE(j.contains("extensionsRequired"));
}

// GltfOptions::meshopt: every vertex and index view decodes (meshoptimizer) to the plain file's,
// in a smaller file; the same track gives the same bytes; OBJ refuses the option.
TEST(MeshExport, MeshoptHoldsTheSameGeometry) {
  const capture::SceneFile scene = test::make_mesh_test_scene(3, true);
  const std::vector<uint8_t> clip = encode(scene, nullptr);
  auto reader = container::Reader::open(container::memory_source(std::span<const uint8_t>(clip)));
  ASSERT_TRUE(reader.ok());
  auto track = decoder::MeshTrack::open(*reader, 0);
  ASSERT_TRUE(track.ok());
  exporter::GltfOptions meshopt;
  meshopt.meshopt = true;
  auto plain = exporter::export_mesh_track(*track, 1, MeshExportFormat::kGlb, "s");
  auto compressed =
      exporter::export_mesh_track(*track, 1, MeshExportFormat::kGlb, "s", nullptr, meshopt);
  auto again =
      exporter::export_mesh_track(*track, 1, MeshExportFormat::kGlb, "s", nullptr, meshopt);
  ASSERT_TRUE(plain.ok() && compressed.ok() && again.ok()) << compressed.status().to_string();
  EXPECT_EQ(compressed->front().bytes, again->front().bytes);
  size_t encoded = 0, decoded = 0;
  test::expect_meshopt_equals_plain(test::read_glb(plain->front().bytes),
                                    test::read_glb(compressed->front().bytes), &encoded, &decoded);
  EXPECT_GT(decoded, 0u);
  EXPECT_LT(encoded, decoded);
  EXPECT_LT(compressed->front().bytes.size(), plain->front().bytes.size());
  EXPECT_EQ(exporter::export_mesh_track(*track, 1, MeshExportFormat::kObj, "s", nullptr, meshopt)
                .status()
                .id(),
            ErrorId::kExportInput);
}

TEST(MeshExport, SameTrackSameBytes) {
  const capture::SceneFile scene = test::make_mesh_test_scene(3, true);
  const std::vector<uint8_t> clip = encode(scene, nullptr);
  auto a = export_clip(clip, 1, MeshExportFormat::kGlb);
  auto b = export_clip(clip, 1, MeshExportFormat::kGlb);
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_EQ(a->front().bytes, b->front().bytes);
}

TEST(MeshExport, BadRequestsAreRefused) {
  const capture::SceneFile scene = test::make_mesh_test_scene(3, false);
  const std::vector<uint8_t> clip = encode(scene, nullptr);
  auto past = export_clip(clip, 3, MeshExportFormat::kGlb);
  ASSERT_FALSE(past.ok());
  EXPECT_EQ(past.status().id(), ErrorId::kExportInput);
  EXPECT_NE(past.status().message().find("frame 3"), std::string::npos);

  EXPECT_EQ(exporter::mesh_export_format_from_path("a/b.GLB").value(), MeshExportFormat::kGlb);
  EXPECT_EQ(exporter::mesh_export_format_from_path("b.obj").value(), MeshExportFormat::kObj);
  for (const char* bad : {"b.fbx", "b", "dir.glb/b", ".glb.x"}) {
    auto f = exporter::mesh_export_format_from_path(bad);
    ASSERT_FALSE(f.ok()) << bad;
    EXPECT_EQ(f.status().id(), ErrorId::kExportInput);
  }

  // Side files are named after the stem, which must need no escaping in a uri or mtllib line.
  auto reader = container::Reader::open(container::memory_source(std::span<const uint8_t>(clip)));
  ASSERT_TRUE(reader.ok());
  auto track = decoder::MeshTrack::open(*reader, 0);
  ASSERT_TRUE(track.ok());
  auto spaced = exporter::export_mesh_track(*track, 0, MeshExportFormat::kGltf, "my scene");
  ASSERT_FALSE(spaced.ok());
  EXPECT_EQ(spaced.status().id(), ErrorId::kExportInput);
  EXPECT_TRUE(exporter::export_mesh_track(*track, 0, MeshExportFormat::kGlb, "my scene").ok());

  // A visible set that is empty everywhere has nothing to export.
  std::vector<std::vector<uint32_t>> none(scene.objects.size());
  const std::vector<uint8_t> empty = encode(scene, &none);
  auto nothing = export_clip(empty, 0, MeshExportFormat::kGlb);
  ASSERT_FALSE(nothing.ok());
  EXPECT_EQ(nothing.status().id(), ErrorId::kExportInput);
}

}  // namespace
}  // namespace calf
