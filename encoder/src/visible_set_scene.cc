// The visible-set builder's view of a scene file: primitives numbered once, the world geometry of
// a frame, the checks every entry point shares and the per-object result.
#include <algorithm>
#include <cmath>
#include <string>
#include <tuple>
#include <vector>

#include "calf/encoder/sphere_mesh.h"
#include "visible_set_internal.h"

namespace calf::encoder::visibility {
namespace {

Vec3 apply(const capture::SceneTransform& m, double x, double y, double z) {
  return {m[0] * x + m[1] * y + m[2] * z + m[3], m[4] * x + m[5] * y + m[6] * z + m[7],
          m[8] * x + m[9] * y + m[10] * z + m[11]};
}

double largest_side(const Box3& b) {
  return std::max({b.max.x - b.min.x, b.max.y - b.min.y, b.max.z - b.min.z});
}

}  // namespace

PrimitiveTable number_primitives(const capture::SceneFile& scene) {
  PrimitiveTable t;
  t.base.reserve(scene.objects.size() + 1);
  t.base.push_back(0);
  for (const capture::SceneObject& o : scene.objects) {
    const capture::SceneMesh& mesh = scene.meshes[o.mesh];
    t.mesh_triangles.push_back(static_cast<uint32_t>(mesh.triangle_count()));
    t.base.push_back(t.base.back() + mesh.triangle_count() + mesh.spheres.size());
  }
  return t;
}

void build_frame(const capture::SceneFile& scene, const PrimitiveTable& table, uint32_t frame,
                 FrameGeometry* out) {
  out->vertices.clear();
  out->triangles.clear();
  out->spheres.clear();
  // Sized once: a 5 M triangle field grown by push_back spent as long in reallocation and page
  // faults as in the transforms, every frame.
  out->vertices.reserve(3 * (table.count()));
  out->triangles.reserve(table.count());
  const double time = frame / scene.fps;
  // Vertex positions per mesh at this time, computed once for all its instances.
  std::vector<std::vector<float>> positions(scene.meshes.size());
  std::vector<uint8_t> done(scene.meshes.size(), 0);
  std::vector<Vec3> world;
  bool any = false;
  for (size_t o = 0; o < scene.objects.size(); ++o) {
    const capture::SceneObject& object = scene.objects[o];
    const capture::SceneMesh& mesh = scene.meshes[object.mesh];
    if (!done[object.mesh]) {
      capture::positions_at(mesh, time, &positions[object.mesh]);
      done[object.mesh] = 1;
    }
    const std::vector<float>& p = positions[object.mesh];
    const capture::SceneTransform& m = capture::transform_at(object, frame);
    // Each vertex transformed once, so corners shared by triangles get the same bits.
    world.resize(mesh.vertex_count());
    for (size_t v = 0; v < world.size(); ++v)
      world[v] = apply(m, p[3 * v], p[3 * v + 1], p[3 * v + 2]);
    const uint64_t base = table.base[o];
    for (size_t tri = 0; tri < mesh.triangle_count(); ++tri) {
      for (int k = 0; k < 3; ++k) {
        const Vec3& c = world[mesh.indices[3 * tri + k]];
        out->vertices.push_back(c);
        if (!any) out->bounds = Box3{c, c};
        any = true;
        Box3& b = out->bounds;
        b.min = {std::min(b.min.x, c.x), std::min(b.min.y, c.y), std::min(b.min.z, c.z)};
        b.max = {std::max(b.max.x, c.x), std::max(b.max.y, c.y), std::max(b.max.z, c.z)};
      }
      out->triangles.push_back(static_cast<uint32_t>(base + tri));
    }
    const double det = m[0] * (m[5] * m[10] - m[6] * m[9]) - m[1] * (m[4] * m[10] - m[6] * m[8]) +
                       m[2] * (m[4] * m[9] - m[5] * m[8]);
    const double scale = std::cbrt(std::fabs(det));
    for (size_t s = 0; s < mesh.spheres.size(); ++s) {
      const capture::SceneSphere& sphere = mesh.spheres[s];
      WorldSphere w;
      w.centre = apply(m, sphere.center[0], sphere.center[1], sphere.center[2]);
      w.radius = sphere.radius * scale;
      w.primitive = static_cast<uint32_t>(base + mesh.triangle_count() + s);
      const Vec3 r{w.radius, w.radius, w.radius};
      const Box3 box{w.centre - r, w.centre + r};
      out->bounds = any ? box_union(out->bounds, box) : box;
      any = true;
      out->spheres.push_back(w);
    }
  }
  if (!any) out->bounds = Box3{};
}

Expected<Prepared> prepare(const capture::SceneFile& scene, const VisibleSetOptions& options) {
  if (options.face_size == 0 || options.face_size > kVisibleSetMaxFaceSize)
    return Status(ErrorId::kVisibleSetOption, "face_size " + std::to_string(options.face_size) +
                                                  " is outside 1.." +
                                                  std::to_string(kVisibleSetMaxFaceSize));
  if (options.threads > 256)
    return Status(ErrorId::kVisibleSetOption,
                  "threads " + std::to_string(options.threads) + " is above 256");
  if (!(options.min_interval >= 0 && options.min_interval < 1))
    return Status(ErrorId::kVisibleSetOption,
                  "min_interval " + std::to_string(options.min_interval) + " is outside [0, 1)");
  if (scene.frame_count == 0 || options.first_frame >= scene.frame_count)
    return Status(ErrorId::kVisibleSetOption, "first_frame " + std::to_string(options.first_frame) +
                                                  " is not below the " + "scene's frame count " +
                                                  std::to_string(scene.frame_count));
  // Hostile values never reach the arithmetic: the scene must keep SCENE.md's rules (E150-E161).
  CALF_RETURN_IF_ERROR(capture::validate_scene_file(scene));
  for (size_t o = 0; o < scene.objects.size(); ++o)
    if (scene.objects[o].mesh >= scene.meshes.size())
      return Status(ErrorId::kVisibleSetScene, "object " + std::to_string(o) + " ('" +
                                                   scene.objects[o].name + "') names mesh " +
                                                   std::to_string(scene.objects[o].mesh) + " of " +
                                                   std::to_string(scene.meshes.size()));
  Prepared out;
  out.table = number_primitives(scene);
  if (out.table.count() == 0)
    return Status(ErrorId::kVisibleSetScene, "scene '" + scene.name +
                                                 "' has no triangle and no sphere in any of its " +
                                                 std::to_string(scene.objects.size()) + " objects");
  if (out.table.count() > (uint64_t{1} << 31))
    return Status(ErrorId::kVisibleSetLimit, "scene '" + scene.name + "' has " +
                                                 std::to_string(out.table.count()) +
                                                 " primitives, more than 2^31");
  const uint32_t last =
      options.frames == 0 ? scene.frame_count
                          : static_cast<uint32_t>(std::min<uint64_t>(
                                scene.frame_count, uint64_t{options.first_frame} + options.frames));
  FrameGeometry previous, current;
  bool any = false;
  for (uint32_t f = options.first_frame; f < last; ++f) {
    build_frame(scene, out.table, f, &current);
    if (!out.frames.empty() && current == previous) continue;
    out.frames.push_back(f);
    out.bounds = any ? box_union(out.bounds, current.bounds) : current.bounds;
    any = true;
    std::swap(previous, current);
  }
  for (const Vec3& c : {out.bounds.min, out.bounds.max})
    if (!is_finite(c))
      return Status(ErrorId::kVisibleSetScene,
                    "scene '" + scene.name + "' has geometry that is not finite once transformed");
  const double side = largest_side(out.bounds);
  out.delta = 1e-9 * std::max(side, 1e-300);
  return out;
}

// The box is the bounds grown by twice their largest side: every rig calf-capture gives a model
// (a ring of radius 2 x the half-diagonal <= sqrt(3) x the largest side around the centre) lies
// inside it, elongated models included, while a point thousands of scene sizes away, where the
// projections lose their precision, is still refused.
Status check_point(const Prepared& prepared, const Vec3& p, const std::string& what) {
  const double side = largest_side(prepared.bounds);
  const Vec3 grow{2 * side, 2 * side, 2 * side};
  const Box3 box{prepared.bounds.min - grow, prepared.bounds.max + grow};
  if (is_finite(p) && box.contains(p)) return Status::Ok();
  auto str = [](const Vec3& v) {
    char buf[96];
    std::snprintf(buf, sizeof buf, "(%.6g, %.6g, %.6g)", v.x, v.y, v.z);
    return std::string(buf);
  };
  return Status(ErrorId::kVisibleSetOutside,
                what + " " + str(p) + " lies outside the scene bounds " + str(prepared.bounds.min) +
                    " .. " + str(prepared.bounds.max) + " grown by twice their largest side " +
                    std::to_string(side));
}

void collect(const capture::SceneFile& scene, const PrimitiveTable& table,
             const std::vector<uint8_t>& visible, bool object_granularity, VisibleSet* out) {
  out->triangles.assign(scene.objects.size(), {});
  out->stats.scene_triangles = 0;
  out->stats.visible_triangles = 0;
  for (size_t o = 0; o < scene.objects.size(); ++o) {
    const uint64_t base = table.base[o];
    const uint32_t t = table.mesh_triangles[o];
    const uint64_t spheres = table.base[o + 1] - base - t;
    const uint64_t all = t + spheres * kSphereTriangles;
    out->stats.scene_triangles += all;
    std::vector<uint32_t>& list = out->triangles[o];
    bool any = false;
    for (uint64_t p = base; p < table.base[o + 1] && !any; ++p) any = visible[p] != 0;
    if (!any) continue;
    if (object_granularity) {
      list.resize(all);
      for (uint64_t i = 0; i < all; ++i) list[i] = static_cast<uint32_t>(i);
    } else {
      for (uint32_t i = 0; i < t; ++i)
        if (visible[base + i]) list.push_back(i);
      for (uint64_t s = 0; s < spheres; ++s)
        if (visible[base + t + s])
          for (uint32_t k = 0; k < kSphereTriangles; ++k)
            list.push_back(static_cast<uint32_t>(t + s * kSphereTriangles + k));
    }
    out->stats.visible_triangles += list.size();
  }
}

bool better_witness(const VisibilityWitness& a, const VisibilityWitness& b) {
  const double la = a.s1 - a.s0, lb = b.s1 - b.s0;
  if (la != lb) return la > lb;
  return std::tie(a.segment, a.frame, a.face, a.y, a.x) <
         std::tie(b.segment, b.frame, b.face, b.y, b.x);
}

}  // namespace calf::encoder::visibility
