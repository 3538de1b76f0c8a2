// Mesh track -> assimp scene -> assimp's glTF 2.0 / OBJ exporters (mesh_export.h).
#include "calf/export/mesh_export.h"

#include <algorithm>
#include <cstdio>
#include <map>
#include <memory>
#include <utility>

#include <assimp/light.h>
#include <assimp/material.h>
#include <assimp/mesh.h>
#include <assimp/scene.h>
#include <assimp/texture.h>

#include "assimp_files.h"
#include "calf/format/mesh_lighting.h"

namespace calf::exporter {
namespace {

Status export_error(std::string message) {
  return Status(ErrorId::kExportInput, std::move(message));
}

// One mesh to write: which source triangles (prototype triangle indices) with which material.
struct MeshPart {
  uint32_t prototype = 0;
  uint32_t material = 0;
  std::vector<uint32_t> triangles;
};

// Splits `triangles` of `prototype` by their material (the object's where the prototype has no
// per-triangle materials, or for mesh::kObjectMaterial), in material order so that the same
// track gives the same file.
std::vector<MeshPart> split_by_material(const decoder::MeshPrototype& prototype,
                                        uint32_t prototype_index, uint32_t object_material,
                                        const std::vector<uint32_t>& triangles) {
  std::map<uint32_t, std::vector<uint32_t>> by_material;
  for (uint32_t t : triangles) {
    uint32_t m = object_material;
    if (!prototype.triangle_materials.empty() &&
        prototype.triangle_materials[t] != mesh::kObjectMaterial) {
      m = prototype.triangle_materials[t];
    }
    by_material[m].push_back(t);
  }
  std::vector<MeshPart> parts;
  for (auto& [material, list] : by_material) {
    parts.push_back({prototype_index, material, std::move(list)});
  }
  return parts;
}

// An aiMesh holding `part`'s triangles with only the vertices they use (in first-use order).
std::unique_ptr<aiMesh> make_mesh(const decoder::MeshPrototype& prototype,
                                  const std::vector<float>& positions, const MeshPart& part,
                                  const std::string& name) {
  std::vector<uint32_t> remap(prototype.vertex_count(), UINT32_MAX);
  std::vector<uint32_t> used;
  for (uint32_t t : part.triangles) {
    for (int k = 0; k < 3; ++k) {
      const uint32_t v = prototype.indices[size_t{t} * 3 + k];
      if (remap[v] == UINT32_MAX) {
        remap[v] = static_cast<uint32_t>(used.size());
        used.push_back(v);
      }
    }
  }
  auto mesh = std::make_unique<aiMesh>();
  mesh->mName = aiString(name);
  mesh->mPrimitiveTypes = aiPrimitiveType_TRIANGLE;
  mesh->mMaterialIndex = part.material;
  mesh->mNumVertices = static_cast<unsigned>(used.size());
  mesh->mVertices = new aiVector3D[used.size()];
  const bool normals = !prototype.normals.empty();
  const bool colours = !prototype.colours.empty();
  const bool uvs = !prototype.uvs.empty();
  if (normals) mesh->mNormals = new aiVector3D[used.size()];
  if (colours) mesh->mColors[0] = new aiColor4D[used.size()];
  if (uvs) {
    mesh->mTextureCoords[0] = new aiVector3D[used.size()];
    mesh->mNumUVComponents[0] = 2;
  }
  for (size_t i = 0; i < used.size(); ++i) {
    const size_t v = used[i];
    mesh->mVertices[i] = aiVector3D(positions[v * 3], positions[v * 3 + 1], positions[v * 3 + 2]);
    if (normals) {
      mesh->mNormals[i] = aiVector3D(prototype.normals[v * 3], prototype.normals[v * 3 + 1],
                                     prototype.normals[v * 3 + 2]);
    }
    if (colours) {
      mesh->mColors[0][i] = aiColor4D(prototype.colours[v * 3], prototype.colours[v * 3 + 1],
                                      prototype.colours[v * 3 + 2], 1.0f);
    }
    if (uvs) {
      // assimp's UVs have v up (OpenGL's convention); its glTF exporter flips them back to
      // glTF's v down, and OBJ's vt is v up too.
      mesh->mTextureCoords[0][i] =
          aiVector3D(prototype.uvs[v * 2], 1.0f - prototype.uvs[v * 2 + 1], 0.0f);
    }
  }
  mesh->mNumFaces = static_cast<unsigned>(part.triangles.size());
  mesh->mFaces = new aiFace[part.triangles.size()];
  for (size_t f = 0; f < part.triangles.size(); ++f) {
    aiFace& face = mesh->mFaces[f];
    face.mNumIndices = 3;
    face.mIndices = new unsigned[3];
    for (int k = 0; k < 3; ++k) {
      face.mIndices[k] = remap[prototype.indices[size_t{part.triangles[f]} * 3 + k]];
    }
  }
  return mesh;
}

// `texture_path`: the file (or assimp's "*<n>" for the n-th embedded texture) of its base-colour
// texture, empty for none.
std::unique_ptr<aiMaterial> make_material(const decoder::MeshMaterial& m, uint32_t index,
                                          const std::string& texture_path) {
  auto material = std::make_unique<aiMaterial>();
  if (!texture_path.empty()) {
    // The diffuse slot: assimp's glTF 2.0 exporter writes it as baseColorTexture, its OBJ
    // exporter as map_Kd.
    const aiString path(texture_path);
    material->AddProperty(&path, AI_MATKEY_TEXTURE(aiTextureType_DIFFUSE, 0));
  }
  const aiString name("material " + std::to_string(index));
  material->AddProperty(&name, AI_MATKEY_NAME);
  const aiColor4D base(m.base_colour[0], m.base_colour[1], m.base_colour[2], 1.0f);
  const aiColor3D diffuse(m.base_colour[0], m.base_colour[1], m.base_colour[2]);
  material->AddProperty(&base, 1, AI_MATKEY_BASE_COLOR);
  material->AddProperty(&diffuse, 1, AI_MATKEY_COLOR_DIFFUSE);
  // glTF's emissiveFactor is limited to [0, 1] and assimp 5.2 writes no emissive-strength
  // extension: HDR emission is clamped per channel (docs/EXPORT.md).
  const aiColor3D emissive(std::min(m.emission[0], 1.0f), std::min(m.emission[1], 1.0f),
                           std::min(m.emission[2], 1.0f));
  material->AddProperty(&emissive, 1, AI_MATKEY_COLOR_EMISSIVE);
  // The renderers' materials are Lambertian with no specular reflection, seen from both sides
  // (the normal flipped towards the eye), as glTF's doubleSided draws them.
  const float specular = 0.0f;
  material->AddProperty(&specular, 1, AI_MATKEY_SPECULAR_FACTOR);
  const int two_sided = 1;
  material->AddProperty(&two_sided, 1, AI_MATKEY_TWOSIDED);
  return material;
}

// The lights of calf/format/mesh_lighting.h: the key light (directional, travelling along
// -kMeshKeyLight, colour (1 - kMeshAmbient) * pi: illuminance in lux for glTF) and the ambient
// term (aiLightSource_AMBIENT, colour kMeshAmbient: a uniform environment's radiance).
void add_lights(aiScene* scene) {
  scene->mNumLights = 2;
  scene->mLights = new aiLight*[2];
  auto* key = new aiLight();
  key->mName = aiString("calf key light");
  key->mType = aiLightSource_DIRECTIONAL;
  key->mDirection =
      aiVector3D(-mesh::kMeshKeyLight[0], -mesh::kMeshKeyLight[1], -mesh::kMeshKeyLight[2]);
  const float illuminance = (1.0f - mesh::kMeshAmbient) * 3.14159265f;
  key->mColorDiffuse = aiColor3D(illuminance, illuminance, illuminance);
  scene->mLights[0] = key;
  auto* ambient = new aiLight();
  ambient->mName = aiString("calf ambient light");
  ambient->mType = aiLightSource_AMBIENT;
  ambient->mColorAmbient = aiColor3D(mesh::kMeshAmbient, mesh::kMeshAmbient, mesh::kMeshAmbient);
  scene->mLights[1] = ambient;
}

aiMatrix4x4 node_matrix(const decoder::MeshTransform& m) {
  return aiMatrix4x4(m[0], m[1], m[2], m[3], m[4], m[5], m[6], m[7], m[8], m[9], m[10], m[11], 0, 0,
                     0, 1);
}

}  // namespace

Expected<MeshExportFormat> mesh_export_format_from_path(const std::string& path) {
  const size_t dot = path.find_last_of('.');
  const size_t slash = path.find_last_of('/');
  std::string ext = (dot == std::string::npos || (slash != std::string::npos && dot < slash))
                        ? ""
                        : path.substr(dot);
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (ext == ".glb") return MeshExportFormat::kGlb;
  if (ext == ".gltf") return MeshExportFormat::kGltf;
  if (ext == ".obj") return MeshExportFormat::kObj;
  return export_error("output '" + path + "': extension '" + ext +
                      "' is not one of .glb, .gltf, .obj");
}

Expected<std::vector<ExportedFile>> export_mesh_track(const decoder::MeshTrack& track,
                                                      uint32_t frame, MeshExportFormat format,
                                                      const std::string& stem,
                                                      MeshExportStats* stats,
                                                      const GltfOptions& gltf) {
  if (frame >= track.frame_count()) {
    return export_error("frame " + std::to_string(frame) + " is past the track's " +
                        std::to_string(track.frame_count()) + " frames");
  }
  // The main file names its side files by `stem`: keep it to characters that need no escaping
  // in a glTF uri or an OBJ mtllib line.
  CALF_RETURN_IF_ERROR(check_stem(stem, format));
  if (track.object_count() == 0) return export_error("the mesh track has no object");
  const double time = static_cast<double>(frame) / track.fps();
  MeshExportStats local;

  auto scene = std::make_unique<aiScene>();
  // Materials: the track's, in order (a mesh's mMaterialIndex is the track's material index).
  const auto& materials = track.materials();
  if (materials.empty()) return export_error("the mesh track has no material");
  // Textures: PNG, embedded in a glTF (assimp's "*<n>" paths, written into the binary buffer) or
  // side files <stem>_texture<n>.png beside an OBJ.
  std::vector<std::vector<uint8_t>> pngs(track.texture_count());
  std::vector<bool> needed(track.texture_count(), false);
  for (const auto& m : materials) {
    if (m.base_colour_texture < needed.size()) needed[m.base_colour_texture] = true;
  }
  std::vector<std::string> texture_paths(track.texture_count());
  std::vector<uint32_t> embedded;  // track texture of each embedded texture
  for (uint32_t t = 0; t < track.texture_count(); ++t) {
    if (!needed[t]) continue;
    mesh::TextureTexels texels;
    if (Status s = track.texture(t, &texels); !s.ok()) return s;
    CALF_ASSIGN_OR_RETURN(pngs[t], png_bytes(texels.rgba.data(), texels.width, texels.height,
                                             "texture " + std::to_string(t)));
    if (format == MeshExportFormat::kObj) {
      texture_paths[t] = stem + "_texture" + std::to_string(t) + ".png";
    } else {
      texture_paths[t] = "*" + std::to_string(embedded.size());
      embedded.push_back(t);
    }
  }
  std::vector<std::unique_ptr<aiMaterial>> ai_materials;
  for (uint32_t i = 0; i < materials.size(); ++i) {
    const uint32_t t = materials[i].base_colour_texture;
    ai_materials.push_back(
        make_material(materials[i], i, t < texture_paths.size() ? texture_paths[t] : ""));
  }

  std::map<uint32_t, uint32_t> untextured;  // track material -> its untextured copy
  std::vector<std::unique_ptr<aiMesh>> meshes;
  std::vector<std::unique_ptr<aiNode>> nodes;
  // Meshes of whole prototypes, shared by the objects that draw them whole (by prototype and
  // object material, since a glTF mesh carries its material).
  std::map<std::pair<uint32_t, uint32_t>, std::vector<unsigned>> shared;
  std::vector<decoder::MeshPrototype> prototypes(track.prototype_count());
  std::vector<bool> loaded(track.prototype_count(), false);
  std::vector<float> positions;
  for (uint32_t i = 0; i < track.object_count(); ++i) {
    decoder::MeshObject object;
    if (Status s = track.object(i, &object); !s.ok()) return s;
    if (!loaded[object.prototype]) {
      if (Status s = track.prototype(object.prototype, &prototypes[object.prototype]); !s.ok()) {
        return s;
      }
      loaded[object.prototype] = true;
    }
    const decoder::MeshPrototype& prototype = prototypes[object.prototype];
    std::vector<unsigned> mesh_indices;
    const auto key = std::make_pair(object.prototype, object.material);
    const bool whole = object.all_triangles && prototype.state_times.empty();
    if (whole && shared.count(key) != 0) {
      mesh_indices = shared[key];
    } else {
      std::vector<uint32_t> triangles = object.triangles;
      if (object.all_triangles) {
        triangles.resize(prototype.triangle_count());
        for (uint32_t t = 0; t < triangles.size(); ++t) triangles[t] = t;
      }
      decoder::positions_at(prototype, time, &positions);
      for (MeshPart& part :
           split_by_material(prototype, object.prototype, object.material, triangles)) {
        // A prototype without UVs draws a textured material untextured (the renderers' rule);
        // glTF forbids a baseColorTexture without TEXCOORD_0, so it gets an untextured copy.
        if (prototype.uvs.empty() &&
            materials[part.material].base_colour_texture < texture_paths.size()) {
          auto [at, added] = untextured.try_emplace(part.material, ai_materials.size());
          if (added) {
            ai_materials.push_back(make_material(materials[part.material], part.material, ""));
            const aiString name("material " + std::to_string(part.material) + " untextured");
            ai_materials.back()->RemoveProperty(AI_MATKEY_NAME);
            ai_materials.back()->AddProperty(&name, AI_MATKEY_NAME);
          }
          part.material = at->second;
        }
        const std::string name =
            whole ? "prototype " + std::to_string(object.prototype) + " material " +
                        std::to_string(part.material)
                  : "object " + std::to_string(i) + " material " + std::to_string(part.material);
        mesh_indices.push_back(static_cast<unsigned>(meshes.size()));
        meshes.push_back(make_mesh(prototype, positions, part, name));
        local.vertices += meshes.back()->mNumVertices;
      }
      if (whole) shared[key] = mesh_indices;
    }
    size_t drawn = 0;
    for (unsigned m : mesh_indices) drawn += meshes[m]->mNumFaces;
    local.triangles += drawn;
    if (mesh_indices.empty()) continue;  // an object whose subset is empty draws nothing
    auto node = std::make_unique<aiNode>("object " + std::to_string(i));
    node->mTransformation = node_matrix(decoder::transform_at(object, frame));
    node->mNumMeshes = static_cast<unsigned>(mesh_indices.size());
    node->mMeshes = new unsigned[mesh_indices.size()];
    std::copy(mesh_indices.begin(), mesh_indices.end(), node->mMeshes);
    nodes.push_back(std::move(node));
  }
  if (meshes.empty()) return export_error("no object of the mesh track draws a triangle");

  // Hand everything to the scene, which owns and frees it.
  scene->mNumMaterials = static_cast<unsigned>(ai_materials.size());
  scene->mMaterials = new aiMaterial*[ai_materials.size()];
  for (size_t m = 0; m < ai_materials.size(); ++m) scene->mMaterials[m] = ai_materials[m].release();
  scene->mNumMeshes = static_cast<unsigned>(meshes.size());
  scene->mMeshes = new aiMesh*[meshes.size()];
  for (size_t m = 0; m < meshes.size(); ++m) scene->mMeshes[m] = meshes[m].release();
  scene->mRootNode = new aiNode("calf mesh track");
  scene->mRootNode->mNumChildren = static_cast<unsigned>(nodes.size());
  scene->mRootNode->mChildren = new aiNode*[nodes.size()];
  for (size_t n = 0; n < nodes.size(); ++n) {
    nodes[n]->mParent = scene->mRootNode;
    scene->mRootNode->mChildren[n] = nodes[n].release();
  }
  if (!embedded.empty()) {
    scene->mNumTextures = static_cast<unsigned>(embedded.size());
    scene->mTextures = new aiTexture*[embedded.size()];
    for (size_t e = 0; e < embedded.size(); ++e) {
      const std::vector<uint8_t>& png = pngs[embedded[e]];
      auto* tex = new aiTexture();
      tex->mWidth = static_cast<unsigned>(png.size());  // mHeight 0: compressed, mWidth bytes
      tex->mHeight = 0;
      std::snprintf(tex->achFormatHint, sizeof tex->achFormatHint, "png");
      tex->pcData = reinterpret_cast<aiTexel*>(new uint8_t[png.size()]);
      std::copy(png.begin(), png.end(), reinterpret_cast<uint8_t*>(tex->pcData));
      scene->mTextures[e] = tex;
    }
  }
  add_lights(scene.get());
  local.objects = nodes.size();
  local.meshes = scene->mNumMeshes;
  local.textures =
      pngs.size() - static_cast<size_t>(std::count(needed.begin(), needed.end(), false));

  CALF_ASSIGN_OR_RETURN(std::vector<ExportedFile> files, write_scene(*scene, format, stem, gltf));
  if (format == MeshExportFormat::kObj) {
    for (uint32_t t = 0; t < pngs.size(); ++t) {
      if (needed[t]) files.push_back({"_texture" + std::to_string(t) + ".png", std::move(pngs[t])});
    }
  }
  if (stats != nullptr) *stats = local;
  return files;
}

}  // namespace calf::exporter
