// An assimp scene as glTF 2.0 through tinygltf (rules in gltf_files.h).
#define TINYGLTF_IMPLEMENTATION
#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#define TINYGLTF_NO_EXTERNAL_IMAGE
#include "gltf_files.h"

#include <algorithm>
#include <cstring>
#include <map>
#include <sstream>
#include <utility>

#include <assimp/GltfMaterial.h>
#include <assimp/material.h>
#include <tiny_gltf.h>
#include <nlohmann/json.hpp>

namespace calf::exporter {
namespace {

constexpr const char* kUnlit = "KHR_materials_unlit";

// The binary buffer and its views, each view 4-byte aligned.
class BufferBuilder {
 public:
  explicit BufferBuilder(tinygltf::Model* model) : model_(model) {}

  int add_view(const void* data, size_t bytes, int target) {
    while (bin_.size() % 4 != 0) bin_.push_back(0);
    tinygltf::BufferView view;
    view.buffer = 0;
    view.byteOffset = bin_.size();
    view.byteLength = bytes;
    view.target = target;
    const auto* p = static_cast<const uint8_t*>(data);
    bin_.insert(bin_.end(), p, p + bytes);
    model_->bufferViews.push_back(std::move(view));
    return static_cast<int>(model_->bufferViews.size() - 1);
  }

  // An accessor of `count` float vectors of `components` in their own view; min / max with
  // `bounds` (glTF requires them for POSITION).
  int add_floats(const std::vector<float>& values, int components, bool bounds) {
    const size_t count = values.size() / components;
    tinygltf::Accessor accessor;
    accessor.bufferView =
        add_view(values.data(), values.size() * sizeof(float), TINYGLTF_TARGET_ARRAY_BUFFER);
    accessor.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
    accessor.count = count;
    accessor.type = components == 2   ? TINYGLTF_TYPE_VEC2
                    : components == 3 ? TINYGLTF_TYPE_VEC3
                                      : TINYGLTF_TYPE_VEC4;
    if (bounds && count > 0) {
      accessor.minValues.assign(components, 0.0);
      accessor.maxValues.assign(components, 0.0);
      for (int c = 0; c < components; ++c) {
        float lo = values[c], hi = values[c];
        for (size_t i = 1; i < count; ++i) {
          lo = std::min(lo, values[i * components + c]);
          hi = std::max(hi, values[i * components + c]);
        }
        accessor.minValues[c] = lo;
        accessor.maxValues[c] = hi;
      }
    }
    model_->accessors.push_back(std::move(accessor));
    return static_cast<int>(model_->accessors.size() - 1);
  }

  int add_indices(const std::vector<uint32_t>& indices) {
    tinygltf::Accessor accessor;
    accessor.bufferView = add_view(indices.data(), indices.size() * sizeof(uint32_t),
                                   TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
    accessor.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
    accessor.count = indices.size();
    accessor.type = TINYGLTF_TYPE_SCALAR;
    model_->accessors.push_back(std::move(accessor));
    return static_cast<int>(model_->accessors.size() - 1);
  }

  std::vector<uint8_t>& bytes() { return bin_; }

 private:
  tinygltf::Model* model_;
  std::vector<uint8_t> bin_;
};

tinygltf::Primitive make_primitive(const aiMesh& mesh, int material, BufferBuilder* buffer) {
  tinygltf::Primitive primitive;
  primitive.mode = TINYGLTF_MODE_TRIANGLES;
  primitive.material = material;
  const unsigned n = mesh.mNumVertices;
  std::vector<float> values;
  values.reserve(size_t{n} * 3);
  for (unsigned i = 0; i < n; ++i) {
    values.insert(values.end(), {mesh.mVertices[i].x, mesh.mVertices[i].y, mesh.mVertices[i].z});
  }
  primitive.attributes["POSITION"] = buffer->add_floats(values, 3, true);
  if (mesh.mNormals != nullptr) {
    values.clear();
    for (unsigned i = 0; i < n; ++i) {
      values.insert(values.end(), {mesh.mNormals[i].x, mesh.mNormals[i].y, mesh.mNormals[i].z});
    }
    primitive.attributes["NORMAL"] = buffer->add_floats(values, 3, false);
  }
  if (mesh.mColors[0] != nullptr) {
    values.clear();
    for (unsigned i = 0; i < n; ++i) {
      values.insert(values.end(),
                    {mesh.mColors[0][i].r, mesh.mColors[0][i].g, mesh.mColors[0][i].b});
    }
    primitive.attributes["COLOR_0"] = buffer->add_floats(values, 3, false);
  }
  if (mesh.mTextureCoords[0] != nullptr) {
    values.clear();
    for (unsigned i = 0; i < n; ++i) {
      // assimp's v runs up, glTF's down.
      values.insert(values.end(),
                    {mesh.mTextureCoords[0][i].x, 1.0f - mesh.mTextureCoords[0][i].y});
    }
    primitive.attributes["TEXCOORD_0"] = buffer->add_floats(values, 2, false);
  }
  std::vector<uint32_t> indices;
  indices.reserve(size_t{mesh.mNumFaces} * 3);
  for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
    for (unsigned k = 0; k < mesh.mFaces[f].mNumIndices; ++k) {
      indices.push_back(mesh.mFaces[f].mIndices[k]);
    }
  }
  primitive.indices = buffer->add_indices(indices);
  return primitive;
}

// The glTF material of `source`; `texture_of` maps an embedded texture's index and sampler to
// the glTF texture written for them (added on first use).
Expected<tinygltf::Material> make_material(const aiScene& scene, const aiMaterial& source,
                                           tinygltf::Model* model, BufferBuilder* buffer,
                                           std::map<std::pair<unsigned, int>, int>* texture_of) {
  tinygltf::Material material;
  aiString name;
  if (source.Get(AI_MATKEY_NAME, name) == AI_SUCCESS) material.name = name.C_Str();
  aiColor4D base(1, 1, 1, 1);
  if (source.Get(AI_MATKEY_BASE_COLOR, base) == AI_SUCCESS) {
    material.pbrMetallicRoughness.baseColorFactor = {base.r, base.g, base.b, base.a};
  }
  material.pbrMetallicRoughness.metallicFactor = 0.0;
  aiColor3D emissive(0, 0, 0);
  if (source.Get(AI_MATKEY_COLOR_EMISSIVE, emissive) == AI_SUCCESS &&
      (emissive.r > 0 || emissive.g > 0 || emissive.b > 0)) {
    material.emissiveFactor = {emissive.r, emissive.g, emissive.b};
  }
  aiString alpha;
  if (source.Get(AI_MATKEY_GLTF_ALPHAMODE, alpha) == AI_SUCCESS) material.alphaMode = alpha.C_Str();
  float cutoff = 0.5f;
  if (source.Get(AI_MATKEY_GLTF_ALPHACUTOFF, cutoff) == AI_SUCCESS) material.alphaCutoff = cutoff;
  int two_sided = 0;
  if (source.Get(AI_MATKEY_TWOSIDED, two_sided) == AI_SUCCESS)
    material.doubleSided = two_sided != 0;
  int shading = 0;
  if (source.Get(AI_MATKEY_SHADING_MODEL, shading) == AI_SUCCESS &&
      shading == aiShadingMode_Unlit) {
    material.extensions[kUnlit] = tinygltf::Value(tinygltf::Value::Object());
  }
  aiString path;
  if (source.Get(AI_MATKEY_TEXTURE(aiTextureType_DIFFUSE, 0), path) == AI_SUCCESS) {
    const std::string p = path.C_Str();
    unsigned index = 0;
    if (p.size() < 2 || p[0] != '*' ||
        (index = static_cast<unsigned>(std::stoul(p.substr(1)))) >= scene.mNumTextures) {
      return Status(ErrorId::kExportWrite,
                    "material '" + material.name + "': texture '" + p + "' is not embedded");
    }
    // The sampler: glTF's defaults (repeat, the engine's filtering) unless the material sets
    // the wrap modes or filters.
    tinygltf::Sampler sampler;
    int mode = aiTextureMapMode_Wrap;
    if (source.Get(AI_MATKEY_MAPPINGMODE_U(aiTextureType_DIFFUSE, 0), mode) == AI_SUCCESS &&
        mode == aiTextureMapMode_Clamp) {
      sampler.wrapS = TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE;
    }
    mode = aiTextureMapMode_Wrap;
    if (source.Get(AI_MATKEY_MAPPINGMODE_V(aiTextureType_DIFFUSE, 0), mode) == AI_SUCCESS &&
        mode == aiTextureMapMode_Clamp) {
      sampler.wrapT = TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE;
    }
    int filter = 0;
    if (source.Get(AI_MATKEY_GLTF_MAPPINGFILTER_MAG(aiTextureType_DIFFUSE, 0), filter) ==
        AI_SUCCESS)
      sampler.magFilter = filter;
    if (source.Get(AI_MATKEY_GLTF_MAPPINGFILTER_MIN(aiTextureType_DIFFUSE, 0), filter) ==
        AI_SUCCESS)
      sampler.minFilter = filter;
    int sampler_index = -1;
    for (size_t i = 0; i < model->samplers.size(); ++i) {
      const tinygltf::Sampler& s = model->samplers[i];
      if (s.wrapS == sampler.wrapS && s.wrapT == sampler.wrapT &&
          s.magFilter == sampler.magFilter && s.minFilter == sampler.minFilter) {
        sampler_index = static_cast<int>(i);
      }
    }
    if (sampler_index < 0) {
      model->samplers.push_back(sampler);
      sampler_index = static_cast<int>(model->samplers.size() - 1);
    }
    const auto key = std::make_pair(index, sampler_index);
    auto [at, added] = texture_of->try_emplace(key, static_cast<int>(model->textures.size()));
    if (added) {
      int source_image = -1;
      for (const auto& [k, t] : *texture_of) {
        if (k.first == index && t != at->second) source_image = model->textures[t].source;
      }
      if (source_image < 0) {
        const aiTexture& t = *scene.mTextures[index];
        tinygltf::Image image;
        image.mimeType = "image/png";
        image.bufferView = buffer->add_view(t.pcData, t.mWidth, 0);
        model->images.push_back(std::move(image));
        source_image = static_cast<int>(model->images.size() - 1);
      }
      tinygltf::Texture texture;
      texture.source = source_image;
      texture.sampler = sampler_index;
      model->textures.push_back(std::move(texture));
    }
    material.pbrMetallicRoughness.baseColorTexture.index = at->second;
  }
  return material;
}

}  // namespace

Expected<std::vector<ExportedFile>> write_gltf(const aiScene& scene, MeshExportFormat format,
                                               const std::string& stem) {
  tinygltf::Model model;
  model.asset.version = "2.0";
  model.asset.generator = "calf-export";
  BufferBuilder buffer(&model);
  std::map<unsigned, int> material_of;                 // assimp material -> glTF material
  std::map<std::pair<unsigned, int>, int> texture_of;  // (embedded texture, sampler) -> texture
  std::map<std::vector<unsigned>, int> mesh_of;
  const auto add_node = [&](const aiNode& source) -> Expected<int> {
    tinygltf::Node node;
    node.name = source.mName.C_Str();
    if (!source.mTransformation.IsIdentity()) {
      const aiMatrix4x4& m = source.mTransformation;
      node.matrix = {m.a1, m.b1, m.c1, m.d1, m.a2, m.b2, m.c2, m.d2,
                     m.a3, m.b3, m.c3, m.d3, m.a4, m.b4, m.c4, m.d4};  // column-major
    }
    if (source.mNumMeshes > 0) {
      const std::vector<unsigned> meshes(source.mMeshes, source.mMeshes + source.mNumMeshes);
      auto [at, added] = mesh_of.try_emplace(meshes, static_cast<int>(model.meshes.size()));
      if (added) {
        tinygltf::Mesh mesh;
        if (meshes.size() == 1) mesh.name = scene.mMeshes[meshes[0]]->mName.C_Str();
        for (unsigned m : meshes) {
          const aiMesh& source_mesh = *scene.mMeshes[m];
          const unsigned mi = source_mesh.mMaterialIndex;
          auto [mat, new_material] =
              material_of.try_emplace(mi, static_cast<int>(model.materials.size()));
          if (new_material) {
            CALF_ASSIGN_OR_RETURN(
                tinygltf::Material material,
                make_material(scene, *scene.mMaterials[mi], &model, &buffer, &texture_of));
            model.materials.push_back(std::move(material));
          }
          mesh.primitives.push_back(make_primitive(source_mesh, mat->second, &buffer));
        }
        model.meshes.push_back(std::move(mesh));
      }
      node.mesh = at->second;
    }
    model.nodes.push_back(std::move(node));
    return static_cast<int>(model.nodes.size() - 1);
  };
  CALF_ASSIGN_OR_RETURN(const int root, add_node(*scene.mRootNode));
  for (unsigned c = 0; c < scene.mRootNode->mNumChildren; ++c) {
    CALF_ASSIGN_OR_RETURN(const int child, add_node(*scene.mRootNode->mChildren[c]));
    model.nodes[root].children.push_back(child);
  }
  tinygltf::Scene gltf_scene;
  gltf_scene.nodes = {root};
  model.scenes.push_back(std::move(gltf_scene));
  model.defaultScene = 0;
  for (const tinygltf::Material& m : model.materials) {
    if (m.extensions.count(kUnlit) != 0) {
      model.extensionsUsed = {kUnlit};
      break;
    }
  }
  while (buffer.bytes().size() % 4 != 0) buffer.bytes().push_back(0);
  const size_t bin_size = buffer.bytes().size();
  tinygltf::Buffer bin;
  if (format == MeshExportFormat::kGlb) bin.data = std::move(buffer.bytes());
  model.buffers.push_back(std::move(bin));

  tinygltf::TinyGLTF writer;
  std::ostringstream out;
  if (!writer.WriteGltfSceneToStream(&model, out, false, format == MeshExportFormat::kGlb)) {
    return Status(ErrorId::kExportWrite, "tinygltf could not write the glTF");
  }
  const std::string text = out.str();
  std::vector<ExportedFile> files;
  if (format == MeshExportFormat::kGlb) {
    files.push_back({"", std::vector<uint8_t>(text.begin(), text.end())});
    return files;
  }
  // tinygltf's stream writer embeds a .gltf's buffers as data URIs; calf writes the buffer
  // beside it, so the (empty) buffer's entry is replaced by the side file's.
  nlohmann::json doc = nlohmann::json::parse(text, nullptr, false);
  if (doc.is_discarded() || !doc.contains("buffers")) {
    return Status(ErrorId::kExportWrite, "tinygltf wrote a .gltf calf cannot read back");
  }
  doc["buffers"][0] = {{"byteLength", bin_size}, {"uri", stem + ".bin"}};
  const std::string patched = doc.dump(2) + "\n";
  files.push_back({"", std::vector<uint8_t>(patched.begin(), patched.end())});
  files.push_back({".bin", std::move(buffer.bytes())});
  return files;
}

}  // namespace calf::exporter
