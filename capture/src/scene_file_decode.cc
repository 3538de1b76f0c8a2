// The scene-file decoder (format/SCENE.md). It runs in two passes: the manifest
// is parsed and every buffer view checked against the declared buffer sizes (in bounds, aligned,
// not overlapping) before a single array is allocated, so that the memory a file can make calf
// allocate is bounded by the bytes it really has; then the arrays are read and the whole scene
// validated by the same function the writer calls first.
#include <algorithm>
#include <bit>
#include <cstring>
#include <fstream>
#include <functional>
#include <memory>
#include <set>
#include <system_error>

#include "calf/capture/capture_set.h"
#include "calf/capture/scene_file.h"
#include "calf/format/files.h"
#include "json_fields.h"
#include "scene_file_internal.h"

namespace calf::capture {

namespace {

using detail::FieldReader;
using detail::Json;
using scene_internal::kMaxByteLength;
using scene_internal::kMaxNameLength;
using scene_internal::kMaxViewCount;
using scene_internal::path_problem;
using scene_internal::validate_impl;

// ---- decoding ----------------------------------------------------------------------------------

// Reads `bytes` bytes at `offset` of buffer `buffer` into `out`.
using ReadBytes =
    std::function<Status(uint32_t buffer, uint64_t offset, uint64_t bytes, void* out)>;

struct Buffer {
  std::string uri;
  uint64_t byte_length = 0;
};

// One array in a buffer, checked against the buffer's size; `target` sizes the destination and
// returns where the bytes go.
struct PendingView {
  std::string field;
  uint32_t buffer = 0;
  uint64_t offset = 0, bytes = 0;
  std::function<void*(size_t count)> target;
  uint64_t count = 0;
};

class Decoder {
 public:
  explicit Decoder(std::string_view source) : source_(source) {}

  Expected<SceneFile> decode(std::string_view text, const ReadBytes& read,
                             const std::function<Status(const std::vector<Buffer>&)>& check_buffers,
                             std::vector<Buffer>* buffers_out);

 private:
  Status error(ErrorId id, const std::string& field, const std::string& what) const {
    return Status(id, std::string(source_) + ": field '" + field + "': " + what);
  }
  FieldReader reader(const Json& object, const std::string& path) const {
    return FieldReader(object, path, source_, ErrorId::kSceneFileField, ErrorId::kSceneFileLimit,
                       ErrorId::kSceneFileValue);
  }

  Expected<std::string> name(const FieldReader& r, const char* key) const;

  // Declares a view read from `key` (absent: nothing), each element `element_size` bytes, going
  // into `target`.
  template <typename T>
  Status view(const FieldReader& r, const char* key, size_t components, std::vector<T>* out);
  Status view_raw(const FieldReader& r, const char* key, size_t element_size,
                  std::function<void*(size_t)> target);

  Status parse_mesh(const Json& j, const std::string& path, SceneMesh* mesh);

  std::string_view source_;
  std::vector<Buffer> buffers_;
  std::vector<PendingView> views_;
};

Expected<std::string> Decoder::name(const FieldReader& r, const char* key) const {
  CALF_ASSIGN_OR_RETURN(std::string s, r.string_or(key, ""));
  if (s.size() > kMaxNameLength) {
    return error(ErrorId::kSceneFileField, r.field(key), "longer than 1000 bytes");
  }
  return s;
}

Status Decoder::view_raw(const FieldReader& r, const char* key, size_t element_size,
                         std::function<void*(size_t)> target) {
  if (!r.has(key)) return Status::Ok();
  CALF_ASSIGN_OR_RETURN(const Json* j, r.get(key));
  const std::string field = r.field(key);
  if (!j->is_object()) {
    return error(ErrorId::kSceneFileField, field, "expected {\"buffer\", \"offset\", \"count\"}");
  }
  FieldReader v = reader(*j, field);
  CALF_RETURN_IF_ERROR(v.check_keys({"buffer", "offset", "count"}));
  CALF_ASSIGN_OR_RETURN(uint64_t buffer, v.count("buffer", kSceneMaxBuffers));
  CALF_ASSIGN_OR_RETURN(uint64_t offset, v.count("offset", kMaxByteLength));
  CALF_ASSIGN_OR_RETURN(uint64_t count, v.count("count", kMaxViewCount));
  if (buffer >= buffers_.size()) {
    return error(
        ErrorId::kSceneFileView, field,
        "names buffer " + std::to_string(buffer) + " of " + std::to_string(buffers_.size()));
  }
  if (offset % 4) {
    return error(ErrorId::kSceneFileView, field,
                 "offset " + std::to_string(offset) + " is not a multiple of 4");
  }
  const uint64_t bytes = count * element_size;  // < 2^46: no overflow
  const uint64_t length = buffers_[buffer].byte_length;
  if (offset > length || bytes > length - offset) {
    return error(ErrorId::kSceneFileView, field,
                 "bytes [" + std::to_string(offset) + ", " + std::to_string(offset + bytes) +
                     ") lie outside buffer " + std::to_string(buffer) + " (" +
                     std::to_string(length) + " bytes)");
  }
  views_.push_back({field, static_cast<uint32_t>(buffer), offset, bytes, std::move(target), count});
  return Status::Ok();
}

template <typename T>
Status Decoder::view(const FieldReader& r, const char* key, size_t components,
                     std::vector<T>* out) {
  return view_raw(r, key, components * sizeof(T), [out, components](size_t count) -> void* {
    out->resize(count * components);
    return out->data();
  });
}

Status Decoder::parse_mesh(const Json& j, const std::string& path, SceneMesh* mesh) {
  if (!j.is_object()) return error(ErrorId::kSceneFileField, path, "expected an object");
  FieldReader r = reader(j, path);
  CALF_RETURN_IF_ERROR(r.check_keys({"name", "positions", "normals", "colors", "uvs", "triangles",
                                     "triangle_materials", "spheres", "states"}));
  CALF_ASSIGN_OR_RETURN(mesh->name, name(r, "name"));
  CALF_RETURN_IF_ERROR(view(r, "positions", 3, &mesh->positions));
  CALF_RETURN_IF_ERROR(view(r, "normals", 3, &mesh->normals));
  CALF_RETURN_IF_ERROR(view(r, "colors", 3, &mesh->colors));
  CALF_RETURN_IF_ERROR(view(r, "uvs", 2, &mesh->uvs));
  CALF_RETURN_IF_ERROR(view(r, "triangles", 3, &mesh->indices));
  CALF_RETURN_IF_ERROR(view(r, "triangle_materials", 1, &mesh->triangle_materials));
  static_assert(sizeof(SceneSphere) == 16);
  CALF_RETURN_IF_ERROR(view(r, "spheres", 1, &mesh->spheres));
  if (r.has("states")) {
    CALF_ASSIGN_OR_RETURN(const Json* states, r.get("states"));
    if (!states->is_object()) {
      return error(ErrorId::kSceneFileField, r.field("states"), "expected an object");
    }
    FieldReader s = reader(*states, r.field("states"));
    CALF_RETURN_IF_ERROR(s.check_keys({"times", "positions"}));
    if (!s.has("times") || !s.has("positions")) {
      return error(ErrorId::kSceneFileField, r.field("states"), "needs times and positions");
    }
    CALF_RETURN_IF_ERROR(view(s, "times", 1, &mesh->state_times));
    CALF_RETURN_IF_ERROR(view(s, "positions", 3, &mesh->state_positions));
  }
  return Status::Ok();
}

Expected<SceneFile> Decoder::decode(
    std::string_view text, const ReadBytes& read,
    const std::function<Status(const std::vector<Buffer>&)>& check_buffers,
    std::vector<Buffer>* buffers_out) {
  auto parsed = detail::parse_json_object(text, source_);
  if (!parsed.ok()) return Status(ErrorId::kSceneFileSyntax, parsed.status().message());
  const Json& json = *parsed;
  FieldReader top = reader(json, "");
  // Format and version first: a future version may change every other key.
  {
    auto format = top.string("format");
    if (!format.ok() || *format != "calf-scene") {
      return error(ErrorId::kSceneFileVersion, "format", "expected \"calf-scene\"");
    }
    const Json* version = json.contains("version") ? &json["version"] : nullptr;
    if (!version || !version->is_number_integer() || version->get<int64_t>() != kSceneFileVersion) {
      return error(ErrorId::kSceneFileVersion, "version",
                   "expected " + std::to_string(kSceneFileVersion) + ", got " +
                       (version ? detail::dump_json(*version) : std::string("nothing")));
    }
  }
  CALF_RETURN_IF_ERROR(top.check_keys(
      {"format", "version", "name", "description", "generator", "fps", "frame_count", "view_region",
       "environment", "buffers", "textures", "materials", "meshes", "objects", "lights"}));
  SceneFile s;
  CALF_ASSIGN_OR_RETURN(s.name, name(top, "name"));
  CALF_ASSIGN_OR_RETURN(s.description, name(top, "description"));
  CALF_ASSIGN_OR_RETURN(s.generator, name(top, "generator"));
  CALF_ASSIGN_OR_RETURN(s.fps, top.number("fps"));
  CALF_ASSIGN_OR_RETURN(uint64_t frames, top.count("frame_count", kSceneMaxFrames));
  s.frame_count = static_cast<uint32_t>(frames);
  {
    CALF_ASSIGN_OR_RETURN(const Json* region, top.get("view_region"));
    if (!region->is_object()) {
      return error(ErrorId::kSceneFileField, "view_region", "expected {\"min\", \"max\"}");
    }
    FieldReader rr = reader(*region, "view_region");
    CALF_RETURN_IF_ERROR(rr.check_keys({"min", "max"}));
    CALF_ASSIGN_OR_RETURN(s.view_volume.min, rr.point("min"));
    CALF_ASSIGN_OR_RETURN(s.view_volume.max, rr.point("max"));
  }
  if (top.has("environment")) {
    CALF_ASSIGN_OR_RETURN(const Json* env, top.get("environment"));
    if (!env->is_object())
      return error(ErrorId::kSceneFileField, "environment", "expected an object");
    FieldReader er = reader(*env, "environment");
    CALF_RETURN_IF_ERROR(
        er.check_keys({"zenith", "horizon", "ground", "sun_direction", "sun_irradiance",
                       "sun_disc_radiance", "sun_cos_radius", "ambient", "ao_distance"}));
    SceneEnvironment& e = s.environment;
    const SceneEnvironment d;
    CALF_ASSIGN_OR_RETURN(e.zenith, er.float3_or("zenith", d.zenith));
    CALF_ASSIGN_OR_RETURN(e.horizon, er.float3_or("horizon", d.horizon));
    CALF_ASSIGN_OR_RETURN(e.ground, er.float3_or("ground", d.ground));
    CALF_ASSIGN_OR_RETURN(e.sun_direction, er.float3_or("sun_direction", d.sun_direction));
    CALF_ASSIGN_OR_RETURN(e.sun_irradiance, er.float3_or("sun_irradiance", d.sun_irradiance));
    CALF_ASSIGN_OR_RETURN(e.sun_disc_radiance, er.f32_or("sun_disc_radiance", d.sun_disc_radiance));
    CALF_ASSIGN_OR_RETURN(e.sun_cos_radius, er.f32_or("sun_cos_radius", d.sun_cos_radius));
    CALF_ASSIGN_OR_RETURN(e.ambient, er.float3_or("ambient", d.ambient));
    CALF_ASSIGN_OR_RETURN(e.ao_distance, er.f32_or("ao_distance", d.ao_distance));
  }
  // Buffers and textures: paths confined to the folder, distinct.
  std::set<std::string> uris;
  CALF_ASSIGN_OR_RETURN(const Json* buffers, top.array("buffers", kSceneMaxBuffers));
  for (size_t i = 0; i < buffers->size(); ++i) {
    const std::string at = "buffers[" + std::to_string(i) + "]";
    const Json& b = (*buffers)[i];
    if (!b.is_object()) return error(ErrorId::kSceneFileField, at, "expected an object");
    FieldReader br = reader(b, at);
    CALF_RETURN_IF_ERROR(br.check_keys({"uri", "byte_length"}));
    Buffer buffer;
    CALF_ASSIGN_OR_RETURN(buffer.uri, br.string("uri"));
    CALF_ASSIGN_OR_RETURN(buffer.byte_length, br.count("byte_length", kMaxByteLength));
    if (std::string p = path_problem(buffer.uri); !p.empty()) {
      return error(ErrorId::kSceneFilePath, br.field("uri"), "'" + buffer.uri + "' " + p);
    }
    if (!uris.insert(buffer.uri).second) {
      return error(ErrorId::kSceneFileField, br.field("uri"), "'" + buffer.uri + "' is used twice");
    }
    buffers_.push_back(std::move(buffer));
  }
  CALF_ASSIGN_OR_RETURN(const Json* textures, top.array_or_null("textures", kSceneMaxTextures));
  for (size_t i = 0; textures && i < textures->size(); ++i) {
    const std::string at = "textures[" + std::to_string(i) + "]";
    const Json& t = (*textures)[i];
    if (!t.is_object()) return error(ErrorId::kSceneFileField, at, "expected an object");
    FieldReader tr = reader(t, at);
    CALF_RETURN_IF_ERROR(tr.check_keys({"uri"}));
    SceneTexture texture;
    CALF_ASSIGN_OR_RETURN(texture.path, tr.string("uri"));
    if (std::string p = path_problem(texture.path); !p.empty()) {
      return error(ErrorId::kSceneFilePath, tr.field("uri"), "'" + texture.path + "' " + p);
    }
    if (!uris.insert(texture.path).second) {
      return error(ErrorId::kSceneFileField, tr.field("uri"),
                   "'" + texture.path + "' is used twice");
    }
    s.textures.push_back(std::move(texture));
  }
  CALF_ASSIGN_OR_RETURN(const Json* materials, top.array_or_null("materials", kSceneMaxMaterials));
  for (size_t i = 0; materials && i < materials->size(); ++i) {
    const std::string at = "materials[" + std::to_string(i) + "]";
    const Json& mj = (*materials)[i];
    if (!mj.is_object()) return error(ErrorId::kSceneFileField, at, "expected an object");
    FieldReader mr = reader(mj, at);
    CALF_RETURN_IF_ERROR(mr.check_keys(
        {"name", "base_color", "base_color_texture", "emission", "reflect", "refract", "ior"}));
    SceneMaterial m;
    CALF_ASSIGN_OR_RETURN(m.name, name(mr, "name"));
    CALF_ASSIGN_OR_RETURN(m.base_color, mr.float3_or("base_color", m.base_color));
    if (mr.has("base_color_texture")) {
      CALF_ASSIGN_OR_RETURN(uint64_t t, mr.count("base_color_texture", kSceneMaxTextures));
      m.base_color_texture = static_cast<uint32_t>(t);
    }
    CALF_ASSIGN_OR_RETURN(m.emission, mr.float3_or("emission", m.emission));
    CALF_ASSIGN_OR_RETURN(m.reflect, mr.f32_or("reflect", m.reflect));
    CALF_ASSIGN_OR_RETURN(m.refract, mr.f32_or("refract", m.refract));
    CALF_ASSIGN_OR_RETURN(m.ior, mr.f32_or("ior", m.ior));
    s.materials.push_back(std::move(m));
  }
  // Meshes, objects and lights are sized first so that the view targets keep valid addresses.
  CALF_ASSIGN_OR_RETURN(const Json* meshes, top.array_or_null("meshes", kSceneMaxMeshes));
  CALF_ASSIGN_OR_RETURN(const Json* objects, top.array_or_null("objects", kSceneMaxObjects));
  CALF_ASSIGN_OR_RETURN(const Json* lights, top.array_or_null("lights", kSceneMaxLights));
  s.meshes.resize(meshes ? meshes->size() : 0);
  s.objects.resize(objects ? objects->size() : 0);
  s.lights.resize(lights ? lights->size() : 0);
  for (size_t i = 0; i < s.meshes.size(); ++i) {
    CALF_RETURN_IF_ERROR(
        parse_mesh((*meshes)[i], "meshes[" + std::to_string(i) + "]", &s.meshes[i]));
  }
  static_assert(sizeof(SceneTransform) == 48 && sizeof(SceneFloat3) == 12);
  for (size_t i = 0; i < s.objects.size(); ++i) {
    const std::string at = "objects[" + std::to_string(i) + "]";
    const Json& oj = (*objects)[i];
    if (!oj.is_object()) return error(ErrorId::kSceneFileField, at, "expected an object");
    FieldReader orr = reader(oj, at);
    CALF_RETURN_IF_ERROR(orr.check_keys({"name", "mesh", "material", "transforms"}));
    SceneObject& o = s.objects[i];
    CALF_ASSIGN_OR_RETURN(o.name, name(orr, "name"));
    CALF_ASSIGN_OR_RETURN(o.mesh, orr.uint("mesh", 0, 0xffffffffu));
    CALF_ASSIGN_OR_RETURN(o.material, orr.uint("material", 0, 0xffffffffu));
    CALF_RETURN_IF_ERROR(view(orr, "transforms", 1, &o.transforms));
  }
  for (size_t i = 0; i < s.lights.size(); ++i) {
    const std::string at = "lights[" + std::to_string(i) + "]";
    const Json& lj = (*lights)[i];
    if (!lj.is_object()) return error(ErrorId::kSceneFileField, at, "expected an object");
    FieldReader lr = reader(lj, at);
    CALF_RETURN_IF_ERROR(lr.check_keys({"name", "positions", "intensities"}));
    SceneLight& l = s.lights[i];
    CALF_ASSIGN_OR_RETURN(l.name, name(lr, "name"));
    if (!lr.has("positions") || !lr.has("intensities")) {
      return error(ErrorId::kSceneFileField, at, "needs positions and intensities");
    }
    CALF_RETURN_IF_ERROR(view(lr, "positions", 1, &l.positions));
    CALF_RETURN_IF_ERROR(view(lr, "intensities", 1, &l.intensities));
  }
  // No two views share a byte: with every view inside its buffer, the arrays cannot add up to
  // more than the buffers' bytes however many views a manifest declares.
  std::vector<const PendingView*> order;
  for (const PendingView& v : views_) {
    if (v.bytes) order.push_back(&v);
  }
  std::sort(order.begin(), order.end(), [](const PendingView* a, const PendingView* b) {
    return a->buffer != b->buffer ? a->buffer < b->buffer : a->offset < b->offset;
  });
  for (size_t i = 1; i < order.size(); ++i) {
    const PendingView& a = *order[i - 1];
    const PendingView& b = *order[i];
    if (a.buffer == b.buffer && b.offset < a.offset + a.bytes) {
      return error(ErrorId::kSceneFileView, b.field,
                   "overlaps '" + a.field + "' in buffer " + std::to_string(a.buffer));
    }
  }
  CALF_RETURN_IF_ERROR(check_buffers(buffers_));
  for (PendingView& v : views_) {
    void* out = v.target(static_cast<size_t>(v.count));
    if (v.bytes) {
      CALF_RETURN_IF_ERROR(read(v.buffer, v.offset, v.bytes, out));
    }
  }
  if (buffers_out) *buffers_out = buffers_;
  if (Status st = validate_impl(s, ErrorId::kSceneFileField); !st.ok()) {
    return st.with_context(source_);
  }
  return s;
}

// Regular file size, or an error naming what is missing.
Expected<uint64_t> regular_file_size(const std::filesystem::path& path, const std::string& what) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    return Status(ErrorId::kSceneFileMissing, path.string() + ": " + what + " is missing");
  }
  uint64_t size = std::filesystem::file_size(path, ec);
  if (ec) return Status(ErrorId::kFileRead, path.string() + ": " + ec.message());
  return size;
}

// Where a relative path resolves, refusing links that lead out of the scene folder.
Expected<std::filesystem::path> confined(const std::filesystem::path& root, const std::string& rel,
                                         const std::string& field) {
  std::error_code ec;
  std::filesystem::path base = std::filesystem::weakly_canonical(root, ec);
  if (ec) return Status(ErrorId::kFileOpen, root.string() + ": " + ec.message());
  std::filesystem::path full = std::filesystem::weakly_canonical(root / rel, ec);
  if (ec) return Status(ErrorId::kFileOpen, (root / rel).string() + ": " + ec.message());
  auto [b, f] = std::mismatch(base.begin(), base.end(), full.begin(), full.end());
  if (b != base.end()) {
    return Status(ErrorId::kSceneFilePath, (root / kSceneManifestFileName).string() + ": field '" +
                                               field + "': '" + rel +
                                               "' resolves outside the scene folder");
  }
  return root / rel;
}

}  // namespace

Expected<SceneFile> parse_scene_file(std::string_view manifest,
                                     std::span<const std::string_view> buffers,
                                     std::string_view source) {
  Decoder decoder(source);
  auto check = [&](const std::vector<Buffer>& declared) -> Status {
    if (declared.size() != buffers.size()) {
      return Status(ErrorId::kSceneFileBufferSize,
                    std::string(source) + ": declares " + std::to_string(declared.size()) +
                        " buffers, " + std::to_string(buffers.size()) + " given");
    }
    for (size_t i = 0; i < declared.size(); ++i) {
      if (buffers[i].size() != declared[i].byte_length) {
        return Status(ErrorId::kSceneFileBufferSize,
                      std::string(source) + ": buffer '" + declared[i].uri + "' holds " +
                          std::to_string(buffers[i].size()) + " bytes, byte_length says " +
                          std::to_string(declared[i].byte_length));
      }
    }
    return Status::Ok();
  };
  auto read = [&](uint32_t b, uint64_t offset, uint64_t bytes, void* out) -> Status {
    std::memcpy(out, buffers[b].data() + offset, bytes);
    return Status::Ok();
  };
  return decoder.decode(manifest, read, check, nullptr);
}

Expected<SceneFile> read_scene_file(const std::filesystem::path& directory,
                                    uint64_t max_image_pixels) {
  const std::filesystem::path manifest_path = directory / kSceneManifestFileName;
  const std::string source = manifest_path.string();
  CALF_ASSIGN_OR_RETURN(
      std::string text,
      read_small_file(manifest_path, " (not a scene folder, or an incomplete one)"));
  std::vector<std::filesystem::path> files;
  std::vector<std::unique_ptr<std::ifstream>> streams;
  auto check = [&](const std::vector<Buffer>& declared) -> Status {
    for (size_t i = 0; i < declared.size(); ++i) {
      const std::string field = "buffers[" + std::to_string(i) + "].uri";
      CALF_ASSIGN_OR_RETURN(std::filesystem::path path,
                            confined(directory, declared[i].uri, field));
      CALF_ASSIGN_OR_RETURN(uint64_t size, regular_file_size(path, "buffer"));
      if (size != declared[i].byte_length) {
        return Status(ErrorId::kSceneFileBufferSize,
                      path.string() + ": " + std::to_string(size) + " bytes, " + source +
                          " declares " + std::to_string(declared[i].byte_length) +
                          (size < declared[i].byte_length ? " (truncated)" : ""));
      }
      files.push_back(path);
      streams.push_back(nullptr);
    }
    return Status::Ok();
  };
  auto read = [&](uint32_t b, uint64_t offset, uint64_t bytes, void* out) -> Status {
    if (!streams[b]) {
      streams[b] = std::make_unique<std::ifstream>(files[b], std::ios::binary);
      if (!*streams[b]) return Status(ErrorId::kFileOpen, files[b].string() + ": cannot open");
    }
    std::ifstream& in = *streams[b];
    in.seekg(static_cast<std::streamoff>(offset));
    in.read(static_cast<char*>(out), static_cast<std::streamsize>(bytes));
    if (!in || static_cast<uint64_t>(in.gcount()) != bytes) {
      return Status(ErrorId::kFileRead,
                    files[b].string() + ": read failed at byte " + std::to_string(offset));
    }
    return Status::Ok();
  };
  Decoder decoder(source);
  CALF_ASSIGN_OR_RETURN(SceneFile scene, decoder.decode(text, read, check, nullptr));
  for (size_t i = 0; i < scene.textures.size(); ++i) {
    SceneTexture& t = scene.textures[i];
    const std::string field = "textures[" + std::to_string(i) + "].uri";
    CALF_ASSIGN_OR_RETURN(std::filesystem::path path, confined(directory, t.path, field));
    CALF_RETURN_IF_ERROR(regular_file_size(path, "texture").status());
    CALF_RETURN_IF_ERROR(read_texture_image(path, &t, max_image_pixels));
  }
  return scene;
}

}  // namespace calf::capture
