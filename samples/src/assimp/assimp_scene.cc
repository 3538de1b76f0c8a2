// Scenes from files through assimp: meshes per node, node animations, simple materials.
//
// The aiScene is copied into calf's own structures (nodes, keyframes) before the importer goes
// away; transforms are then evaluated per frame by walking the node chain, so that any frame can
// be rendered alone.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <system_error>

#include <assimp/BaseImporter.h>
#include <assimp/importerdesc.h>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <assimp/Importer.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>

#include "calf/format/coordinates.h"
#include "calf/format/files.h"
#include "calf/samples/scene.h"
#include "glm_vec.h"
#include "model_prescan.h"
#include "model_textures.h"

namespace calf::samples {

namespace {

glm::mat4 to_glm(const aiMatrix4x4& a) {
  // assimp is row-major with the translation in the last column; glm is column-major.
  return glm::mat4(a.a1, a.b1, a.c1, a.d1, a.a2, a.b2, a.c2, a.d2, a.a3, a.b3, a.c3, a.d3, a.a4,
                   a.b4, a.c4, a.d4);
}

template <typename T>
struct Key {
  double time;  // seconds
  T value;
};

// One node of the copied hierarchy with its animation channel (if any).
struct Node {
  int parent = -1;
  glm::mat4 local{1.0f};
  std::vector<Key<glm::vec3>> positions, scalings;
  std::vector<Key<glm::quat>> rotations;
};

// Linear / spherical interpolation between keys, held at both ends.
template <typename T, typename Mix>
T sample(const std::vector<Key<T>>& keys, double t, Mix mix) {
  if (t <= keys.front().time) return keys.front().value;
  if (t >= keys.back().time) return keys.back().value;
  auto it = std::upper_bound(keys.begin(), keys.end(), t,
                             [](double v, const Key<T>& k) { return v < k.time; });
  const Key<T>& b = *it;
  const Key<T>& a = *(it - 1);
  float f = b.time > a.time ? static_cast<float>((t - a.time) / (b.time - a.time)) : 0.0f;
  return mix(a.value, b.value, f);
}

struct Hierarchy {
  std::vector<Node> nodes;

  glm::mat4 local_at(const Node& n, double t) const {
    if (n.positions.empty() && n.rotations.empty() && n.scalings.empty()) return n.local;
    // An animated node replaces its whole local transform by T * R * S (assimp's convention);
    // missing channels keep the rest pose's component.
    glm::vec3 pos(n.local[3]);
    glm::vec3 scl(glm::length(glm::vec3(n.local[0])), glm::length(glm::vec3(n.local[1])),
                  glm::length(glm::vec3(n.local[2])));
    glm::mat3 rot_m(glm::vec3(n.local[0]) / scl.x, glm::vec3(n.local[1]) / scl.y,
                    glm::vec3(n.local[2]) / scl.z);
    glm::quat rot = glm::quat_cast(rot_m);
    auto lerp = [](const glm::vec3& a, const glm::vec3& b, float f) { return a + (b - a) * f; };
    if (!n.positions.empty()) pos = sample(n.positions, t, lerp);
    if (!n.scalings.empty()) scl = sample(n.scalings, t, lerp);
    if (!n.rotations.empty()) {
      rot = sample(n.rotations, t, [](const glm::quat& a, const glm::quat& b, float f) {
        return glm::slerp(a, b, f);
      });
    }
    return glm::translate(glm::mat4(1), pos) * glm::mat4_cast(glm::normalize(rot)) *
           glm::scale(glm::mat4(1), scl);
  }

  glm::mat4 global_at(int index, double t) const {
    glm::mat4 m(1.0f);
    for (int i = index; i >= 0; i = nodes[static_cast<size_t>(i)].parent) {
      m = local_at(nodes[static_cast<size_t>(i)], t) * m;
    }
    return m;
  }
};

void copy_nodes(const aiNode* node, int parent, Hierarchy* h,
                std::vector<std::pair<const aiNode*, int>>* order) {
  int index = static_cast<int>(h->nodes.size());
  Node n;
  n.parent = parent;
  n.local = to_glm(node->mTransformation);
  h->nodes.push_back(n);
  order->push_back({node, index});
  for (unsigned c = 0; c < node->mNumChildren; ++c) copy_nodes(node->mChildren[c], index, h, order);
}

Material convert_material(const aiMaterial* m) {
  Material out;
  aiColor3D c;
  if (m->Get(AI_MATKEY_COLOR_DIFFUSE, c) == AI_SUCCESS) {
    out.albedo = glm::clamp(glm::vec3(c.r, c.g, c.b), 0.0f, 1.0f);
  }
  if (m->Get(AI_MATKEY_COLOR_EMISSIVE, c) == AI_SUCCESS) {
    out.emission = glm::max(glm::vec3(c.r, c.g, c.b), 0.0f);
  }
  float v = 0;
  if (m->Get(AI_MATKEY_REFLECTIVITY, v) == AI_SUCCESS && std::isfinite(v)) {
    out.reflect = std::clamp(v, 0.0f, 1.0f);
  }
  if (m->Get(AI_MATKEY_OPACITY, v) == AI_SUCCESS && std::isfinite(v) && v < 1) {
    out.refract = std::clamp(1 - v, 0.0f, 1.0f);
  }
  if (m->Get(AI_MATKEY_REFRACTI, v) == AI_SUCCESS && std::isfinite(v) && v > 0) out.ior = v;
  if (out.reflect + out.refract > 1) out.reflect = 1 - out.refract;
  if (!std::isfinite(out.albedo.x + out.albedo.y + out.albedo.z)) out.albedo = glm::vec3(0.7f);
  if (!std::isfinite(out.emission.x + out.emission.y + out.emission.z)) out.emission = glm::vec3(0);
  return out;
}

bool finite_matrix(const aiMatrix4x4& m) {
  const float* v = &m.a1;
  for (int i = 0; i < 16; ++i) {
    if (!std::isfinite(v[i])) return false;
  }
  return true;
}

std::string vertex_text(const aiVector3D& p) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "(%g, %g, %g)", static_cast<double>(p.x), static_cast<double>(p.y),
                static_cast<double>(p.z));
  return buf;
}

// Sets each mesh's primitive-type flags from its faces. The PLY importer can leave the polygon
// flag on a mesh of triangles, and assimp's triangulation then aborts on its own assertion
// (numOut != pMesh->mNumFaces); the flags are derived data, so recomputing them loses nothing.
void set_primitive_types(const aiScene* ai) {
  for (unsigned i = 0; i < ai->mNumMeshes; ++i) {
    // The scene belongs to the importer and was created mutable; the post-processing steps
    // that follow modify it the same way.
    aiMesh* mesh = const_cast<aiMesh*>(ai->mMeshes[i]);
    unsigned types = 0;
    for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
      const unsigned n = mesh->mFaces[f].mNumIndices;
      types |= n == 1   ? aiPrimitiveType_POINT
               : n == 2 ? aiPrimitiveType_LINE
               : n == 3 ? aiPrimitiveType_TRIANGLE
                        : aiPrimitiveType_POLYGON;
    }
    mesh->mPrimitiveTypes = types;
  }
}

// assimp picks the importer by extension, but when several claim it (.gltf and .glb: glTF 1 and
// glTF 2) and none recognises the content, it falls back to trying every importer it has on the
// bytes: a truncated PLY header named .glb then reached the PLY importer, past the PLY pre-scan,
// and looped forever. The content must be what the extension says: one of the importers for it
// must recognise it, or the file is refused here.
Status check_importer_for_extension(Assimp::Importer& importer, const std::string& file,
                                    const std::string& lower_ext) {
  std::vector<Assimp::BaseImporter*> claiming;
  for (size_t i = 0; i < importer.GetImporterCount(); ++i) {
    const aiImporterDesc* info = importer.GetImporterInfo(i);
    if (!info || !info->mFileExtensions) continue;
    std::string list = std::string(" ") + info->mFileExtensions + " ";
    for (char& c : list) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    // Appends, not operator+ on a temporary: GCC 12 -O3 misfires -Wrestrict on that.
    std::string word = " ";
    word.append(lower_ext, 1).append(" ");
    if (list.find(word) != std::string::npos) {
      claiming.push_back(importer.GetImporter(i));
    }
  }
  if (claiming.size() <= 1) return Status::Ok();  // assimp uses that one importer, no fallback
  for (Assimp::BaseImporter* candidate : claiming) {
    if (candidate && candidate->CanRead(file, importer.GetIOHandler(), true)) return Status::Ok();
  }
  return Status(ErrorId::kSceneLoad, file + ": its content is not a '" + lower_ext +
                                         "' file that assimp's importers for it recognise");
}

// Every vertex, node transform and animation key of the imported file, before any
// post-processing: assimp's vertex joining merges a NaN vertex into another one (NaN compares
// equal to nothing and so sorts anywhere), which would hide it from any later check.
// Face indices, node mesh references and array pointers are checked too: assimp's importers
// pass a PLY face index 0xfe000000 through unchecked, and its post-processing then reads far
// outside the vertex array.
Status check_imported(const aiScene* ai, const std::string& file) {
  if (ai->mNumMeshes > 0 && !ai->mMeshes) {
    return Status(ErrorId::kSceneLoad, file + ": the importer returned no mesh array");
  }
  for (unsigned i = 0; i < ai->mNumMeshes; ++i) {
    const aiMesh* mesh = ai->mMeshes[i];
    const std::string where = file + ": mesh " + std::to_string(i);
    if (!mesh || (mesh->mNumVertices > 0 && !mesh->mVertices) ||
        (mesh->mNumFaces > 0 && !mesh->mFaces)) {
      return Status(ErrorId::kSceneLoad, where + ": the importer returned an incomplete mesh");
    }
    for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
      const aiFace& face = mesh->mFaces[f];
      if (face.mNumIndices == 0) {
        return Status(ErrorId::kSceneLoad,
                      where + ": face " + std::to_string(f) + " has no vertex");
      }
      if (!face.mIndices) {
        return Status(ErrorId::kSceneLoad,
                      where + ": face " + std::to_string(f) + " has no indices");
      }
      for (unsigned k = 0; k < face.mNumIndices; ++k) {
        if (face.mIndices[k] >= mesh->mNumVertices) {
          return Status(ErrorId::kSceneGeometry, where + " '" + mesh->mName.C_Str() + "' face " +
                                                     std::to_string(f) + " uses vertex " +
                                                     std::to_string(face.mIndices[k]) + " of " +
                                                     std::to_string(mesh->mNumVertices));
        }
      }
    }
    for (unsigned v = 0; v < mesh->mNumVertices; ++v) {
      const aiVector3D& p = mesh->mVertices[v];
      if (!coordinates_ok({p.x, p.y, p.z})) {
        return Status(ErrorId::kSceneGeometry,
                      file + ": mesh " + std::to_string(i) + " '" + mesh->mName.C_Str() +
                          "' vertex " + std::to_string(v) + " " + vertex_text(p) +
                          " is not finite or lies beyond the coordinate bound +-1e12");
      }
    }
    if (mesh->mNumVertices > 0 && mesh->mTextureCoords[0]) {
      for (unsigned v = 0; v < mesh->mNumVertices; ++v) {
        const aiVector3D& t = mesh->mTextureCoords[0][v];
        if (!std::isfinite(t.x) || !std::isfinite(t.y)) {
          return Status(ErrorId::kSceneGeometry, file + ": mesh " + std::to_string(i) + " '" +
                                                     mesh->mName.C_Str() + "' UV of vertex " +
                                                     std::to_string(v) + " is not finite");
        }
      }
    }
  }
  std::vector<const aiNode*> stack = {ai->mRootNode};
  while (!stack.empty()) {
    const aiNode* node = stack.back();
    stack.pop_back();
    if (!finite_matrix(node->mTransformation)) {
      return Status(ErrorId::kSceneGeometry,
                    file + ": node '" + node->mName.C_Str() + "' has a non-finite transform");
    }
    for (unsigned k = 0; k < node->mNumMeshes; ++k) {
      if (node->mMeshes[k] >= ai->mNumMeshes) {
        return Status(ErrorId::kSceneLoad, file + ": node '" + node->mName.C_Str() +
                                               "' names mesh " + std::to_string(node->mMeshes[k]) +
                                               " of " + std::to_string(ai->mNumMeshes));
      }
    }
    for (unsigned c = 0; c < node->mNumChildren; ++c) {
      if (node->mChildren[c]) stack.push_back(node->mChildren[c]);
    }
  }
  for (unsigned a = 0; a < ai->mNumAnimations; ++a) {
    const aiAnimation* anim = ai->mAnimations[a];
    bool ok = std::isfinite(anim->mDuration) && std::isfinite(anim->mTicksPerSecond);
    for (unsigned c = 0; ok && c < anim->mNumChannels; ++c) {
      const aiNodeAnim* ch = anim->mChannels[c];
      auto vec_ok = [](const aiVectorKey& k) {
        return std::isfinite(k.mTime) && std::isfinite(k.mValue.x) && std::isfinite(k.mValue.y) &&
               std::isfinite(k.mValue.z);
      };
      for (unsigned k = 0; ok && k < ch->mNumPositionKeys; ++k) ok = vec_ok(ch->mPositionKeys[k]);
      for (unsigned k = 0; ok && k < ch->mNumScalingKeys; ++k) ok = vec_ok(ch->mScalingKeys[k]);
      for (unsigned k = 0; ok && k < ch->mNumRotationKeys; ++k) {
        const aiQuatKey& q = ch->mRotationKeys[k];
        ok = std::isfinite(q.mTime) && std::isfinite(q.mValue.w) && std::isfinite(q.mValue.x) &&
             std::isfinite(q.mValue.y) && std::isfinite(q.mValue.z);
      }
    }
    if (!ok) {
      return Status(ErrorId::kSceneGeometry, file + ": animation " + std::to_string(a) +
                                                 " has a non-finite key, time or duration");
    }
  }
  return Status::Ok();
}

}  // namespace

Expected<Scene> load_scene_file(const std::filesystem::path& path, uint64_t max_image_pixels) {
  const std::string file = path.string();
  // "no such file", or what the path is instead ("not a regular file (a directory)").
  CALF_RETURN_IF_ERROR(files::check_regular_file(file));
  Assimp::Importer importer;
  std::string ext = path.extension().string();
  if (ext.empty() || !importer.IsExtensionSupported(ext)) {
    return Status(ErrorId::kSceneFormat, file + ": assimp cannot import '" + ext +
                                             "' files (try glTF, GLB, OBJ, PLY or FBX)");
  }
  std::string lower_ext = ext;
  for (char& c : lower_ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  CALF_RETURN_IF_ERROR(detail::prescan_model_file(path, lower_ext));
  const aiScene* ai = nullptr;
  try {
    CALF_RETURN_IF_ERROR(check_importer_for_extension(importer, file, lower_ext));
    // Imported as it is first, checked, and only then post-processed (check_imported).
    ai = importer.ReadFile(file, 0);
    if (ai && ai->mRootNode && !(ai->mFlags & AI_SCENE_FLAGS_INCOMPLETE)) {
      CALF_RETURN_IF_ERROR(check_imported(ai, file));
      set_primitive_types(ai);
      ai = importer.ApplyPostProcessing(aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                                        aiProcess_SortByPType);
    }
  } catch (const std::exception& e) {
    return Status(ErrorId::kSceneLoad, file + ": " + e.what());
  }
  if (!ai || !ai->mRootNode || (ai->mFlags & AI_SCENE_FLAGS_INCOMPLETE)) {
    return Status(ErrorId::kSceneLoad, file + ": " + importer.GetErrorString());
  }

  auto hierarchy = std::make_shared<Hierarchy>();
  std::vector<std::pair<const aiNode*, int>> order;
  copy_nodes(ai->mRootNode, -1, hierarchy.get(), &order);

  Scene scene;
  scene.name = path.filename().string();
  scene.description = "loaded from " + file;
  for (unsigned i = 0; i < ai->mNumMaterials; ++i) {
    scene.materials.push_back(convert_material(ai->mMaterials[i]));
  }
  CALF_RETURN_IF_ERROR(
      detail::load_model_textures(*ai, path, lower_ext == ".fbx", max_image_pixels, &scene));
  if (scene.materials.empty()) scene.materials.push_back(Material{});

  // The first animation drives the nodes it names.
  double duration = 0;
  if (ai->mNumAnimations > 0) {
    const aiAnimation* anim = ai->mAnimations[0];
    double tps = anim->mTicksPerSecond > 0 ? anim->mTicksPerSecond : 25.0;
    duration = anim->mDuration / tps;
    for (unsigned c = 0; c < anim->mNumChannels; ++c) {
      const aiNodeAnim* ch = anim->mChannels[c];
      for (const auto& [node, index] : order) {
        if (node->mName != ch->mNodeName) continue;
        Node& n = hierarchy->nodes[static_cast<size_t>(index)];
        for (unsigned k = 0; k < ch->mNumPositionKeys; ++k) {
          const aiVectorKey& key = ch->mPositionKeys[k];
          n.positions.push_back({key.mTime / tps, {key.mValue.x, key.mValue.y, key.mValue.z}});
        }
        for (unsigned k = 0; k < ch->mNumScalingKeys; ++k) {
          const aiVectorKey& key = ch->mScalingKeys[k];
          n.scalings.push_back({key.mTime / tps, {key.mValue.x, key.mValue.y, key.mValue.z}});
        }
        for (unsigned k = 0; k < ch->mNumRotationKeys; ++k) {
          const aiQuatKey& key = ch->mRotationKeys[k];
          n.rotations.push_back(
              {key.mTime / tps, glm::quat(key.mValue.w, key.mValue.x, key.mValue.y, key.mValue.z)});
        }
        break;
      }
    }
  }

  for (const auto& [node, index] : order) {
    for (unsigned k = 0; k < node->mNumMeshes; ++k) {
      const aiMesh* mesh = ai->mMeshes[node->mMeshes[k]];
      if (!(mesh->mPrimitiveTypes & aiPrimitiveType_TRIANGLE)) continue;
      Object o;
      o.name = std::string(node->mName.C_Str()) + "/" + mesh->mName.C_Str();
      o.material = mesh->mMaterialIndex < scene.materials.size() ? mesh->mMaterialIndex : 0;
      for (unsigned v = 0; v < mesh->mNumVertices; ++v) {
        const aiVector3D& p = mesh->mVertices[v];
        o.mesh.positions.emplace_back(p.x, p.y, p.z);
      }
      // UV channel 0, for a textured material only. assimp gives every format's UVs with v up
      // from the image's bottom row (it flips glTF's); scenes count v down from the top row.
      if (scene.materials[o.material].base_color_texture != capture::kNoTexture &&
          mesh->mTextureCoords[0]) {
        for (unsigned v = 0; v < mesh->mNumVertices; ++v) {
          const aiVector3D& t = mesh->mTextureCoords[0][v];
          o.mesh.uvs.emplace_back(t.x, 1.0f - t.y);
        }
      }
      for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
        const aiFace& face = mesh->mFaces[f];
        if (face.mNumIndices != 3) continue;
        o.mesh.triangles.emplace_back(face.mIndices[0], face.mIndices[1], face.mIndices[2]);
      }
      if (o.mesh.triangles.empty()) continue;
      int node_index = index;
      o.transform = [hierarchy, node_index](double t) {
        return hierarchy->global_at(node_index, t);
      };
      scene.objects.push_back(std::move(o));
    }
  }
  if (scene.objects.empty()) {
    return Status(ErrorId::kSceneEmpty, file + ": no triangles in any mesh");
  }

  // Bounds at time 0 place the default rig, lights and path.
  glm::vec3 lo(INFINITY), hi(-INFINITY);
  for (const Object& o : scene.objects) {
    glm::mat4 m = o.transform(0);
    for (const glm::vec3& p : o.mesh.positions) {
      glm::vec3 w(m * glm::vec4(p, 1));
      // Per vertex, not on the bounds: min and max drop NaN.
      if (!coordinates_ok({w.x, w.y, w.z})) {
        return Status(ErrorId::kSceneGeometry,
                      file + ": object '" + o.name +
                          "' has a vertex that its transform puts beyond the coordinate bound "
                          "+-1e12 (or at a non-finite place)");
      }
      lo = glm::min(lo, w);
      hi = glm::max(hi, w);
    }
  }
  if (!std::isfinite(lo.x + lo.y + lo.z + hi.x + hi.y + hi.z)) {
    return Status(ErrorId::kSceneGeometry, file + ": vertices are not finite");
  }
  const glm::dvec3 center = glm::dvec3(lo + hi) * 0.5;
  const double radius = std::max(1e-3, 0.5 * glm::length(glm::dvec3(hi - lo)));
  scene.fps = 30;
  scene.frame_count =
      static_cast<uint32_t>(std::clamp(std::ceil(duration * scene.fps) + 1, 1.0, 300.0));
  scene.sky.sun_direction = {0.4f, 0.8f, 0.45f};
  scene.sky.sun_irradiance = glm::vec3(2.5f);
  scene.ambient = glm::vec3(0.25f);
  scene.ao_distance = static_cast<float>(0.3 * radius);
  scene.default_rig = ring_rig(8, 2.0 * radius, center + glm::dvec3(0, 0.25 * radius, 0));
  // The viewer walks around the model, not through it; placement is in units of its size.
  scene.default_rig.keep_out_center = to_vec3(center);
  scene.default_rig.keep_out_radius = radius;
  scene.length_scale = radius;
  // Midway between ring cameras (which sit at multiples of 45 degrees), inside the ring.
  scene.validation_path = [center, radius](uint32_t frames, double fps, uint32_t w, uint32_t h) {
    capture::EyePath p;
    p.width = w, p.height = h;
    for (uint32_t f = 0; f < frames; ++f) {
      double a = M_PI / 8 + M_PI / 4 * f / std::max(1u, frames);
      glm::dvec3 eye =
          center + glm::dvec3(1.6 * radius * std::cos(a), 0.3 * radius, 1.6 * radius * std::sin(a));
      p.poses.push_back(look_at_pose(f / fps, eye, center, 50));
    }
    return p;
  };
  CALF_RETURN_IF_ERROR(validate_scene(scene));
  return scene;
}

}  // namespace calf::samples
