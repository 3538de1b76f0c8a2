// Tile set -> assimp scene -> assimp's glTF 2.0 / OBJ exporters (tiles_export.h).
#include "calf/export/tiles_export.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <utility>

#include <assimp/GltfMaterial.h>
#include <assimp/material.h>
#include <assimp/mesh.h>
#include <assimp/scene.h>

#include "assimp_files.h"

namespace calf::exporter {
namespace {

constexpr uint32_t kMaxSubdivide = 16;

// A point of a tile's triangle: position and projective texture coordinate, in binary64.
struct Point {
  std::array<double, 3> p, uvw;
};

Point corner(const TileCorner& c) {
  return {{c.position[0], c.position[1], c.position[2]}, {c.uvw[0], c.uvw[1], c.uvw[2]}};
}

// P + (Q - P) a + (R - P) b, for positions and (U, V, W) alike: perspective-correct
// interpolation is linear in the triangle's plane, so this is the exact (U, V, W) at that point.
Point lerp(const Point& P, const Point& Q, const Point& R, double a, double b) {
  Point x;
  for (int c = 0; c < 3; ++c) {
    x.p[c] = P.p[c] + (Q.p[c] - P.p[c]) * a + (R.p[c] - P.p[c]) * b;
    x.uvw[c] = P.uvw[c] + (Q.uvw[c] - P.uvw[c]) * a + (R.uvw[c] - P.uvw[c]) * b;
  }
  return x;
}

// The atlas with straight (unassociated) alpha, as glTF and PNG expect. A texel of alpha 0 gets
// the alpha-weighted mean colour of its 8 neighbours (0 where none is covered): engines filter
// the straight colours bilinearly, and a black transparent texel would darken the edge texels
// next to it, which the tiles representation, filtering premultiplied colour, does not.
std::vector<uint8_t> unpremultiply(const std::vector<uint8_t>& rgba, uint32_t width,
                                   uint32_t height) {
  std::vector<uint8_t> out(rgba.size());
  for (size_t i = 0; i < rgba.size(); i += 4) {
    const unsigned a = rgba[i + 3];
    for (int c = 0; c < 3; ++c) {
      out[i + c] =
          a == 0 ? 0 : static_cast<uint8_t>(std::min(255u, (rgba[i + c] * 255u + a / 2) / a));
    }
    out[i + 3] = static_cast<uint8_t>(a);
  }
  for (uint32_t y = 0; y < height; ++y) {
    for (uint32_t x = 0; x < width; ++x) {
      const size_t i = (size_t{y} * width + x) * 4;
      if (rgba[i + 3] != 0) continue;
      uint64_t sum[3] = {0, 0, 0}, weight = 0;
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const int64_t nx = int64_t{x} + dx, ny = int64_t{y} + dy;
          if (nx < 0 || ny < 0 || nx >= width || ny >= height) continue;
          const size_t j = (static_cast<size_t>(ny) * width + static_cast<size_t>(nx)) * 4;
          const unsigned a = rgba[j + 3];
          if (a == 0) continue;
          for (int c = 0; c < 3; ++c) sum[c] += uint64_t{out[j + c]} * a;
          weight += a;
        }
      }
      for (int c = 0; c < 3 && weight > 0; ++c) {
        out[i + c] = static_cast<uint8_t>((sum[c] + weight / 2) / weight);
      }
    }
  }
  return out;
}

// The largest affine texture error, in atlas texels, at the centroids of the n x n sub-triangles
// of the triangle (P, Q, R): the affine mean of their vertices' (U / W, V / W) against the
// projective (U, V, W) there.
double triangle_error(const Point& P, const Point& Q, const Point& R, uint32_t n, double aw,
                      double ah) {
  double worst = 0;
  const auto at = [&](uint32_t i, uint32_t j) {
    return lerp(P, Q, R, double(i) / n, double(j) / n);
  };
  const auto centroid_error = [&](const Point& a, const Point& b, const Point& d) {
    double affine[2] = {0, 0}, sum[3] = {0, 0, 0};
    for (const Point* p : {&a, &b, &d}) {
      affine[0] += p->uvw[0] / p->uvw[2] / 3;
      affine[1] += p->uvw[1] / p->uvw[2] / 3;
      for (int k = 0; k < 3; ++k) sum[k] += p->uvw[k];
    }
    const double du = (affine[0] - sum[0] / sum[2]) * aw;
    const double dv = (affine[1] - sum[1] / sum[2]) * ah;
    worst = std::max(worst, std::sqrt(du * du + dv * dv));
  };
  for (uint32_t i = 0; i < n; ++i) {
    for (uint32_t j = 0; i + j < n; ++j) {
      centroid_error(at(i, j), at(i + 1, j), at(i, j + 1));
      if (i + j + 2 <= n) centroid_error(at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
    }
  }
  return worst;
}

// The tile's error with each of its triangles split n x n.
double tile_error(const Point (&c)[4], uint32_t n, double aw, double ah) {
  return std::max(triangle_error(c[0], c[1], c[2], n, aw, ah),
                  triangle_error(c[0], c[2], c[3], n, aw, ah));
}

// The tiles' order, farthest first from `centre` (distance to the mean of a tile's corners; the
// index breaks ties): the static back-to-front order of paper 000, drawn from the view region's
// centre.
std::vector<uint32_t> back_to_front(const TileSet& set, const std::array<double, 3>& centre) {
  const size_t n = set.tiles.size();
  std::vector<double> distance(n);
  for (size_t t = 0; t < n; ++t) {
    double d2 = 0;
    for (int k = 0; k < 3; ++k) {
      double mean = 0;
      for (const TileCorner& c : set.tiles[t].corners) mean += c.position[k];
      d2 += (mean / 4 - centre[k]) * (mean / 4 - centre[k]);
    }
    distance[t] = d2;
  }
  std::vector<uint32_t> order(n);
  for (size_t t = 0; t < n; ++t) order[t] = static_cast<uint32_t>(t);
  std::sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) {
    return distance[a] != distance[b] ? distance[a] > distance[b] : a < b;
  });
  return order;
}

}  // namespace

Expected<std::vector<ExportedFile>> export_tile_set(const TileSet& set, MeshExportFormat format,
                                                    const std::string& stem,
                                                    const TilesExportOptions& options,
                                                    TilesExportStats* stats) {
  const uint32_t fixed = options.subdivide;
  if (fixed > kMaxSubdivide)
    return Status(ErrorId::kExportTilesOption, "subdivide " + std::to_string(fixed) +
                                                   " is not auto (0) or 1 .. " +
                                                   std::to_string(kMaxSubdivide));
  if (fixed == 0 && !(options.target_texel_error > 0))
    return Status(
        ErrorId::kExportTilesOption,
        "target texel error " + std::to_string(options.target_texel_error) + " is not > 0");
  if (!(options.alpha_cutoff >= 0 && options.alpha_cutoff < 1))
    return Status(
        ErrorId::kExportTilesOption,
        "alpha cutoff " + std::to_string(options.alpha_cutoff) + " is not 0 (BLEND) or in (0, 1)");
  if (set.tiles.empty()) return Status(ErrorId::kExportTilesEmpty, "the tile set has no tile");
  const size_t texels = size_t{set.atlas_width} * set.atlas_height;
  if (texels == 0 || set.atlas_rgba.size() != 4 * texels)
    return Status(ErrorId::kExportTilesEmpty, "the tile set's atlas is " +
                                                  std::to_string(set.atlas_width) + " x " +
                                                  std::to_string(set.atlas_height) + " with " +
                                                  std::to_string(set.atlas_rgba.size()) + " bytes");
  CALF_RETURN_IF_ERROR(check_stem(stem, format));
  const double aw = set.atlas_width, ah = set.atlas_height;

  // Each tile's subdivision: the fixed one, or the smallest whose error is within the target.
  std::vector<uint32_t> split(set.tiles.size(), fixed);
  uint64_t triangles = 0;
  for (size_t t = 0; t < set.tiles.size(); ++t) {
    const Tile& tile = set.tiles[t];
    const Point c[4] = {corner(tile.corners[0]), corner(tile.corners[1]), corner(tile.corners[2]),
                        corner(tile.corners[3])};
    if (fixed == 0) {
      uint32_t n = 1;
      while (n < kMaxSubdivide && tile_error(c, n, aw, ah) > options.target_texel_error) ++n;
      split[t] = n;
    }
    triangles += uint64_t{2} * split[t] * split[t];
  }
  if (triangles > (uint64_t{1} << 31))
    return Status(ErrorId::kExportTilesOption, "subdivision of " +
                                                   std::to_string(set.tiles.size()) +
                                                   " tiles gives more than 2^31 triangles");

  auto scene = std::make_unique<aiScene>();
  const std::vector<uint8_t> straight =
      unpremultiply(set.atlas_rgba, set.atlas_width, set.atlas_height);
  CALF_ASSIGN_OR_RETURN(std::vector<uint8_t> png,
                        png_bytes(straight.data(), set.atlas_width, set.atlas_height, "atlas"));
  const std::string texture =
      format == MeshExportFormat::kObj ? stem + "_atlas.png" : embed_png(scene.get(), png);

  auto material = std::make_unique<aiMaterial>();
  const aiString path(texture);
  material->AddProperty(&path, AI_MATKEY_TEXTURE(aiTextureType_DIFFUSE, 0));
  // OBJ: the atlas's alpha as the dissolve map (map_d), which importers read as the alpha.
  if (format == MeshExportFormat::kObj)
    material->AddProperty(&path, AI_MATKEY_TEXTURE(aiTextureType_OPACITY, 0));
  // Sampled as the tiles representation samples it: bilinear, one level, clamped to the atlas's
  // edge (calf/player/tiles_renderer.h); engines otherwise build mipmaps and blur the tiles.
  const int clamp = aiTextureMapMode_Clamp, linear = 9729;  // glTF's LINEAR
  material->AddProperty(&clamp, 1, AI_MATKEY_MAPPINGMODE_U(aiTextureType_DIFFUSE, 0));
  material->AddProperty(&clamp, 1, AI_MATKEY_MAPPINGMODE_V(aiTextureType_DIFFUSE, 0));
  material->AddProperty(&linear, 1, AI_MATKEY_GLTF_MAPPINGFILTER_MAG(aiTextureType_DIFFUSE, 0));
  material->AddProperty(&linear, 1, AI_MATKEY_GLTF_MAPPINGFILTER_MIN(aiTextureType_DIFFUSE, 0));
  const aiString name("tiles atlas");
  material->AddProperty(&name, AI_MATKEY_NAME);
  const aiColor4D white(1, 1, 1, 1);
  const aiColor3D white3(1, 1, 1);
  material->AddProperty(&white, 1, AI_MATKEY_BASE_COLOR);
  material->AddProperty(&white3, 1, AI_MATKEY_COLOR_DIFFUSE);
  const float opaque = 1.0f;
  material->AddProperty(&opaque, 1, AI_MATKEY_OPACITY);
  const aiString blend(options.alpha_cutoff > 0 ? "MASK" : "BLEND");
  material->AddProperty(&blend, AI_MATKEY_GLTF_ALPHAMODE);
  if (options.alpha_cutoff > 0) {
    const float cutoff = static_cast<float>(options.alpha_cutoff);
    material->AddProperty(&cutoff, 1, AI_MATKEY_GLTF_ALPHACUTOFF);
  }
  const int two_sided = 0;
  material->AddProperty(&two_sided, 1, AI_MATKEY_TWOSIDED);
  // Baked radiance: glTF's KHR_materials_unlit (gltf_files.h).
  const int unlit = aiShadingMode_Unlit;
  material->AddProperty(&unlit, 1, AI_MATKEY_SHADING_MODEL);

  // Vertices of one triangle's grid: (i, j) with i + j <= n at barycentric (i / n, j / n) of
  // (Q, R); a tile's second triangle (c0, c2, c3) shares the first's (c0, c1, c2) edge c0-c2.
  // Tiles are written back to front from the view region's centre, so an engine drawing the
  // mesh's triangles in index order composites them as the tiles representation does there.
  std::vector<aiVector3D> positions, uvs;
  std::vector<std::array<unsigned, 3>> faces;
  double worst = 0;
  const Box3& region = set.view_volume;
  const std::array<double, 3> centre = {(double(region.min.x) + region.max.x) / 2,
                                        (double(region.min.y) + region.max.y) / 2,
                                        (double(region.min.z) + region.max.z) / 2};
  TilesExportStats local;
  local.min_subdivide = kMaxSubdivide;
  for (const uint32_t t : back_to_front(set, centre)) {
    const Tile& tile = set.tiles[t];
    const uint32_t n = split[t];
    local.min_subdivide = std::min(local.min_subdivide, n);
    local.max_subdivide = std::max(local.max_subdivide, n);
    const Point c[4] = {corner(tile.corners[0]), corner(tile.corners[1]), corner(tile.corners[2]),
                        corner(tile.corners[3])};
    worst = std::max(worst, tile_error(c, n, aw, ah));
    std::vector<unsigned> grid(size_t{n + 1} * (n + 1));
    std::vector<unsigned> edge(n + 1);  // c0-c2 edge vertices of the first triangle, by step
    for (int half = 0; half < 2; ++half) {
      const Point& P = c[0];
      const Point& Q = half == 0 ? c[1] : c[2];
      const Point& R = half == 0 ? c[2] : c[3];
      for (uint32_t i = 0; i <= n; ++i) {
        for (uint32_t j = 0; i + j <= n; ++j) {
          const size_t at = size_t{i} * (n + 1) + j;
          // The shared edge c0-c2: j = k of the first triangle is i = k of the second.
          if (half == 1 && j == 0) {
            grid[at] = edge[i];
            continue;
          }
          const Point x = lerp(P, Q, R, double(i) / n, double(j) / n);
          grid[at] = static_cast<unsigned>(positions.size());
          if (half == 0 && i == 0) edge[j] = grid[at];
          positions.emplace_back(static_cast<float>(x.p[0]), static_cast<float>(x.p[1]),
                                 static_cast<float>(x.p[2]));
          // assimp's UVs have v up; the glTF writer flips them back to glTF's v down, and
          // OBJ's vt is v up too.
          uvs.emplace_back(static_cast<float>(x.uvw[0] / x.uvw[2]),
                           static_cast<float>(1.0 - x.uvw[1] / x.uvw[2]), 0.0f);
        }
      }
      const auto add = [&](uint32_t i0, uint32_t j0, uint32_t i1, uint32_t j1, uint32_t i2,
                           uint32_t j2) {
        faces.push_back({grid[size_t{i0} * (n + 1) + j0], grid[size_t{i1} * (n + 1) + j1],
                         grid[size_t{i2} * (n + 1) + j2]});
      };
      for (uint32_t i = 0; i < n; ++i) {
        for (uint32_t j = 0; i + j < n; ++j) {
          add(i, j, i + 1, j, i, j + 1);
          if (i + j + 2 <= n) add(i + 1, j, i + 1, j + 1, i, j + 1);
        }
      }
    }
  }

  auto mesh = std::make_unique<aiMesh>();
  mesh->mName = aiString("tiles");
  mesh->mPrimitiveTypes = aiPrimitiveType_TRIANGLE;
  mesh->mMaterialIndex = 0;
  mesh->mNumVertices = static_cast<unsigned>(positions.size());
  mesh->mVertices = new aiVector3D[positions.size()];
  std::copy(positions.begin(), positions.end(), mesh->mVertices);
  mesh->mTextureCoords[0] = new aiVector3D[uvs.size()];
  std::copy(uvs.begin(), uvs.end(), mesh->mTextureCoords[0]);
  mesh->mNumUVComponents[0] = 2;
  mesh->mNumFaces = static_cast<unsigned>(faces.size());
  mesh->mFaces = new aiFace[faces.size()];
  for (size_t f = 0; f < faces.size(); ++f) {
    mesh->mFaces[f].mNumIndices = 3;
    mesh->mFaces[f].mIndices = new unsigned[3]{faces[f][0], faces[f][1], faces[f][2]};
  }

  local.tiles = set.tiles.size();
  local.triangles = faces.size();
  local.vertices = positions.size();
  local.atlas_width = set.atlas_width;
  local.atlas_height = set.atlas_height;
  local.max_texel_error = worst;

  // Hand everything to the scene, which owns and frees it.
  scene->mNumMaterials = 1;
  scene->mMaterials = new aiMaterial* [1] { material.release() };
  scene->mNumMeshes = 1;
  scene->mMeshes = new aiMesh* [1] { mesh.release() };
  scene->mRootNode = new aiNode("calf tiles");
  scene->mRootNode->mNumMeshes = 1;
  scene->mRootNode->mMeshes = new unsigned[1]{0};

  CALF_ASSIGN_OR_RETURN(std::vector<ExportedFile> files,
                        write_scene(*scene, format, stem, options.gltf));
  if (format == MeshExportFormat::kObj) files.push_back({"_atlas.png", std::move(png)});
  if (stats != nullptr) *stats = local;
  return files;
}

}  // namespace calf::exporter
