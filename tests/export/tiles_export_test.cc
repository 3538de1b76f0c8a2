// calf/export/tiles_export.h: a tile set exported to glTF / OBJ and read back by assimp's
// importer: two triangles per tile (2 n^2 with subdivision), one embedded PNG of the atlas's size
// with straight alpha, the material's alpha mode BLEND and single-sided, texture coordinates
// (U / W, V / W) at the corners. Expected values come from the synthetic tile set itself
// (tests/integration/synthetic_tiles.h), not from the exporter. The second, independent glTF
// reader (Khronos' glTF-Validator) runs in the CLI tests (cli.calf_export_tiles_*).
#include "calf/export/tiles_export.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <unistd.h>

#include <OpenImageIO/imageio.h>
#include <assimp/GltfMaterial.h>
#include <assimp/scene.h>
#include <gtest/gtest.h>
#include <assimp/Importer.hpp>

#include "../integration/synthetic_tiles.h"

namespace calf {
namespace {

using exporter::ExportedFile;
using exporter::MeshExportFormat;

// Through a file: this OpenImageIO's PNG reader takes no memory proxy.
std::vector<uint8_t> decode_png(const uint8_t* data, size_t size, uint32_t* w, uint32_t* h) {
  const std::filesystem::path path = std::filesystem::temp_directory_path() /
                                     ("calf_tiles_png_" + std::to_string(getpid()) + ".png");
  std::ofstream(path, std::ios::binary)
      .write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  OIIO::ImageSpec config;
  config.attribute("oiio:UnassociatedAlpha", 1);
  auto in = OIIO::ImageInput::open(path.string(), &config);
  EXPECT_TRUE(in);
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

TileSet small_set() {
  return test::make_synthetic_tile_set(2, 10, 62, 21);  // 24 tiles, 62 x 40
}

TEST(TilesExport, GlbHasTwoTrianglesPerTileAndTheAtlas) {
  const TileSet set = small_set();
  exporter::TilesExportStats stats;
  auto glb = exporter::export_tile_set(set, MeshExportFormat::kGlb, "tiles", {}, &stats);
  ASSERT_TRUE(glb.ok()) << glb.status().to_string();
  ASSERT_EQ(glb->size(), 1u);
  EXPECT_EQ(stats.tiles, 24u);
  EXPECT_EQ(stats.triangles, 48u);
  EXPECT_EQ(stats.vertices, 96u) << "four corners per tile, the diagonal shared";
  Assimp::Importer importer;
  const aiScene* got =
      importer.ReadFileFromMemory(glb->front().bytes.data(), glb->front().bytes.size(), 0, "glb");
  ASSERT_NE(got, nullptr) << importer.GetErrorString();
  uint64_t triangles = 0;
  for (unsigned m = 0; m < got->mNumMeshes; ++m) triangles += got->mMeshes[m]->mNumFaces;
  EXPECT_EQ(triangles, 2 * set.tiles.size());
  ASSERT_EQ(got->mNumTextures, 1u);
  uint32_t w = 0, h = 0;
  const auto* tex = got->mTextures[0];
  const auto png = decode_png(reinterpret_cast<const uint8_t*>(tex->pcData), tex->mWidth, &w, &h);
  EXPECT_EQ(w, set.atlas_width);
  EXPECT_EQ(h, set.atlas_height);
  // Straight alpha: colour = premultiplied * 255 / alpha, rounded (a texel inside a disc's edge).
  size_t checked = 0;
  for (size_t i = 0; i + 3 < png.size(); i += 4) {
    const unsigned a = set.atlas_rgba[i + 3];
    EXPECT_EQ(png[i + 3], a);
    for (int c = 0; c < 3 && a > 0; ++c) {
      const double want = std::min(255.0, set.atlas_rgba[i + c] * 255.0 / a);
      ASSERT_LE(std::fabs(png[i + c] - want), 0.5 + 1e-9) << "texel " << i / 4;
      ++checked;
    }
  }
  EXPECT_GT(checked, 1000u);
  ASSERT_EQ(got->mNumMeshes, 1u);
  ASSERT_LT(got->mMeshes[0]->mMaterialIndex, got->mNumMaterials);
  const aiMaterial* material = got->mMaterials[got->mMeshes[0]->mMaterialIndex];
  aiString mode;
  ASSERT_EQ(material->Get(AI_MATKEY_GLTF_ALPHAMODE, mode), AI_SUCCESS);
  EXPECT_STREQ(mode.C_Str(), "BLEND");
  int two_sided = 1;
  material->Get(AI_MATKEY_TWOSIDED, two_sided);
  EXPECT_EQ(two_sided, 0);
  const std::string json(glb->front().bytes.begin(), glb->front().bytes.end());
  EXPECT_NE(json.find("\"alphaMode\":\"BLEND\""), std::string::npos);
  // Corner texture coordinates: (U / W, V / W) of the set, at some vertex of the import.
  const aiMesh* mesh = got->mMeshes[0];
  ASSERT_NE(mesh->mTextureCoords[0], nullptr);
  size_t matched = 0;
  for (const Tile& t : set.tiles) {
    for (const TileCorner& c : t.corners) {
      const float u = c.uvw[0] / c.uvw[2], v = c.uvw[1] / c.uvw[2];
      for (unsigned i = 0; i < mesh->mNumVertices; ++i) {
        const aiVector3D& p = mesh->mVertices[i];
        if (p.x == c.position[0] && p.y == c.position[1] && p.z == c.position[2]) {
          EXPECT_NEAR(mesh->mTextureCoords[0][i].x, u, 1e-6);
          EXPECT_NEAR(1.0f - mesh->mTextureCoords[0][i].y, v, 1e-6);  // assimp's v is up
          ++matched;
          break;
        }
      }
    }
  }
  EXPECT_EQ(matched, 4 * set.tiles.size());
}

TEST(TilesExport, SubdivisionBoundsTheAffineError) {
  const TileSet set = small_set();
  double last = INFINITY;
  for (uint32_t n : {1u, 2u, 4u}) {
    exporter::TilesExportOptions o;
    o.subdivide = n;
    exporter::TilesExportStats stats;
    auto glb = exporter::export_tile_set(set, MeshExportFormat::kGlb, "t", o, &stats);
    ASSERT_TRUE(glb.ok()) << glb.status().to_string();
    EXPECT_EQ(stats.triangles, 2ull * n * n * set.tiles.size());
    std::printf("subdivide %u: %llu triangles, largest affine texture error %.4f texels\n", n,
                static_cast<unsigned long long>(stats.triangles), stats.max_texel_error);
    EXPECT_LT(stats.max_texel_error, last);
    last = stats.max_texel_error;
    Assimp::Importer importer;
    const aiScene* got =
        importer.ReadFileFromMemory(glb->front().bytes.data(), glb->front().bytes.size(), 0, "glb");
    ASSERT_NE(got, nullptr);
    EXPECT_EQ(got->mMeshes[0]->mNumFaces, stats.triangles);
  }
  // The synthetic tiles are tilted by up to ~35 degrees: with n = 1 the shift is real.
  EXPECT_GT(last, 0.0);
}

TEST(TilesExport, ObjWritesMtlAndAtlasPng) {
  const TileSet set = small_set();
  auto obj = exporter::export_tile_set(set, MeshExportFormat::kObj, "scene_tiles");
  ASSERT_TRUE(obj.ok()) << obj.status().to_string();
  ASSERT_EQ(obj->size(), 3u);
  EXPECT_EQ((*obj)[1].suffix, ".mtl");
  EXPECT_EQ((*obj)[2].suffix, "_atlas.png");
  const std::string mtl((*obj)[1].bytes.begin(), (*obj)[1].bytes.end());
  EXPECT_NE(mtl.find("map_Kd scene_tiles_atlas.png"), std::string::npos) << mtl;
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("calf_tiles_obj_" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  for (const ExportedFile& f : *obj) {
    std::ofstream(dir / ("scene_tiles" + (f.suffix.empty() ? ".obj" : f.suffix)), std::ios::binary)
        .write(reinterpret_cast<const char*>(f.bytes.data()),
               static_cast<std::streamsize>(f.bytes.size()));
  }
  Assimp::Importer importer;
  const aiScene* got = importer.ReadFile((dir / "scene_tiles.obj").string(), 0);
  ASSERT_NE(got, nullptr) << importer.GetErrorString();
  uint64_t triangles = 0;
  for (unsigned m = 0; m < got->mNumMeshes; ++m) triangles += got->mMeshes[m]->mNumFaces;
  EXPECT_EQ(triangles, 2 * set.tiles.size());
  uint32_t w = 0, h = 0;
  decode_png((*obj)[2].bytes.data(), (*obj)[2].bytes.size(), &w, &h);
  EXPECT_EQ(w, set.atlas_width);
  EXPECT_EQ(h, set.atlas_height);
  std::filesystem::remove_all(dir);
}

TEST(TilesExport, BadRequestsAreRefused) {
  const TileSet set = small_set();
  exporter::TilesExportOptions o;
  o.subdivide = 0;
  EXPECT_EQ(exporter::export_tile_set(set, MeshExportFormat::kGlb, "t", o).status().id(),
            ErrorId::kExportTilesOption);
  o.subdivide = 17;
  EXPECT_EQ(exporter::export_tile_set(set, MeshExportFormat::kGlb, "t", o).status().id(),
            ErrorId::kExportTilesOption);
  TileSet empty = set;
  empty.tiles.clear();
  EXPECT_EQ(exporter::export_tile_set(empty, MeshExportFormat::kGlb, "t").status().id(),
            ErrorId::kExportTilesEmpty);
  TileSet short_atlas = set;
  short_atlas.atlas_rgba.pop_back();
  EXPECT_EQ(exporter::export_tile_set(short_atlas, MeshExportFormat::kGlb, "t").status().id(),
            ErrorId::kExportTilesEmpty);
  EXPECT_EQ(exporter::export_tile_set(set, MeshExportFormat::kGltf, "a b").status().id(),
            ErrorId::kExportInput);
}

}  // namespace
}  // namespace calf
