// calf/export/tiles_export.h: a tile set exported to glTF / OBJ and read back by assimp's
// importer (and the .glb's JSON by nlohmann-json): two triangles per tile (2 n^2 with
// subdivision), one embedded PNG of the atlas's size with straight alpha, the material's alpha
// mode BLEND, single-sided and unlit, texture coordinates (U / W, V / W) at the corners, tiles
// back to front from the view region's centre, the default per-tile subdivision, OBJ's map_d.
// Expected values come from the synthetic tile set itself (tests/integration/synthetic_tiles.h),
// not from the exporter. The second, independent glTF reader (Khronos' glTF-Validator) runs in the
// CLI tests (cli.calf_export_tiles_*).
#include "calf/export/tiles_export.h"

#include <array>
#include <cmath>
#include <cstring>
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
#include <nlohmann/json.hpp>

#include "../integration/synthetic_tiles.h"
#include "glb_reading.h"

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

exporter::TilesExportOptions fixed(uint32_t n) {
  exporter::TilesExportOptions o;
  o.subdivide = n;
  return o;
}

// The JSON chunk of a .glb (its 12-byte header, then the chunk's length and type).
std::string glb_json(const std::vector<uint8_t>& glb) {
  if (glb.size() < 20) return {};
  uint32_t length = 0;
  std::memcpy(&length, glb.data() + 12, 4);
  if (glb.size() < 20 + size_t{length}) return {};
  return std::string(glb.begin() + 20, glb.begin() + 20 + length);
}

TEST(TilesExport, GlbHasTwoTrianglesPerTileAndTheAtlas) {
  const TileSet set = small_set();
  exporter::TilesExportStats stats;
  auto glb = exporter::export_tile_set(set, MeshExportFormat::kGlb, "tiles", fixed(1), &stats);
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
  const nlohmann::json json = nlohmann::json::parse(glb_json(glb->front().bytes), nullptr, false);
  ASSERT_FALSE(json.is_discarded());
  EXPECT_EQ(json["materials"][0]["alphaMode"], "BLEND");
  // Baked radiance: unlit, and that is the only extension the file declares.
  EXPECT_TRUE(json["materials"][0]["extensions"].contains("KHR_materials_unlit")) << json.dump();
  EXPECT_EQ(json["extensionsUsed"], nlohmann::json::array({"KHR_materials_unlit"}));
  EXPECT_FALSE(json.contains("extensionsRequired"));
  EXPECT_EQ(json["materials"].size(), 1u);
  EXPECT_FALSE(json["materials"][0].contains("emissiveFactor"));
  // Sampled as calf-play samples the atlas: bilinear, no mipmaps, clamped.
  const nlohmann::json& sampler = json["samplers"][json["textures"][0]["sampler"].get<int>()];
  EXPECT_EQ(sampler["magFilter"], 9729);
  EXPECT_EQ(sampler["minFilter"], 9729);
  EXPECT_EQ(sampler["wrapS"], 33071);
  EXPECT_EQ(sampler["wrapT"], 33071);
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
    exporter::TilesExportStats stats;
    auto glb = exporter::export_tile_set(set, MeshExportFormat::kGlb, "t", fixed(n), &stats);
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

// The triangles of a tile are written together, tiles farthest first from the view region's
// centre (distance to the mean of the tile's four corners, computed here from the file's own
// vertices), so an engine drawing the mesh in index order composites back to front there.
TEST(TilesExport, TilesAreWrittenBackToFrontFromTheViewRegionCentre) {
  const TileSet set = small_set();
  const Box3& r = set.view_volume;
  const aiVector3D centre((r.min.x + r.max.x) / 2, (r.min.y + r.max.y) / 2,
                          (r.min.z + r.max.z) / 2);
  const auto distance_of = [&](const std::array<aiVector3D, 4>& corners) {
    aiVector3D mean(0, 0, 0);
    for (const aiVector3D& c : corners) mean += c;
    return (mean * 0.25f - centre).Length();
  };
  // The set's own order is not already sorted, or the test would prove nothing.
  bool sorted = true;
  for (size_t t = 1; t < set.tiles.size(); ++t) {
    std::array<aiVector3D, 4> a, b;
    for (int k = 0; k < 4; ++k) {
      const auto& p = set.tiles[t - 1].corners[k].position;
      const auto& q = set.tiles[t].corners[k].position;
      a[k] = aiVector3D(p[0], p[1], p[2]);
      b[k] = aiVector3D(q[0], q[1], q[2]);
    }
    sorted = sorted && distance_of(a) >= distance_of(b);
  }
  ASSERT_FALSE(sorted);
  auto glb = exporter::export_tile_set(set, MeshExportFormat::kGlb, "t", fixed(1));
  ASSERT_TRUE(glb.ok()) << glb.status().to_string();
  Assimp::Importer importer;
  const aiScene* got =
      importer.ReadFileFromMemory(glb->front().bytes.data(), glb->front().bytes.size(), 0, "glb");
  ASSERT_NE(got, nullptr);
  const aiMesh* mesh = got->mMeshes[0];
  ASSERT_EQ(mesh->mNumFaces, 2 * set.tiles.size());
  double last = INFINITY;
  for (unsigned f = 0; f < mesh->mNumFaces; f += 2) {
    // Triangles (0, 1, 2) and (0, 2, 3) of one tile: its corners are the first's three and the
    // second's last.
    const aiFace& a = mesh->mFaces[f];
    const aiFace& b = mesh->mFaces[f + 1];
    ASSERT_EQ(a.mIndices[0], b.mIndices[0]);
    ASSERT_EQ(a.mIndices[2], b.mIndices[1]);
    const double d = distance_of({mesh->mVertices[a.mIndices[0]], mesh->mVertices[a.mIndices[1]],
                                  mesh->mVertices[a.mIndices[2]], mesh->mVertices[b.mIndices[2]]});
    EXPECT_LE(d, last + 1e-6) << "tile " << f / 2;
    last = d;
  }
}

// The default subdivision: each tile the smallest n that keeps its own error within the target,
// so the whole file is within it, with fewer triangles than one n for all would need.
TEST(TilesExport, DefaultSubdivisionKeepsEveryTileWithinTheTarget) {
  // A set with more tilt (more cells of a larger cube face) than small_set: its error at n = 1
  // is several texels.
  const TileSet set = test::make_synthetic_tile_set(3, 32, 512, 21);
  exporter::TilesExportStats one, automatic, coarse;
  ASSERT_TRUE(exporter::export_tile_set(set, MeshExportFormat::kGlb, "t", fixed(1), &one).ok());
  ASSERT_TRUE(exporter::export_tile_set(set, MeshExportFormat::kGlb, "t", {}, &automatic).ok());
  exporter::TilesExportOptions loose;
  loose.target_texel_error = 2.0;
  ASSERT_TRUE(exporter::export_tile_set(set, MeshExportFormat::kGlb, "t", loose, &coarse).ok());
  std::printf(
      "subdivide 1: %.3f texels, %llu triangles; auto: %.3f texels, %llu triangles "
      "(n %u .. %u); auto within 2: %.3f texels, %llu triangles\n",
      one.max_texel_error, static_cast<unsigned long long>(one.triangles),
      automatic.max_texel_error, static_cast<unsigned long long>(automatic.triangles),
      automatic.min_subdivide, automatic.max_subdivide, coarse.max_texel_error,
      static_cast<unsigned long long>(coarse.triangles));
  ASSERT_GT(one.max_texel_error, 2.0) << "the set must need subdivision";
  EXPECT_LE(automatic.max_texel_error, 1.0);
  EXPECT_LE(coarse.max_texel_error, 2.0);
  EXPECT_LT(coarse.triangles, automatic.triangles);
  EXPECT_EQ(automatic.min_subdivide, 1u) << "tiles facing the centre need no split";
  EXPECT_GT(automatic.max_subdivide, 1u);
  // Fewer triangles than the one n that bounds every tile.
  const uint64_t n = automatic.max_subdivide;
  EXPECT_LT(automatic.triangles, 2 * n * n * set.tiles.size());
}

TEST(TilesExport, GltfWritesItsBufferBeside) {
  const TileSet set = small_set();
  auto gltf = exporter::export_tile_set(set, MeshExportFormat::kGltf, "t2", fixed(1));
  ASSERT_TRUE(gltf.ok()) << gltf.status().to_string();
  ASSERT_EQ(gltf->size(), 2u);
  EXPECT_EQ((*gltf)[1].suffix, ".bin");
  const nlohmann::json json = nlohmann::json::parse(
      std::string((*gltf)[0].bytes.begin(), (*gltf)[0].bytes.end()), nullptr, false);
  ASSERT_FALSE(json.is_discarded());
  EXPECT_EQ(json["buffers"][0]["uri"], "t2.bin");
  EXPECT_EQ(json["buffers"][0]["byteLength"], (*gltf)[1].bytes.size());
}

TEST(TilesExport, ObjWritesMtlAndAtlasPng) {
  const TileSet set = small_set();
  auto obj = exporter::export_tile_set(set, MeshExportFormat::kObj, "scene_tiles", fixed(1));
  ASSERT_TRUE(obj.ok()) << obj.status().to_string();
  ASSERT_EQ(obj->size(), 3u);
  EXPECT_EQ((*obj)[1].suffix, ".mtl");
  EXPECT_EQ((*obj)[2].suffix, "_atlas.png");
  const std::string mtl((*obj)[1].bytes.begin(), (*obj)[1].bytes.end());
  EXPECT_NE(mtl.find("map_Kd scene_tiles_atlas.png"), std::string::npos) << mtl;
  // The atlas's alpha: the dissolve map, the material itself opaque.
  EXPECT_NE(mtl.find("map_d scene_tiles_atlas.png"), std::string::npos) << mtl;
  EXPECT_NE(mtl.find("\nd 1"), std::string::npos) << mtl;
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

// --meshopt: the same tiles (triangles in the same back-to-front order) and atlas, decoded by
// meshoptimizer, in a smaller file; OBJ refuses the option.
TEST(TilesExport, MeshoptHoldsTheSameGeometry) {
  const TileSet set = small_set();
  auto plain = exporter::export_tile_set(set, MeshExportFormat::kGlb, "t");
  exporter::TilesExportOptions o;
  o.gltf.meshopt = true;
  auto compressed = exporter::export_tile_set(set, MeshExportFormat::kGlb, "t", o);
  ASSERT_TRUE(plain.ok() && compressed.ok()) << compressed.status().to_string();
  size_t encoded = 0, decoded = 0;
  test::expect_meshopt_equals_plain(test::read_glb(plain->front().bytes),
                                    test::read_glb(compressed->front().bytes), &encoded, &decoded);
  EXPECT_LT(encoded, decoded);
  EXPECT_LT(compressed->front().bytes.size(), plain->front().bytes.size());
  auto gltf = exporter::export_tile_set(set, MeshExportFormat::kGltf, "t", o);
  ASSERT_TRUE(gltf.ok());
  ASSERT_EQ(gltf->size(), 2u);
  const nlohmann::json json = nlohmann::json::parse((*gltf)[0].bytes);
  EXPECT_EQ(json["buffers"][0]["uri"], "t.bin");
  EXPECT_EQ(json["buffers"][0]["byteLength"], (*gltf)[1].bytes.size());
  EXPECT_EQ(exporter::export_tile_set(set, MeshExportFormat::kObj, "t", o).status().id(),
            ErrorId::kExportInput);
}

// alpha_cutoff: alphaMode MASK with that cutoff (glTF's default BLEND otherwise).
TEST(TilesExport, AlphaCutoffWritesMask) {
  const TileSet set = small_set();
  exporter::TilesExportOptions o;
  o.alpha_cutoff = 0.25;
  auto glb = exporter::export_tile_set(set, MeshExportFormat::kGlb, "t", o);
  ASSERT_TRUE(glb.ok()) << glb.status().to_string();
  const nlohmann::json j = test::read_glb(glb->front().bytes).json;
  ASSERT_EQ(j["materials"].size(), 1u);
  EXPECT_EQ(j["materials"][0]["alphaMode"], "MASK");
  EXPECT_NEAR(j["materials"][0]["alphaCutoff"].get<double>(), 0.25, 1e-6);
  auto blend = exporter::export_tile_set(set, MeshExportFormat::kGlb, "t");
  ASSERT_TRUE(blend.ok());
  const nlohmann::json b = test::read_glb(blend->front().bytes).json;
  EXPECT_EQ(b["materials"][0]["alphaMode"], "BLEND");
  EXPECT_FALSE(b["materials"][0].contains("alphaCutoff"));
  for (double bad : {-0.5, 1.0, 2.0}) {
    o.alpha_cutoff = bad;
    EXPECT_EQ(exporter::export_tile_set(set, MeshExportFormat::kGlb, "t", o).status().id(),
              ErrorId::kExportTilesOption)
        << bad;
  }
}

TEST(TilesExport, BadRequestsAreRefused) {
  const TileSet set = small_set();
  exporter::TilesExportOptions o;
  o.target_texel_error = 0;
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
