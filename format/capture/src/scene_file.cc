// Scene-file reader and writer (format/SCENE.md). The decoder runs in two passes: the manifest
// is parsed and every buffer view checked against the declared buffer sizes (in bounds, aligned,
// not overlapping) before a single array is allocated, so that the memory a file can make calf
// allocate is bounded by the bytes it really has; then the arrays are read and the whole scene
// validated by the same function the writer calls first.
#include "calf/capture/scene_file.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <functional>
#include <memory>
#include <set>
#include <system_error>

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include "calf/capture/capture_set.h"
#include "calf/format/coordinates.h"
#include "calf/format/files.h"
#include "calf/format/vertex_states.h"
#include "image_input.h"
#include "json_fields.h"

namespace calf::capture {

// Buffers are little-endian and are copied byte for byte into the arrays.
static_assert(std::endian::native == std::endian::little,
              "scene buffers assume a little-endian host");

// An object transform's scale (the cube root of |det| of its 3 x 3 part) lies within
// [kMinScale, kMaxScale] (CALF-E157 outside: singular, zero or absurdly scaled; SCENE.md).
constexpr double kMinScale = 1e-6;
constexpr double kMaxScale = 1e6;

namespace {

using detail::FieldReader;
using detail::Json;

constexpr uint64_t kMaxByteLength = uint64_t{1} << 50;
constexpr uint64_t kMaxViewCount = uint64_t{1} << 40;
constexpr uint64_t kMaxVertices = uint64_t{1} << 32;
constexpr size_t kMaxNameLength = 1000;
constexpr size_t kMaxPathLength = 200;
// reflect + refract may exceed 1 by float rounding ((1 - r) + r); the sample scenes allow as much.
constexpr float kWeightSlack = 1e-6f;

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

// ---- paths -------------------------------------------------------------------------------------

// A relative path confined to the scene folder: '/'-separated components of A-Z a-z 0-9 _ - .,
// none empty, "." or "..", none starting with '.', not "scene.json". Returns "" when valid.
std::string path_problem(std::string_view path) {
  if (path.empty()) return "is empty";
  if (path.size() > kMaxPathLength) return "is longer than 200 characters";
  if (path.front() == '/') return "is absolute";
  size_t begin = 0;
  while (begin <= path.size()) {
    size_t end = path.find('/', begin);
    if (end == std::string_view::npos) end = path.size();
    std::string_view part = path.substr(begin, end - begin);
    if (part.empty()) return "has an empty component";
    if (part == "..") return "holds '..'";
    if (part.front() == '.') return "has a component starting with '.'";
    for (char c : part) {
      bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                c == '_' || c == '-' || c == '.';
      if (!ok)
        return "holds the character '" + std::string(1, c) + "' (allowed: A-Z a-z 0-9 _ - . /)";
    }
    begin = end + 1;
  }
  if (path == kSceneManifestFileName) return "names the manifest itself";
  return "";
}

// ---- validation --------------------------------------------------------------------------------

bool finite3(const SceneFloat3& v) {
  return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]);
}
bool in01(float v) {
  return v >= 0 && v <= 1;
}

// The index of the first non-finite value, or size().
size_t first_non_finite(const std::vector<float>& v) {
  for (size_t i = 0; i < v.size(); ++i) {
    if (!std::isfinite(v[i])) return i;
  }
  return v.size();
}

std::string mesh_name(const SceneFile& s, size_t m) {
  return "meshes[" + std::to_string(m) + "]" +
         (s.meshes[m].name.empty() ? "" : " '" + s.meshes[m].name + "'");
}

Status check_mesh(const SceneFile& s, size_t m, ErrorId size_id) {
  const SceneMesh& mesh = s.meshes[m];
  const std::string at = mesh_name(s, m);
  auto size_error = [&](const char* what, size_t got, size_t want) {
    return Status(size_id, at + ": " + what + " holds " + std::to_string(got) +
                               " values, expected " + std::to_string(want));
  };
  if (mesh.positions.size() % 3)
    return size_error("positions", mesh.positions.size(), mesh.positions.size() / 3 * 3);
  if (mesh.indices.size() % 3)
    return size_error("triangles", mesh.indices.size(), mesh.indices.size() / 3 * 3);
  const size_t v = mesh.vertex_count(), t = mesh.triangle_count();
  if (v > kMaxVertices) {
    return Status(ErrorId::kSceneFileLimit,
                  at + ": " + std::to_string(v) + " vertices (at most 2^32)");
  }
  if (!mesh.normals.empty() && mesh.normals.size() != 3 * v)
    return size_error("normals", mesh.normals.size(), 3 * v);
  if (!mesh.colors.empty() && mesh.colors.size() != 3 * v)
    return size_error("colors", mesh.colors.size(), 3 * v);
  if (!mesh.uvs.empty() && mesh.uvs.size() != 2 * v)
    return size_error("uvs", mesh.uvs.size(), 2 * v);
  if (!mesh.triangle_materials.empty() && mesh.triangle_materials.size() != t) {
    return size_error("triangle_materials", mesh.triangle_materials.size(), t);
  }
  if (mesh.state_times.size() > kSceneMaxStates) {
    return Status(ErrorId::kSceneFileLimit, at + ": " + std::to_string(mesh.state_times.size()) +
                                                " vertex states (at most 4096)");
  }
  if (mesh.state_positions.size() != mesh.state_times.size() * 3 * v) {
    return size_error("states.positions", mesh.state_positions.size(),
                      mesh.state_times.size() * 3 * v);
  }
  if (t == 0 && mesh.spheres.empty()) {
    return Status(ErrorId::kSceneFileField, at + ": holds no triangle and no sphere");
  }
  auto value_error = [&](const std::string& what) {
    return Status(ErrorId::kSceneFileValue, at + ": " + what);
  };
  if (size_t i = first_non_finite(mesh.positions); i < mesh.positions.size()) {
    return value_error("vertex " + std::to_string(i / 3) + ": position is not finite");
  }
  for (size_t i = 0; i < mesh.normals.size(); i += 3) {
    const float* n = &mesh.normals[i];
    bool ok = std::isfinite(n[0]) && std::isfinite(n[1]) && std::isfinite(n[2]) &&
              (n[0] != 0 || n[1] != 0 || n[2] != 0);
    if (!ok)
      return value_error("vertex " + std::to_string(i / 3) + ": normal is not finite and non-zero");
  }
  for (size_t i = 0; i < mesh.colors.size(); ++i) {
    if (!in01(mesh.colors[i])) {
      return value_error("vertex " + std::to_string(i / 3) + ": colour " + num(mesh.colors[i]) +
                         " is outside [0, 1]");
    }
  }
  if (size_t i = first_non_finite(mesh.uvs); i < mesh.uvs.size()) {
    return value_error("vertex " + std::to_string(i / 2) + ": uv is not finite");
  }
  for (size_t i = 0; i < mesh.indices.size(); ++i) {
    if (mesh.indices[i] >= v) {
      return Status(ErrorId::kSceneFileIndex,
                    at + ": triangle " + std::to_string(i / 3) + " names vertex " +
                        std::to_string(mesh.indices[i]) + " of " + std::to_string(v));
    }
  }
  for (size_t i = 0; i < mesh.triangle_materials.size(); ++i) {
    if (mesh.triangle_materials[i] >= s.materials.size()) {
      return Status(ErrorId::kSceneFileIndex, at + ": triangle " + std::to_string(i) +
                                                  " names material " +
                                                  std::to_string(mesh.triangle_materials[i]) +
                                                  " of " + std::to_string(s.materials.size()));
    }
  }
  for (size_t i = 0; i < mesh.spheres.size(); ++i) {
    const SceneSphere& sp = mesh.spheres[i];
    if (!finite3(sp.center) || !std::isfinite(sp.radius) || !(sp.radius > 0)) {
      return value_error("sphere " + std::to_string(i) + ": centre not finite or radius " +
                         num(sp.radius) + " not finite and > 0");
    }
  }
  for (size_t k = 0; k < mesh.state_times.size(); ++k) {
    float time = mesh.state_times[k];
    if (!std::isfinite(time) || time < 0 || (k > 0 && !(time > mesh.state_times[k - 1]))) {
      return value_error("state " + std::to_string(k) + ": time " + num(time) +
                         " is not finite, >= 0 and after the previous state's");
    }
  }
  if (size_t i = first_non_finite(mesh.state_positions); i < mesh.state_positions.size()) {
    return value_error("state " + std::to_string(i / 3 / v) + ", vertex " +
                       std::to_string(i / 3 % v) + ": position is not finite");
  }
  return Status::Ok();
}

Status validate_impl(const SceneFile& s, ErrorId size_id) {
  if (!(s.fps > 0 && s.fps <= 1000)) {
    return Status(ErrorId::kSceneFileField, "fps " + num(s.fps) + " is outside (0, 1000]");
  }
  if (s.frame_count < 1) return Status(ErrorId::kSceneFileField, "frame_count is 0");
  if (s.frame_count > kSceneMaxFrames) {
    return Status(ErrorId::kSceneFileLimit,
                  "frame_count " + std::to_string(s.frame_count) + " exceeds 1000000");
  }
  const Box3& box = s.view_volume;
  const double lo[3] = {box.min.x, box.min.y, box.min.z}, hi[3] = {box.max.x, box.max.y, box.max.z};
  for (int a = 0; a < 3; ++a) {
    if (!std::isfinite(lo[a]) || !std::isfinite(hi[a])) {
      return Status(ErrorId::kSceneFileValue, "view_region is not finite");
    }
    if (lo[a] > hi[a]) {
      return Status(ErrorId::kSceneFileField,
                    "view_region: min exceeds max on axis " + std::string(1, "xyz"[a]));
    }
  }
  for (const std::string* text : {&s.name, &s.description, &s.generator}) {
    if (text->size() > kMaxNameLength) {
      return Status(ErrorId::kSceneFileField, "a name or description exceeds 1000 bytes");
    }
  }
  const SceneEnvironment& e = s.environment;
  bool env_ok = finite3(e.zenith) && finite3(e.horizon) && finite3(e.ground) &&
                finite3(e.sun_direction) && finite3(e.sun_irradiance) && finite3(e.ambient) &&
                std::isfinite(e.sun_disc_radiance) && std::isfinite(e.sun_cos_radius) &&
                std::isfinite(e.ao_distance) && e.ao_distance > 0 && e.sun_cos_radius >= -1 &&
                e.sun_cos_radius <= 1 &&
                (e.sun_direction[0] != 0 || e.sun_direction[1] != 0 || e.sun_direction[2] != 0);
  for (const SceneFloat3* c : {&e.zenith, &e.horizon, &e.ground, &e.sun_irradiance, &e.ambient}) {
    env_ok = env_ok && (*c)[0] >= 0 && (*c)[1] >= 0 && (*c)[2] >= 0;
  }
  if (!env_ok || !(e.sun_disc_radiance >= 0)) {
    return Status(ErrorId::kSceneFileValue,
                  "environment: a value is not finite or outside its range (colours >= 0, "
                  "sun_direction non-zero, sun_cos_radius in [-1, 1], ao_distance > 0)");
  }
  if (s.materials.size() > kSceneMaxMaterials || s.textures.size() > kSceneMaxTextures ||
      s.meshes.size() > kSceneMaxMeshes || s.objects.size() > kSceneMaxObjects ||
      s.lights.size() > kSceneMaxLights) {
    return Status(ErrorId::kSceneFileLimit,
                  "more materials, textures, meshes, objects or lights "
                  "than SCENE.md \"Limits\" allows");
  }
  std::set<std::string> paths;
  for (size_t i = 0; i < s.textures.size(); ++i) {
    const SceneTexture& t = s.textures[i];
    const std::string at = "textures[" + std::to_string(i) + "]";
    if (std::string p = path_problem(t.path); !p.empty()) {
      return Status(ErrorId::kSceneFilePath, at + ": path '" + t.path + "' " + p);
    }
    if (!paths.insert(t.path).second || t.path == kSceneBufferFileName) {
      return Status(ErrorId::kSceneFileField,
                    at + ": path '" + t.path + "' is used twice or names the buffer");
    }
    if (t.width > kSceneMaxTextureSize || t.height > kSceneMaxTextureSize) {
      return Status(ErrorId::kSceneFileTexture, at + ": larger than 16384 x 16384");
    }
    if (!t.rgba.empty() && t.rgba.size() != size_t{4} * t.width * t.height) {
      return Status(size_id, at + ": holds " + std::to_string(t.rgba.size()) +
                                 " bytes, expected width * height * 4");
    }
  }
  for (size_t i = 0; i < s.materials.size(); ++i) {
    const SceneMaterial& m = s.materials[i];
    const std::string at = "materials[" + std::to_string(i) + "]";
    bool ok = in01(m.base_color[0]) && in01(m.base_color[1]) && in01(m.base_color[2]) &&
              finite3(m.emission) && m.emission[0] >= 0 && m.emission[1] >= 0 &&
              m.emission[2] >= 0 && in01(m.reflect) && in01(m.refract) &&
              m.reflect + m.refract <= 1 + kWeightSlack && std::isfinite(m.ior) && m.ior > 0;
    if (!ok) {
      return Status(ErrorId::kSceneFileValue,
                    at + ": a value is outside its range (base_color and weights in [0, 1], "
                         "reflect + refract <= 1, emission finite and >= 0, ior finite and > 0)");
    }
    if (m.base_color_texture != kNoTexture && m.base_color_texture >= s.textures.size()) {
      return Status(ErrorId::kSceneFileIndex, at + ": base_color_texture " +
                                                  std::to_string(m.base_color_texture) + " of " +
                                                  std::to_string(s.textures.size()));
    }
  }
  for (size_t m = 0; m < s.meshes.size(); ++m) CALF_RETURN_IF_ERROR(check_mesh(s, m, size_id));
  for (size_t i = 0; i < s.objects.size(); ++i) {
    const SceneObject& o = s.objects[i];
    const std::string at = "objects[" + std::to_string(i) + "]";
    if (o.mesh >= s.meshes.size()) {
      return Status(ErrorId::kSceneFileIndex, at + ": mesh " + std::to_string(o.mesh) + " of " +
                                                  std::to_string(s.meshes.size()));
    }
    if (o.material >= s.materials.size()) {
      return Status(ErrorId::kSceneFileIndex, at + ": material " + std::to_string(o.material) +
                                                  " of " + std::to_string(s.materials.size()));
    }
    size_t n = o.transforms.size();
    if (n > 1 && n != s.frame_count) {
      return Status(size_id, at + ": " + std::to_string(n) +
                                 " transforms, expected 0, 1 or frame_count (" +
                                 std::to_string(s.frame_count) + ")");
    }
    for (size_t f = 0; f < n; ++f) {
      const SceneTransform& t = o.transforms[f];
      for (float x : t) {
        if (!std::isfinite(x)) {
          return Status(ErrorId::kSceneFileValue,
                        at + ": transform " + std::to_string(f) + " is not finite");
        }
      }
      // Rigid or uniformly scaled (SCENE.md): at least not singular, and a scale and a
      // translation a renderer can hold.
      const auto m = [&](int r, int c) { return static_cast<double>(t[4 * r + c]); };
      const double det = m(0, 0) * (m(1, 1) * m(2, 2) - m(1, 2) * m(2, 1)) -
                         m(0, 1) * (m(1, 0) * m(2, 2) - m(1, 2) * m(2, 0)) +
                         m(0, 2) * (m(1, 0) * m(2, 1) - m(1, 1) * m(2, 0));
      const double scale = std::cbrt(std::fabs(det));
      if (!(scale >= kMinScale && scale <= kMaxScale)) {
        char buf[160];
        std::snprintf(buf, sizeof buf,
                      ": transform %zu has scale %g (cube root of |det|), not in "
                      "[%g, %g]: singular, zero or too large",
                      f, scale, kMinScale, kMaxScale);
        return Status(ErrorId::kSceneFileValue, at + buf);
      }
      for (int r = 0; r < 3; ++r) {
        if (!coordinate_ok(m(r, 3))) {
          return Status(ErrorId::kSceneFileValue, at + ": transform " + std::to_string(f) +
                                                      " translates beyond the coordinate bound");
        }
      }
    }
  }
  for (size_t i = 0; i < s.lights.size(); ++i) {
    const SceneLight& l = s.lights[i];
    const std::string at = "lights[" + std::to_string(i) + "]";
    for (const auto* samples : {&l.positions, &l.intensities}) {
      if (samples->size() != 1 && samples->size() != s.frame_count) {
        return Status(size_id, at + ": " + std::to_string(samples->size()) +
                                   " samples, expected 1 or frame_count (" +
                                   std::to_string(s.frame_count) + ")");
      }
    }
    for (const SceneFloat3& p : l.positions) {
      if (!finite3(p)) return Status(ErrorId::kSceneFileValue, at + ": a position is not finite");
    }
    for (const SceneFloat3& c : l.intensities) {
      if (!finite3(c) || c[0] < 0 || c[1] < 0 || c[2] < 0) {
        return Status(ErrorId::kSceneFileValue, at + ": an intensity is not finite and >= 0");
      }
    }
  }
  return Status::Ok();
}

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

std::string oiio_error(const std::string& fallback) {
  std::string e = OIIO::geterror();
  return e.empty() ? fallback : e;
}

// Spreads `nch` 8-bit channels into RGBA by SCENE.md "Texture" (grey spreads to RGB, alpha is
// opaque when the image has none); `rgba` may be `raw` itself when nch is 4.
void spread_to_rgba(const uint8_t* raw, int nch, size_t pixels, uint8_t* rgba) {
  if (nch == 4) {
    if (raw != rgba) std::memcpy(rgba, raw, pixels * 4);
    return;
  }
  for (size_t i = 0; i < pixels; ++i) {
    const uint8_t* p = &raw[i * static_cast<size_t>(nch)];
    uint8_t* q = &rgba[i * 4];
    q[0] = p[0];
    q[1] = nch >= 3 ? p[1] : p[0];
    q[2] = nch >= 3 ? p[2] : p[0];
    q[3] = nch >= 4 ? p[3] : nch == 2 ? p[1] : 255;
  }
}

// The texture rule of every image: its header's size (at most 16384 x 16384, within the budget)
// before any pixel is decoded.
detail::ImageExpect texture_expect(uint64_t max_pixels) {
  detail::ImageExpect expect;
  expect.wrong_size = ErrorId::kSceneFileTexture;
  expect.undecodable = ErrorId::kSceneFileTexture;
  expect.max_pixels = max_pixels;
  expect.allow_16_bit = true;
  return expect;
}

// A decoded PNG as a texture: RGBA images keep their buffer, others spread into a new one.
void texture_from_png(detail::Png8&& image, SceneTexture* t) {
  t->width = image.width;
  t->height = image.height;
  const size_t pixels = size_t{image.width} * image.height;
  if (image.channels == 4) {
    t->rgba = std::move(image.pixels);
    return;
  }
  t->rgba.resize(pixels * 4);
  spread_to_rgba(image.pixels.data(), static_cast<int>(image.channels), pixels, t->rgba.data());
}

// Decodes the image `name` (read through `proxy` when given, else from the file of that name)
// with OpenImageIO: formats other than PNG. `exr`: the bytes are OpenEXR whose header passed
// check_exr_header, and only OpenImageIO's OpenEXR reader may see them (its open() would hand
// bytes its first choice refuses to every other format reader in turn).
Status decode_image(const std::string& name, OIIO::Filesystem::IOProxy* proxy, bool exr,
                    uint64_t max_pixels, SceneTexture* t) {
  try {
    // Unassociated alpha: the bytes of the file, not colour premultiplied by alpha.
    OIIO::ImageSpec config;
    config.attribute("oiio:UnassociatedAlpha", 1);
    // The readers of OpenImageIO 2.4 take the proxy from the configuration, not the argument.
    if (proxy) config.attribute("oiio:ioproxy", OIIO::TypeDesc::PTR, &proxy);
    std::unique_ptr<OIIO::ImageInput> in;
    if (exr) {
      in = OIIO::ImageInput::create("openexr");
      OIIO::ImageSpec spec;
      if (in && !in->open(name, spec, config)) in.reset();
    } else {
      in = OIIO::ImageInput::open(name, &config, proxy);
    }
    if (!in) return Status(ErrorId::kSceneFileTexture, name + ": " + oiio_error("cannot decode"));
    const OIIO::ImageSpec& spec = in->spec();
    CALF_RETURN_IF_ERROR(
        detail::check_image_size(name, spec.width, spec.height, texture_expect(max_pixels)));
    if (spec.nchannels < 1) {
      return Status(ErrorId::kSceneFileTexture, name + ": an image without channels");
    }
    const int nch = std::min(spec.nchannels, 4);  // channels past RGBA are never read
    const size_t pixels = static_cast<size_t>(spec.width) * static_cast<size_t>(spec.height);
    t->rgba.resize(pixels * 4);
    std::vector<uint8_t> raw;
    if (nch != 4) raw.resize(pixels * static_cast<size_t>(nch));
    uint8_t* target = nch == 4 ? t->rgba.data() : raw.data();
    if (!in->read_image(0, 0, 0, nch, OIIO::TypeDesc::UINT8, target)) {
      t->rgba.clear();
      return Status(ErrorId::kSceneFileTexture, name + ": " + oiio_error("cannot decode"));
    }
    t->width = static_cast<uint32_t>(spec.width);
    t->height = static_cast<uint32_t>(spec.height);
    spread_to_rgba(target, nch, pixels, t->rgba.data());
  } catch (const std::exception& e) {
    return Status(ErrorId::kSceneFileTexture, name + ": " + e.what());
  }
  return Status::Ok();
}

Status write_png(const std::filesystem::path& path, const SceneTexture& t) {
  const std::string final_name = path.string();
  // The output rules, temporary name and cleanup on a signal are files::TempFile's.
  CALF_ASSIGN_OR_RETURN(files::TempFile temp, files::TempFile::create(final_name));
  temp.close_fd();  // OIIO opens the file by name
  try {
    std::unique_ptr<OIIO::ImageOutput> out = OIIO::ImageOutput::create("png");
    if (!out) return Status(ErrorId::kFileWrite, final_name + ": " + oiio_error("no PNG writer"));
    OIIO::ImageSpec spec(static_cast<int>(t.width), static_cast<int>(t.height), 4,
                         OIIO::TypeDesc::UINT8);
    spec.attribute("oiio:UnassociatedAlpha", 1);  // the pixels are not premultiplied
    bool ok =
        out->open(temp.temp_path(), spec) && out->write_image(OIIO::TypeDesc::UINT8, t.rgba.data());
    ok = out->close() && ok;
    if (!ok) return Status(ErrorId::kFileWrite, final_name + ": " + oiio_error("write failed"));
  } catch (const std::exception& e) {
    return Status(ErrorId::kFileWrite, final_name + ": " + e.what());
  }
  return temp.commit(/*sync=*/false);
}

}  // namespace

size_t SceneFile::triangle_count() const {
  size_t n = 0;
  for (const SceneObject& o : objects) {
    if (o.mesh < meshes.size()) n += meshes[o.mesh].triangle_count();
  }
  return n;
}

size_t SceneFile::mesh_triangle_count() const {
  size_t n = 0;
  for (const SceneMesh& m : meshes) n += m.triangle_count();
  return n;
}

const SceneTransform& transform_at(const SceneObject& object, uint32_t frame) {
  if (object.transforms.empty()) return kSceneIdentity;
  return object.transforms[std::min<size_t>(frame, object.transforms.size() - 1)];
}

void positions_at(const SceneMesh& mesh, double time, std::vector<float>* out) {
  out->resize(mesh.positions.size());
  vertex_states_at(mesh.positions, mesh.state_times, mesh.state_positions, time, *out);
}

Status validate_scene_file(const SceneFile& scene) {
  return validate_impl(scene, ErrorId::kSceneFileWriterMisuse);
}

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

Status read_texture_image(const std::filesystem::path& path, SceneTexture* texture,
                          uint64_t max_image_pixels) {
  if (detail::has_png_signature(path)) {
    detail::Png8 image;
    CALF_RETURN_IF_ERROR(detail::read_png8(path, texture_expect(max_image_pixels), &image));
    texture_from_png(std::move(image), texture);
    return Status::Ok();
  }
  const bool exr = detail::has_exr_signature(path) || path.extension() == ".exr";
  if (exr) {
    detail::ExrHeader header;
    CALF_RETURN_IF_ERROR(detail::check_exr_header(path, ErrorId::kSceneFileTexture, &header));
    CALF_RETURN_IF_ERROR(detail::check_image_size(path.string(), header.width, header.height,
                                                  texture_expect(max_image_pixels)));
  }
  return decode_image(path.string(), nullptr, exr, max_image_pixels, texture);
}

Status decode_texture_image(std::span<const uint8_t> bytes, std::string_view format_hint,
                            std::string_view name, SceneTexture* texture,
                            uint64_t max_image_pixels) {
  if (detail::has_png_signature(bytes)) {
    detail::Png8 image;
    CALF_RETURN_IF_ERROR(detail::decode_png8(bytes, std::string(name) + " (png)",
                                             texture_expect(max_image_pixels), &image));
    texture_from_png(std::move(image), texture);
    return Status::Ok();
  }
  // OpenImageIO picks its reader by the name's extension; the magic numbers of the formats
  // models embed win over a hint that may be wrong or empty.
  std::string ext(format_hint);
  if (bytes.size() >= 8 && std::memcmp(bytes.data(), "\x89PNG\r\n\x1a\n", 8) == 0) {
    ext = "png";
  } else if (bytes.size() >= 3 && bytes[0] == 0xff && bytes[1] == 0xd8 && bytes[2] == 0xff) {
    ext = "jpg";
  } else if (detail::has_exr_signature(bytes)) {
    ext = "exr";
  }
  if (ext.empty() || ext.find_first_of("./\\") != std::string::npos) {
    return Status(ErrorId::kSceneFileTexture,
                  std::string(name) + ": an image of unknown format (not PNG or JPEG, no hint)");
  }
  // OpenEXR by its magic number or its hint: the header walked first, in the bytes given.
  const bool exr = ext == "exr";
  if (exr) {
    const std::string label = std::string(name) + " (exr)";
    detail::ExrHeader header;
    CALF_RETURN_IF_ERROR(
        detail::check_exr_header(bytes, label, ErrorId::kSceneFileTexture, &header));
    CALF_RETURN_IF_ERROR(detail::check_image_size(label, header.width, header.height,
                                                  texture_expect(max_image_pixels)));
  }
  OIIO::Filesystem::IOMemReader reader(bytes.data(), bytes.size());
  Status s = decode_image("embedded." + ext, &reader, exr, max_image_pixels, texture);
  if (s.ok()) return s;
  return Status(s.id(), std::string(name) + " (" + ext + "): " + s.message());
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
    CALF_RETURN_IF_ERROR(write_png(path, t));
  }
  CALF_RETURN_IF_ERROR(write_file_atomically(directory / kSceneBufferFileName, encoded.buffer));
  return write_file_atomically(manifest, encoded.manifest);
}

}  // namespace calf::capture
