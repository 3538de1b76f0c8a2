// Scene validation, procedural geometry helpers and loading by name.
#include <algorithm>
#include <cmath>
#include <system_error>
#include <unordered_set>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>

#include "calf/capture/scene_file.h"
#include "calf/format/vertex_states.h"
#include "calf/samples/scene.h"
#include "glm_vec.h"

namespace calf::samples {

namespace {

bool finite(const glm::vec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

}  // namespace

bool Scene::has_mirror_or_glass() const {
  for (const Object& o : objects) {
    if (o.material < materials.size() &&
        (materials[o.material].reflect > 0 || materials[o.material].refract > 0)) {
      return true;
    }
  }
  return false;
}

size_t Scene::triangle_count() const {
  size_t n = 0;
  for (const Object& o : objects) n += o.triangle_mesh().triangles.size();
  return n;
}

size_t Scene::sphere_count() const {
  size_t n = 0;
  for (const Object& o : objects) n += o.spheres.size();
  return n;
}

void positions_at(const TriangleMesh& mesh, double time, std::vector<glm::vec3>* out) {
  static_assert(sizeof(glm::vec3) == 3 * sizeof(float));
  out->resize(mesh.positions.size());
  if (out->empty()) return;
  const size_t n = mesh.positions.size() * 3;
  const size_t s = mesh.state_positions.size() * 3;
  vertex_states_at({glm::value_ptr(mesh.positions.front()), n}, mesh.state_times,
                   {s == 0 ? nullptr : glm::value_ptr(mesh.state_positions.front()), s}, time,
                   {glm::value_ptr(out->front()), n});
}

namespace {

// The checks of one mesh (own or shared), naming `what` (the object) in messages.
Status validate_mesh(const TriangleMesh& mesh, const std::string& what) {
  auto bad = [&](const std::string& why) {
    return Status(ErrorId::kSceneGeometry, what + " " + why);
  };
  for (size_t i = 0; i < mesh.positions.size(); ++i) {
    if (!finite(mesh.positions[i])) return bad("has a non-finite vertex " + std::to_string(i));
  }
  const size_t v = mesh.positions.size();
  for (size_t i = 0; i < mesh.triangles.size(); ++i) {
    const glm::uvec3& t = mesh.triangles[i];
    if (t.x >= v || t.y >= v || t.z >= v) {
      return bad("has triangle " + std::to_string(i) + " with a vertex index out of range");
    }
  }
  if (!mesh.uvs.empty() && mesh.uvs.size() != v) {
    return bad("has " + std::to_string(mesh.uvs.size()) + " UVs for " + std::to_string(v) +
               " vertices");
  }
  for (size_t i = 0; i < mesh.uvs.size(); ++i) {
    if (!std::isfinite(mesh.uvs[i].x) || !std::isfinite(mesh.uvs[i].y)) {
      return bad("has a non-finite UV at vertex " + std::to_string(i));
    }
  }
  const size_t states = mesh.state_times.size();
  if (states > capture::kSceneMaxStates) {
    return bad("has " + std::to_string(states) + " vertex states, more than 4096");
  }
  for (size_t k = 0; k < states; ++k) {
    const float t = mesh.state_times[k];
    if (!std::isfinite(t) || t < 0 || (k > 0 && !(t > mesh.state_times[k - 1]))) {
      return bad("has vertex state " + std::to_string(k) + " at time " + std::to_string(t) +
                 ": times must be finite, >= 0 and strictly increasing");
    }
  }
  if (mesh.state_positions.size() != states * v) {
    return bad("has " + std::to_string(mesh.state_positions.size()) + " state positions for " +
               std::to_string(states) + " states of " + std::to_string(v) + " vertices");
  }
  for (size_t i = 0; i < mesh.state_positions.size(); ++i) {
    if (!finite(mesh.state_positions[i])) {
      return bad("has a non-finite position of vertex " + std::to_string(v ? i % v : 0) +
                 " in state " + std::to_string(v ? i / v : 0));
    }
  }
  return Status::Ok();
}

}  // namespace

Status validate_scene(const Scene& scene) {
  const std::string where = "scene '" + scene.name + "'";
  size_t primitives = 0;
  std::unordered_set<const TriangleMesh*> checked;
  for (size_t i = 0; i < scene.textures.size(); ++i) {
    const Texture* t = scene.textures[i].get();
    const capture::SceneTexture* im = t ? &t->image : nullptr;
    if (!im || im->width < 1 || im->height < 1 || im->width > capture::kSceneMaxTextureSize ||
        im->height > capture::kSceneMaxTextureSize ||
        im->rgba.size() != size_t{im->width} * im->height * 4 || t->levels.empty() ||
        t->levels[0].width != im->width || t->levels[0].height != im->height) {
      return Status(ErrorId::kSceneGeometry,
                    where + ": texture " + std::to_string(i) +
                        " is missing, empty, larger than 16384 x 16384 or not made by "
                        "make_texture");
    }
  }
  if (!(std::isfinite(scene.length_scale) && scene.length_scale > 0) ||
      !(std::isfinite(scene.default_rig.keep_out_radius) &&
        scene.default_rig.keep_out_radius >= 0)) {
    return Status(ErrorId::kSceneGeometry,
                  where +
                      ": the length scale must be finite and > 0, the rig's keep-out radius "
                      "finite and >= 0");
  }
  for (size_t m = 0; m < scene.materials.size(); ++m) {
    const Material& mat = scene.materials[m];
    bool ok = finite(mat.albedo) && finite(mat.emission) && mat.reflect >= 0 && mat.refract >= 0 &&
              mat.reflect + mat.refract <= 1.0f + 1e-6f && std::isfinite(mat.ior) && mat.ior > 0 &&
              glm::all(glm::greaterThanEqual(mat.emission, glm::vec3(0))) &&
              (mat.base_color_texture == capture::kNoTexture ||
               mat.base_color_texture < scene.textures.size());
    if (!ok) {
      return Status(ErrorId::kSceneGeometry, where + ": material " + std::to_string(m) +
                                                 " is out of range or names a missing texture");
    }
  }
  for (const Object& o : scene.objects) {
    if (o.material >= scene.materials.size()) {
      return Status(ErrorId::kSceneGeometry, where + ": object '" + o.name + "' uses material " +
                                                 std::to_string(o.material) + " of " +
                                                 std::to_string(scene.materials.size()));
    }
    const std::string what = where + ": object '" + o.name + "'";
    if (o.shared_mesh) {
      if (!o.mesh.positions.empty() || !o.mesh.triangles.empty() || !o.spheres.empty()) {
        return Status(ErrorId::kSceneGeometry,
                      what + " has a shared mesh and also triangles or spheres of its own");
      }
      // A shared mesh is checked once, however many objects place it.
      if (checked.insert(o.shared_mesh.get()).second) {
        CALF_RETURN_IF_ERROR(validate_mesh(*o.shared_mesh, what + " (shared mesh)"));
      }
    } else {
      CALF_RETURN_IF_ERROR(validate_mesh(o.mesh, what));
    }
    for (const Sphere& s : o.spheres) {
      if (!finite(s.center) || !(s.radius > 0) || !std::isfinite(s.radius)) {
        return Status(ErrorId::kSceneGeometry,
                      where + ": object '" + o.name + "' has a sphere with a bad centre or radius");
      }
    }
    primitives += o.triangle_mesh().triangles.size() + o.spheres.size();
  }
  if (primitives == 0) {
    return Status(ErrorId::kSceneEmpty, where + ": no triangles and no spheres to render");
  }
  if (!(scene.fps > 0 && scene.fps <= 1000) || scene.frame_count == 0) {
    return Status(ErrorId::kSceneGeometry, where + ": fps or frame count out of range");
  }
  return Status::Ok();
}

Expected<Scene> load_scene(std::string_view name_or_path, uint64_t max_image_pixels) {
  for (const SceneInfo& info : builtin_scenes()) {
    if (name_or_path == info.name) return make_builtin_scene(name_or_path);
  }
  std::error_code ec;
  std::filesystem::path path(name_or_path);
  if (name_or_path.find('.') != std::string_view::npos || std::filesystem::exists(path, ec)) {
    return load_scene_file(path, max_image_pixels);
  }
  std::string names;
  for (const SceneInfo& info : builtin_scenes()) {
    if (!names.empty()) names.append(", ");
    names.append(info.name);
  }
  std::string message = "'";
  message.append(name_or_path).append("' is neither a built-in scene (").append(names);
  message.append(") nor a file");
  return Status(ErrorId::kSceneUnknown, message);
}

// ---- geometry helpers
// ----------------------------------------------------------------------------

void add_quad(TriangleMesh* mesh, const glm::vec3& p0, const glm::vec3& p1, const glm::vec3& p2,
              const glm::vec3& p3) {
  uint32_t b = static_cast<uint32_t>(mesh->positions.size());
  mesh->positions.insert(mesh->positions.end(), {p0, p1, p2, p3});
  mesh->triangles.push_back({b, b + 1, b + 2});
  mesh->triangles.push_back({b, b + 2, b + 3});
}

namespace {

// The 6 faces of [-1, 1]^3 as corner lists, counter-clockwise seen from outside.
void add_unit_box(TriangleMesh* mesh, const glm::mat4& m, bool inward) {
  auto t = [&](float x, float y, float z) { return glm::vec3(m * glm::vec4(x, y, z, 1)); };
  const float q[6][4][3] = {
      {{1, -1, -1}, {1, 1, -1}, {1, 1, 1}, {1, -1, 1}},      // +X
      {{-1, -1, 1}, {-1, 1, 1}, {-1, 1, -1}, {-1, -1, -1}},  // -X
      {{-1, 1, -1}, {-1, 1, 1}, {1, 1, 1}, {1, 1, -1}},      // +Y
      {{-1, -1, 1}, {-1, -1, -1}, {1, -1, -1}, {1, -1, 1}},  // -Y
      {{-1, -1, 1}, {1, -1, 1}, {1, 1, 1}, {-1, 1, 1}},      // +Z
      {{1, -1, -1}, {-1, -1, -1}, {-1, 1, -1}, {1, 1, -1}},  // -Z
  };
  // A reflection (negative determinant) flips the winding; undo it so outside stays outside.
  bool flip = inward != (glm::determinant(glm::mat3(m)) < 0);
  for (const auto& f : q) {
    glm::vec3 c[4];
    for (int i = 0; i < 4; ++i) c[i] = t(f[i][0], f[i][1], f[i][2]);
    if (flip) {
      add_quad(mesh, c[3], c[2], c[1], c[0]);
    } else {
      add_quad(mesh, c[0], c[1], c[2], c[3]);
    }
  }
}

glm::mat4 box_matrix(const glm::vec3& lo, const glm::vec3& hi) {
  glm::mat4 m = glm::translate(glm::mat4(1), (lo + hi) * 0.5f);
  return glm::scale(m, (hi - lo) * 0.5f);
}

}  // namespace

void add_box(TriangleMesh* mesh, const glm::mat4& m) {
  add_unit_box(mesh, m, false);
}

void add_box(TriangleMesh* mesh, const glm::vec3& lo, const glm::vec3& hi) {
  add_unit_box(mesh, box_matrix(lo, hi), false);
}

void add_room(TriangleMesh* mesh, const glm::vec3& lo, const glm::vec3& hi) {
  add_unit_box(mesh, box_matrix(lo, hi), true);
}

void add_cylinder(TriangleMesh* mesh, const glm::mat4& m, uint32_t segments) {
  auto t = [&](float x, float y, float z) { return glm::vec3(m * glm::vec4(x, y, z, 1)); };
  bool flip = glm::determinant(glm::mat3(m)) < 0;
  const glm::vec3 top = t(0, 1, 0), bottom = t(0, -1, 0);
  for (uint32_t i = 0; i < segments; ++i) {
    float a0 = 6.2831853f * static_cast<float>(i) / static_cast<float>(segments);
    float a1 = 6.2831853f * static_cast<float>(i + 1) / static_cast<float>(segments);
    // Angles grow from +X towards -Z so that quads wind outward.
    glm::vec3 b0 = t(std::cos(a0), -1, -std::sin(a0)), b1 = t(std::cos(a1), -1, -std::sin(a1));
    glm::vec3 u0 = t(std::cos(a0), 1, -std::sin(a0)), u1 = t(std::cos(a1), 1, -std::sin(a1));
    uint32_t b = static_cast<uint32_t>(mesh->positions.size());
    mesh->positions.insert(mesh->positions.end(), {b0, b1, u1, u0, top, bottom});
    auto tri = [&](uint32_t i0, uint32_t i1, uint32_t i2) {
      mesh->triangles.push_back(flip ? glm::uvec3(b + i0, b + i2, b + i1)
                                     : glm::uvec3(b + i0, b + i1, b + i2));
    };
    tri(0, 1, 2);
    tri(0, 2, 3);
    tri(3, 2, 4);  // top cap
    tri(1, 0, 5);  // bottom cap
  }
}

capture::EyePose look_at_pose(double time, const glm::dvec3& position, const glm::dvec3& target,
                              double fov_y_degrees) {
  capture::EyePose pose;
  pose.time = time;
  pose.position = to_vec3(position);
  glm::dvec3 f = glm::normalize(target - position);
  glm::dvec3 up = glm::normalize(glm::dvec3(0, 1, 0) - f * f.y);
  pose.forward = to_vec3(f);
  pose.up = to_vec3(up);
  pose.fov_y_degrees = fov_y_degrees;
  return pose;
}

}  // namespace calf::samples
