// Validation of a surfel draw list and the disc tangents (rules in surfel_draw_list.h).
#include "calf/player/surfel_draw_list.h"

#include <cmath>
#include <string>

#include "object_transform.h"

namespace calf::player {
namespace {

Status list_error(const std::string& what) {
  return Status(ErrorId::kSurfelDrawList, what);
}

Status check_prototype(const SurfelDrawPrototype& p, size_t index) {
  const std::string name = "surfel prototype " + std::to_string(index);
  if (p.positions.size() % 3 != 0 || p.normals.size() != p.positions.size() ||
      p.colours.size() != p.positions.size()) {
    return list_error(name + ": " + std::to_string(p.positions.size()) + " position, " +
                      std::to_string(p.normals.size()) + " normal and " +
                      std::to_string(p.colours.size()) +
                      " colour floats, not 3 of each per surfel");
  }
  for (size_t s = 0; s < p.surfel_count(); ++s) {
    const float* x = &p.positions[3 * s];
    const float* n = &p.normals[3 * s];
    const float* c = &p.colours[3 * s];
    for (int k = 0; k < 3; ++k) {
      if (!std::isfinite(x[k]) || !std::isfinite(n[k]) || !(std::isfinite(c[k]) && c[k] >= 0)) {
        return list_error(name + ", surfel " + std::to_string(s) +
                          ": a position, normal or colour is not finite (or a colour < 0)");
      }
    }
    const double len = std::sqrt(double{n[0]} * n[0] + double{n[1]} * n[1] + double{n[2]} * n[2]);
    if (!(std::abs(len - 1) <= 1e-3)) {
      return list_error(name + ", surfel " + std::to_string(s) + ": normal of length " +
                        std::to_string(len) + ", not 1");
    }
  }
  return Status::Ok();
}

Status check_object(const SurfelDrawObject& o, size_t index, const SurfelDrawList& list) {
  const std::string name = "surfel object " + std::to_string(index);
  if (o.prototype >= list.prototypes.size()) {
    return list_error(name + ": prototype " + std::to_string(o.prototype) + " >= prototype count " +
                      std::to_string(list.prototypes.size()));
  }
  const size_t n = list.prototypes[o.prototype].surfel_count();
  if (o.count > n) {
    return list_error(name + ": prefix of " + std::to_string(o.count) + " surfels > the " +
                      std::to_string(n) + " of prototype " + std::to_string(o.prototype));
  }
  if (o.count > 0 && !(std::isfinite(o.radius) && o.radius > 0)) {
    return list_error(name + ": disc radius " + std::to_string(o.radius) +
                      " is not finite and > 0");
  }
  for (float x : o.transform) {
    if (!std::isfinite(x)) return list_error(name + ": the transform is not finite");
  }
  for (float x : o.tint) {
    if (!(std::isfinite(x) && x >= 0))
      return list_error(name + ": a tint is negative or not finite");
  }
  if (!(std::abs(internal::ObjectTransform(o.transform).det) > 1e-30)) {
    return list_error(name + ": the transform is singular");
  }
  return Status::Ok();
}

}  // namespace

void surfel_tangents(const Vec3& n, Vec3* u, Vec3* v) {
  const double ax = std::abs(n.x), ay = std::abs(n.y), az = std::abs(n.z);
  Vec3 e{0, 0, 1};
  if (ax <= ay && ax <= az) {
    e = {1, 0, 0};
  } else if (ay <= az) {
    e = {0, 1, 0};
  }
  *u = normalize(cross(n, e));
  *v = cross(n, *u);
}

Status validate_surfel_draw_list(const SurfelDrawList& list) {
  for (size_t p = 0; p < list.prototypes.size(); ++p) {
    CALF_RETURN_IF_ERROR(check_prototype(list.prototypes[p], p));
  }
  for (size_t o = 0; o < list.objects.size(); ++o) {
    CALF_RETURN_IF_ERROR(check_object(list.objects[o], o, list));
  }
  return Status::Ok();
}

Status validate_surfel_render_options(const SurfelRenderOptions& options) {
  if (!(std::isfinite(options.near) && options.near > 0)) {
    return Status(
        ErrorId::kSurfelRenderOptions,
        "surfel near distance " + std::to_string(options.near) + " is not finite and > 0");
  }
  return Status::Ok();
}

uint64_t surfel_draw_count(const SurfelDrawList& list) {
  uint64_t n = 0;
  for (const SurfelDrawObject& o : list.objects) n += o.count;
  return n;
}

}  // namespace calf::player
