// An assimp scene as glTF 2.0 through tinygltf (rules in gltf_files.h).
#define TINYGLTF_IMPLEMENTATION
#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#define TINYGLTF_NO_EXTERNAL_IMAGE
#include "gltf_files.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <sstream>
#include <utility>

#include <assimp/GltfMaterial.h>
#include <assimp/light.h>
#include <assimp/material.h>
#include <meshoptimizer.h>
#include <tiny_gltf.h>
#include <nlohmann/json.hpp>

namespace calf::exporter {
namespace {

constexpr const char* kUnlit = "KHR_materials_unlit";
constexpr const char* kSpecular = "KHR_materials_specular";
constexpr const char* kMeshopt = "EXT_meshopt_compression";

// How a view's bytes are compressed with EXT_meshopt_compression: mode "ATTRIBUTES" (vertex
// data: count elements of stride bytes) or "TRIANGLES" (a triangle list of 32-bit indices);
// empty mode: kept as it is (images).
struct ViewCodec {
  std::string mode;
  size_t stride = 0;
  size_t count = 0;
};

// The binary buffer and its views, each view 4-byte aligned.
class BufferBuilder {
 public:
  explicit BufferBuilder(tinygltf::Model* model) : model_(model) {}

  int add_view(const void* data, size_t bytes, int target, ViewCodec codec = {}) {
    codecs_.push_back(std::move(codec));
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
        add_view(values.data(), values.size() * sizeof(float), TINYGLTF_TARGET_ARRAY_BUFFER,
                 {"ATTRIBUTES", components * sizeof(float), count});
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
                                   TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER,
                                   {"TRIANGLES", sizeof(uint32_t), indices.size()});
    accessor.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
    accessor.count = indices.size();
    accessor.type = TINYGLTF_TYPE_SCALAR;
    model_->accessors.push_back(std::move(accessor));
    return static_cast<int>(model_->accessors.size() - 1);
  }

  std::vector<uint8_t>& bytes() { return bin_; }
  const std::vector<ViewCodec>& codecs() const { return codecs_; }

 private:
  tinygltf::Model* model_;
  std::vector<uint8_t> bin_;
  std::vector<ViewCodec> codecs_;  // per view
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
  float specular = 1.0f;
  if (source.Get(AI_MATKEY_SPECULAR_FACTOR, specular) == AI_SUCCESS && specular != 1.0f) {
    tinygltf::Value::Object factor;
    factor["specularFactor"] = tinygltf::Value(static_cast<double>(specular));
    material.extensions[kSpecular] = tinygltf::Value(std::move(factor));
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

// The node of a directional light travelling along `direction` (glTF's lights shine along the
// node's -Z): the rotation taking -Z onto the unit direction.
tinygltf::Node light_node(const aiLight& light, int index) {
  tinygltf::Node node;
  node.name = light.mName.C_Str();
  aiVector3D d = light.mDirection;
  d.Normalize();
  // q = (a x b, 1 + a . b) normalised, a = (0, 0, -1), b = d; half a turn about y when b = -a.
  const double w = 1.0 - d.z;
  if (w < 1e-9) {
    node.rotation = {0.0, 1.0, 0.0, 0.0};
  } else {
    const double x = d.y, y = -d.x, norm = std::sqrt(x * x + y * y + w * w);
    node.rotation = {x / norm, y / norm, 0.0, w / norm};
  }
  tinygltf::Value::Object reference;
  reference["light"] = tinygltf::Value(index);
  node.extensions["KHR_lights_punctual"] = tinygltf::Value(std::move(reference));
  return node;
}

// The GLB container (glTF 2.0 §4.4): header, the JSON chunk padded with spaces, the BIN chunk
// padded with zeros.
std::vector<uint8_t> glb_bytes(std::string json, const std::vector<uint8_t>& bin) {
  while (json.size() % 4 != 0) json.push_back(' ');
  std::vector<uint8_t> out;
  const auto put32 = [&](uint32_t v) {
    for (int b = 0; b < 4; ++b) out.push_back(static_cast<uint8_t>(v >> (8 * b)));
  };
  const size_t bin_padded = (bin.size() + 3) / 4 * 4;
  put32(0x46546C67u);  // "glTF"
  put32(2);
  put32(static_cast<uint32_t>(12 + 8 + json.size() + (bin.empty() ? 0 : 8 + bin_padded)));
  put32(static_cast<uint32_t>(json.size()));
  put32(0x4E4F534Au);  // "JSON"
  out.insert(out.end(), json.begin(), json.end());
  if (!bin.empty()) {
    put32(static_cast<uint32_t>(bin_padded));
    put32(0x004E4942u);  // "BIN\0"
    out.insert(out.end(), bin.begin(), bin.end());
    out.resize(out.size() + bin_padded - bin.size(), 0);
  }
  return out;
}

// EXT_meshopt_compression: every view with a codec is stored compressed in buffer 0 (the GLB's
// BIN chunk / <stem>.bin), the others (images) as they are; the compressed views' own buffer is
// buffer 1, the fallback, which holds no data (only its byteLength). `doc` is tinygltf's JSON;
// `bin` becomes buffer 0.
Status compress_views(const BufferBuilder& buffer, tinygltf::Model* model, nlohmann::json* doc,
                      std::vector<uint8_t>* bin) {
  const std::vector<uint8_t> plain = *bin;
  bin->clear();
  size_t fallback = 0;
  nlohmann::json& views = (*doc)["bufferViews"];
  for (size_t v = 0; v < model->bufferViews.size(); ++v) {
    const tinygltf::BufferView& view = model->bufferViews[v];
    const ViewCodec& codec = buffer.codecs()[v];
    const uint8_t* data = plain.data() + view.byteOffset;
    while (bin->size() % 4 != 0) bin->push_back(0);
    const size_t at = bin->size();
    if (codec.mode.empty()) {
      bin->insert(bin->end(), data, data + view.byteLength);
      views[v]["buffer"] = 0;
      views[v]["byteOffset"] = at;
      continue;
    }
    size_t size = 0;
    if (codec.mode == "TRIANGLES") {
      std::vector<uint32_t> indices(codec.count);
      std::memcpy(indices.data(), data, view.byteLength);
      const uint32_t vertices =
          indices.empty() ? 0 : *std::max_element(indices.begin(), indices.end()) + 1;
      bin->resize(at + meshopt_encodeIndexBufferBound(codec.count, vertices));
      size = meshopt_encodeIndexBuffer(bin->data() + at, bin->size() - at, indices.data(),
                                       codec.count);
    } else {
      bin->resize(at + meshopt_encodeVertexBufferBound(codec.count, codec.stride));
      size = meshopt_encodeVertexBuffer(bin->data() + at, bin->size() - at, data, codec.count,
                                        codec.stride);
    }
    if (size == 0) return Status(ErrorId::kExportWrite, "meshoptimizer could not encode a view");
    bin->resize(at + size);
    while (fallback % 4 != 0) ++fallback;
    views[v]["buffer"] = 1;
    views[v]["byteOffset"] = fallback;
    fallback += view.byteLength;
    views[v]["extensions"][kMeshopt] = {{"buffer", 0},          {"byteOffset", at},
                                        {"byteLength", size},   {"byteStride", codec.stride},
                                        {"count", codec.count}, {"mode", codec.mode}};
  }
  while (bin->size() % 4 != 0) bin->push_back(0);
  (*doc)["buffers"] = nlohmann::json::array(
      {{{"byteLength", bin->size()}},
       {{"byteLength", fallback}, {"extensions", {{kMeshopt, {{"fallback", true}}}}}}});
  (*doc)["extensionsUsed"].push_back(kMeshopt);
  (*doc)["extensionsRequired"].push_back(kMeshopt);
  return Status::Ok();
}

}  // namespace

Expected<std::vector<ExportedFile>> write_gltf(const aiScene& scene, MeshExportFormat format,
                                               const std::string& stem,
                                               const GltfOptions& options) {
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
  // Lights: directional ones as KHR_lights_punctual (tinygltf declares the extension), each on a
  // node of the scene's own; an ambient one as the scene's extras (glTF has no ambient light).
  tinygltf::Value::Object scene_extras;
  for (unsigned l = 0; l < scene.mNumLights; ++l) {
    const aiLight& source = *scene.mLights[l];
    if (source.mType == aiLightSource_DIRECTIONAL) {
      const aiColor3D& c = source.mColorDiffuse;
      const double intensity = std::max({c.r, c.g, c.b});
      tinygltf::Light light;
      light.name = source.mName.C_Str();
      light.type = "directional";
      light.intensity = intensity;
      light.color = {c.r / intensity, c.g / intensity, c.b / intensity};
      model.lights.push_back(light);
      model.nodes.push_back(light_node(source, static_cast<int>(model.lights.size() - 1)));
      gltf_scene.nodes.push_back(static_cast<int>(model.nodes.size() - 1));
    } else if (source.mType == aiLightSource_AMBIENT) {
      const aiColor3D& c = source.mColorAmbient;
      scene_extras["calf_ambient_radiance"] = tinygltf::Value(tinygltf::Value::Array{
          tinygltf::Value(static_cast<double>(c.r)), tinygltf::Value(static_cast<double>(c.g)),
          tinygltf::Value(static_cast<double>(c.b))});
    }
  }
  if (!scene_extras.empty()) gltf_scene.extras = tinygltf::Value(std::move(scene_extras));
  model.scenes.push_back(std::move(gltf_scene));
  model.defaultScene = 0;
  for (const char* extension : {kUnlit, kSpecular}) {
    for (const tinygltf::Material& m : model.materials) {
      if (m.extensions.count(extension) != 0) {
        model.extensionsUsed.push_back(extension);
        break;
      }
    }
  }
  while (buffer.bytes().size() % 4 != 0) buffer.bytes().push_back(0);
  const size_t bin_size = buffer.bytes().size();
  tinygltf::Buffer bin;
  if (format == MeshExportFormat::kGlb && !options.meshopt) bin.data = std::move(buffer.bytes());
  model.buffers.push_back(std::move(bin));

  tinygltf::TinyGLTF writer;
  std::ostringstream out;
  const bool tinygltf_glb = format == MeshExportFormat::kGlb && !options.meshopt;
  if (!writer.WriteGltfSceneToStream(&model, out, false, tinygltf_glb)) {
    return Status(ErrorId::kExportWrite, "tinygltf could not write the glTF");
  }
  const std::string text = out.str();
  std::vector<ExportedFile> files;
  if (tinygltf_glb) {
    files.push_back({"", std::vector<uint8_t>(text.begin(), text.end())});
    return files;
  }
  // tinygltf's stream writer embeds a .gltf's buffers as data URIs and cannot write a
  // bufferView's extensions: calf writes the buffer beside a .gltf (the (empty) buffer's entry is
  // replaced by the side file's), and adds EXT_meshopt_compression's objects to the JSON.
  nlohmann::json doc = nlohmann::json::parse(text, nullptr, false);
  if (doc.is_discarded() || !doc.contains("buffers")) {
    return Status(ErrorId::kExportWrite, "tinygltf wrote a .gltf calf cannot read back");
  }
  std::vector<uint8_t> data = std::move(buffer.bytes());
  if (options.meshopt) {
    CALF_RETURN_IF_ERROR(compress_views(buffer, &model, &doc, &data));
  } else {
    doc["buffers"][0] = {{"byteLength", bin_size}};
  }
  if (format == MeshExportFormat::kGlb) {
    files.push_back({"", glb_bytes(doc.dump(), data)});
    return files;
  }
  doc["buffers"][0]["uri"] = stem + ".bin";
  const std::string patched = doc.dump(2) + "\n";
  files.push_back({"", std::vector<uint8_t>(patched.begin(), patched.end())});
  files.push_back({".bin", std::move(data)});
  return files;
}

}  // namespace calf::exporter
