// Validation of a mesh draw list (rules in mesh_draw_list.h).
#include "calf/player/mesh_draw_list.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "object_transform.h"

namespace calf::player {
namespace {

Status list_error(const std::string& what) {
  return Status(ErrorId::kMeshDrawList, what);
}

bool all_finite(const std::vector<float>& v) {
  for (float x : v) {
    if (!std::isfinite(x)) return false;
  }
  return true;
}

Status check_prototype(const MeshDrawPrototype& p, size_t index, size_t material_count) {
  const std::string name = "prototype " + std::to_string(index);
  if (p.positions.size() % 3 != 0) {
    return list_error(name + ": " + std::to_string(p.positions.size()) +
                      " position floats, not 3 per vertex");
  }
  const size_t n = p.vertex_count();
  if (!p.normals.empty() && p.normals.size() != 3 * n) {
    return list_error(name + ": " + std::to_string(p.normals.size()) + " normal floats for " +
                      std::to_string(n) + " vertices");
  }
  if (!p.colours.empty() && p.colours.size() != 3 * n) {
    return list_error(name + ": " + std::to_string(p.colours.size()) + " colour floats for " +
                      std::to_string(n) + " vertices");
  }
  if (!p.uvs.empty() && p.uvs.size() != 2 * n) {
    return list_error(name + ": " + std::to_string(p.uvs.size()) + " uv floats for " +
                      std::to_string(n) + " vertices");
  }
  if (!all_finite(p.uvs)) return list_error(name + ": a uv is not finite");
  if (p.indices.size() % 3 != 0) {
    return list_error(name + ": " + std::to_string(p.indices.size()) +
                      " indices, not 3 per triangle");
  }
  if (!all_finite(p.positions) || !all_finite(p.normals) || !all_finite(p.colours)) {
    return list_error(name + ": a position, normal or colour is not finite");
  }
  for (size_t i = 0; i < p.indices.size(); ++i) {
    if (p.indices[i] >= n) {
      return list_error(name + ", triangle " + std::to_string(i / 3) + ": vertex index " +
                        std::to_string(p.indices[i]) + " >= vertex count " + std::to_string(n));
    }
  }
  if (!p.triangle_materials.empty()) {
    if (p.triangle_materials.size() != p.triangle_count()) {
      return list_error(name + ": " + std::to_string(p.triangle_materials.size()) +
                        " triangle materials for " + std::to_string(p.triangle_count()) +
                        " triangles");
    }
    for (size_t t = 0; t < p.triangle_materials.size(); ++t) {
      if (p.triangle_materials[t] >= material_count &&
          p.triangle_materials[t] != kMeshObjectMaterial) {
        return list_error(name + ", triangle " + std::to_string(t) + ": material " +
                          std::to_string(p.triangle_materials[t]) + " >= material count " +
                          std::to_string(material_count));
      }
    }
  }
  return Status::Ok();
}

Status check_object(const MeshDrawObject& o, size_t index, const MeshDrawList& list) {
  const std::string name = "object " + std::to_string(index);
  if (o.prototype >= list.prototypes.size()) {
    return list_error(name + ": prototype " + std::to_string(o.prototype) + " >= prototype count " +
                      std::to_string(list.prototypes.size()));
  }
  if (o.material >= list.materials.size()) {
    return list_error(name + ": material " + std::to_string(o.material) + " >= material count " +
                      std::to_string(list.materials.size()));
  }
  for (float x : o.transform) {
    if (!std::isfinite(x)) return list_error(name + ": the transform is not finite");
  }
  // The 3 x 3 part's determinant, in double: a singular transform has no normal matrix.
  const double det = internal::ObjectTransform(o.transform).det;
  if (!(std::abs(det) > 1e-30)) return list_error(name + ": the transform is singular");
  if (!o.all_triangles) {
    const size_t count = list.prototypes[o.prototype].triangle_count();
    for (size_t i = 0; i < o.triangles.size(); ++i) {
      if (o.triangles[i] >= count) {
        return list_error(name + ": subset triangle " + std::to_string(o.triangles[i]) +
                          " >= the prototype's triangle count " + std::to_string(count));
      }
      if (i > 0 && o.triangles[i] <= o.triangles[i - 1]) {
        return list_error(name + ": subset triangle " + std::to_string(o.triangles[i]) +
                          " does not increase (after " + std::to_string(o.triangles[i - 1]) + ")");
      }
    }
  }
  return Status::Ok();
}

Status check_texture(const std::vector<mesh::TextureTexels>& chain, size_t index) {
  const std::string name = "texture " + std::to_string(index);
  if (chain.empty() || chain[0].width == 0 || chain[0].height == 0 ||
      chain.size() != mesh::mip_level_count(chain[0].width, chain[0].height)) {
    return list_error(name + ": not a whole mip chain");
  }
  for (size_t k = 0; k < chain.size(); ++k) {
    const mesh::TextureTexels& l = chain[k];
    const uint32_t w = std::max(1u, chain[0].width >> k), h = std::max(1u, chain[0].height >> k);
    if (l.width != w || l.height != h || l.rgba.size() != size_t{4} * w * h) {
      return list_error(name + ", level " + std::to_string(k) + ": " + std::to_string(l.width) +
                        " x " + std::to_string(l.height) + " with " +
                        std::to_string(l.rgba.size()) + " bytes, expected " + std::to_string(w) +
                        " x " + std::to_string(h));
    }
  }
  return Status::Ok();
}

}  // namespace

Status validate_mesh_draw_list(const MeshDrawList& list) {
  for (size_t t = 0; t < list.textures.size(); ++t) {
    CALF_RETURN_IF_ERROR(check_texture(list.textures[t], t));
  }
  for (size_t m = 0; m < list.materials.size(); ++m) {
    const uint32_t tex = list.materials[m].base_colour_texture;
    if (tex != kMeshNoTexture && tex >= list.textures.size()) {
      return list_error("material " + std::to_string(m) + ": texture " + std::to_string(tex) +
                        " >= texture count " + std::to_string(list.textures.size()));
    }
    for (int c = 0; c < 3; ++c) {
      const float b = list.materials[m].base_colour[c], e = list.materials[m].emission[c];
      if (!(std::isfinite(b) && b >= 0 && std::isfinite(e) && e >= 0)) {
        return list_error("material " + std::to_string(m) + ": a colour is negative or not finite");
      }
    }
  }
  for (size_t p = 0; p < list.prototypes.size(); ++p) {
    CALF_RETURN_IF_ERROR(check_prototype(list.prototypes[p], p, list.materials.size()));
  }
  for (size_t o = 0; o < list.objects.size(); ++o) {
    CALF_RETURN_IF_ERROR(check_object(list.objects[o], o, list));
  }
  return Status::Ok();
}

Status validate_mesh_render_options(const MeshRenderOptions& options) {
  if (!(std::isfinite(options.near) && options.near > 0)) {
    return Status(ErrorId::kMeshRenderOptions,
                  "mesh near distance " + std::to_string(options.near) + " is not finite and > 0");
  }
  return Status::Ok();
}

uint64_t mesh_draw_triangle_count(const MeshDrawList& list) {
  uint64_t n = 0;
  for (const MeshDrawObject& o : list.objects) {
    if (o.visible) n += o.drawn_triangles(list.prototypes[o.prototype]);
  }
  return n;
}

}  // namespace calf::player
