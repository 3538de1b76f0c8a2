#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <system_error>

#include <nlohmann/json.hpp>

#include "calf/capture/capture_set.h"
#include "calf/capture/scene_file.h"
#include "calf/format/files.h"
#include "scene_file_internal.h"

namespace calf::capture {
namespace {

// ---- JSON writing ------------------------------------------------------------------------------

// The manifest is written in SCENE.md's key order (ordered_json) for people reading it; it is read
// by key.
using OJson = nlohmann::ordered_json;

// A float as the shortest decimal that reads back (through double, as the reader does) to the
// same float: 0.8f is written 0.8, not 0.800000011920929.
OJson float_json(float v) {
  for (int digits = 1; digits <= 9; ++digits) {
    char text[32];
    std::snprintf(text, sizeof text, "%.*g", digits, static_cast<double>(v));
    double d = std::strtod(text, nullptr);
    if (static_cast<float>(d) == v) return d;
  }
  return static_cast<double>(v);
}

OJson float3_json(const SceneFloat3& v) {
  return OJson::array({float_json(v[0]), float_json(v[1]), float_json(v[2])});
}

// Appends arrays to the one buffer calf writes, each at a 4-byte-aligned offset (every element
// type is 4-byte aligned, so appending keeps the alignment).
class BufferBuilder {
 public:
  OJson add(const void* data, size_t count, size_t element_size) {
    OJson view = {{"buffer", 0}, {"offset", bytes_.size()}, {"count", count}};
    bytes_.append(static_cast<const char*>(data), count * element_size);
    return view;
  }
  std::string take() { return std::move(bytes_); }
  size_t size() const { return bytes_.size(); }

 private:
  std::string bytes_;
};

}  // namespace

Expected<EncodedScene> encode_scene_file(const SceneFile& s) {
  CALF_RETURN_IF_ERROR(validate_scene_file(s));
  BufferBuilder buffer;
  OJson meshes = OJson::array();
  for (const SceneMesh& m : s.meshes) {
    OJson j = OJson::object();
    if (!m.name.empty()) j["name"] = m.name;
    auto add = [&](const char* key, const auto& v, size_t components) {
      if (v.empty()) return;
      using T = typename std::decay_t<decltype(v)>::value_type;
      j[key] = buffer.add(v.data(), v.size() / components, components * sizeof(T));
    };
    add("positions", m.positions, 3);
    add("normals", m.normals, 3);
    add("colors", m.colors, 3);
    add("uvs", m.uvs, 2);
    add("triangles", m.indices, 3);
    add("triangle_materials", m.triangle_materials, 1);
    add("spheres", m.spheres, 1);
    if (!m.state_times.empty()) {
      j["states"] = {
          {"times", buffer.add(m.state_times.data(), m.state_times.size(), 4)},
          {"positions", buffer.add(m.state_positions.data(), m.state_positions.size() / 3, 12)}};
    }
    meshes.push_back(std::move(j));
  }
  OJson objects = OJson::array();
  for (const SceneObject& o : s.objects) {
    OJson j = OJson::object();
    if (!o.name.empty()) j["name"] = o.name;
    j["mesh"] = o.mesh;
    j["material"] = o.material;
    if (!o.transforms.empty()) {
      j["transforms"] =
          buffer.add(o.transforms.data(), o.transforms.size(), sizeof(SceneTransform));
    }
    objects.push_back(std::move(j));
  }
  OJson lights = OJson::array();
  for (const SceneLight& l : s.lights) {
    OJson j = OJson::object();
    if (!l.name.empty()) j["name"] = l.name;
    j["positions"] = buffer.add(l.positions.data(), l.positions.size(), sizeof(SceneFloat3));
    j["intensities"] = buffer.add(l.intensities.data(), l.intensities.size(), sizeof(SceneFloat3));
    lights.push_back(std::move(j));
  }
  OJson materials = OJson::array();
  for (const SceneMaterial& m : s.materials) {
    OJson j = OJson::object();
    if (!m.name.empty()) j["name"] = m.name;
    j["base_color"] = float3_json(m.base_color);
    if (m.base_color_texture != kNoTexture) j["base_color_texture"] = m.base_color_texture;
    j["emission"] = float3_json(m.emission);
    j["reflect"] = float_json(m.reflect);
    j["refract"] = float_json(m.refract);
    j["ior"] = float_json(m.ior);
    materials.push_back(std::move(j));
  }
  OJson textures = OJson::array();
  for (const SceneTexture& t : s.textures) textures.push_back({{"uri", t.path}});
  const SceneEnvironment& e = s.environment;
  OJson json = OJson::object();
  json["format"] = "calf-scene";
  json["version"] = kSceneFileVersion;
  if (!s.name.empty()) json["name"] = s.name;
  if (!s.description.empty()) json["description"] = s.description;
  if (!s.generator.empty()) json["generator"] = s.generator;
  json["fps"] = s.fps;
  json["frame_count"] = s.frame_count;
  json["view_region"] = {
      {"min", OJson::array({s.view_volume.min.x, s.view_volume.min.y, s.view_volume.min.z})},
      {"max", OJson::array({s.view_volume.max.x, s.view_volume.max.y, s.view_volume.max.z})}};
  json["environment"] = {{"zenith", float3_json(e.zenith)},
                         {"horizon", float3_json(e.horizon)},
                         {"ground", float3_json(e.ground)},
                         {"sun_direction", float3_json(e.sun_direction)},
                         {"sun_irradiance", float3_json(e.sun_irradiance)},
                         {"sun_disc_radiance", float_json(e.sun_disc_radiance)},
                         {"sun_cos_radius", float_json(e.sun_cos_radius)},
                         {"ambient", float3_json(e.ambient)},
                         {"ao_distance", float_json(e.ao_distance)}};
  json["buffers"] = OJson::array({{{"uri", kSceneBufferFileName}, {"byte_length", buffer.size()}}});
  json["textures"] = std::move(textures);
  json["materials"] = std::move(materials);
  json["meshes"] = std::move(meshes);
  json["objects"] = std::move(objects);
  json["lights"] = std::move(lights);
  EncodedScene out;
  out.manifest = json.dump(2, ' ', false, OJson::error_handler_t::replace) + "\n";
  out.buffer = buffer.take();
  return out;
}

Status write_scene_file(const SceneFile& scene, const std::filesystem::path& directory) {
  CALF_ASSIGN_OR_RETURN(EncodedScene encoded, encode_scene_file(scene));
  for (size_t i = 0; i < scene.textures.size(); ++i) {
    const SceneTexture& t = scene.textures[i];
    const std::string ext = ".png";
    bool png = t.path.size() > ext.size() && t.path.compare(t.path.size() - 4, 4, ext) == 0;
    if (!png || t.rgba.empty() || t.width == 0 || t.height == 0) {
      return Status(ErrorId::kSceneFileWriterMisuse,
                    "textures[" + std::to_string(i) + "] '" + t.path +
                        "': the writer needs pixels and a name ending in \".png\"");
    }
  }
  std::error_code ec;
  std::filesystem::create_directories(directory, ec);
  if (ec) return Status(ErrorId::kFileWrite, directory.string() + ": " + ec.message());
  const std::filesystem::path manifest = directory / kSceneManifestFileName;
  // A FIFO or link under the manifest's name is refused, not removed (calf/format/files.h).
  CALF_RETURN_IF_ERROR(files::check_output_file(manifest.string()));
  std::filesystem::remove(manifest, ec);
  if (ec)
    return Status(ErrorId::kFileWrite, manifest.string() + ": cannot remove: " + ec.message());
  for (const SceneTexture& t : scene.textures) {
    const std::filesystem::path path = directory / t.path;
    std::filesystem::create_directories(path.parent_path(), ec);
    if (ec) return Status(ErrorId::kFileWrite, path.parent_path().string() + ": " + ec.message());
    CALF_RETURN_IF_ERROR(scene_internal::write_png(path, t));
  }
  CALF_RETURN_IF_ERROR(write_file_atomically(directory / kSceneBufferFileName, encoded.buffer));
  return write_file_atomically(manifest, encoded.manifest);
}

}  // namespace calf::capture
