#include <cmath>
#include <cstdio>
#include <set>
#include <string>
#include <vector>

#include "calf/capture/scene_file.h"
#include "calf/format/coordinates.h"
#include "calf/format/vertex_states.h"
#include "scene_file_internal.h"

namespace calf::capture {

// An object transform's scale (the cube root of |det| of its 3 x 3 part) lies within
// [kMinScale, kMaxScale] (CALF-E157 outside: singular, zero or absurdly scaled; SCENE.md).
constexpr double kMinScale = 1e-6;
constexpr double kMaxScale = 1e6;

namespace scene_internal {
namespace {

constexpr uint64_t kMaxVertices = uint64_t{1} << 32;
constexpr size_t kMaxPathLength = 200;
// reflect + refract may exceed 1 by float rounding ((1 - r) + r); the sample scenes allow as much.
constexpr float kWeightSlack = 1e-6f;

}  // namespace

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

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

namespace {

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

}  // namespace

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

}  // namespace scene_internal

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
  return scene_internal::validate_impl(scene, ErrorId::kSceneFileWriterMisuse);
}

}  // namespace calf::capture
