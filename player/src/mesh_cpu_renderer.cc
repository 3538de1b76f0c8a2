// The scalar CPU rasteriser of a mesh draw list: the reference the GL rasteriser is tested against
// (what it does is in mesh_renderer.h and mesh_draw_list.h).
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "calf/player/mesh_renderer.h"
#include "cpu_raster.h"
#include "mesh_texture_sampler.h"
#include "object_transform.h"

namespace calf::player {
namespace {

using internal::ViewProjector;
using internal::ViewVertex;

// Everything one triangle's pixels need.
struct TriangleShade {
  Vec3 p[3];        // eye-relative world positions
  Vec3 n[3];        // world normals (vertex normals through the normal matrix), or unused
  Vec3 colour[3];   // vertex colours (1 when none)
  double uv[3][2];  // vertex UVs, when textured
  const std::vector<mesh::TextureTexels>* texture = nullptr;  // its mip chain, or untextured
  Vec3 face;        // unnormalised face normal (p1 - p0) x (p2 - p0)
  double side = 1;  // -1 when the front faces away from the eye
  bool vertex_normals = false;
  const MeshDrawMaterial* material = nullptr;
};

struct Target {
  const Camera* camera;
  const CameraFrame* frame;
  const std::vector<Vec3>* rays;
  RenderedImage* out;
};

// The UV where ray `d` meets the triangle's plane (also outside the triangle), through the
// barycentric coordinates of the hit point.
void uv_on_plane(const TriangleShade& s, const Vec3& d, double* u, double* v) {
  const double dist = dot(s.face, s.p[0]) / dot(s.face, d);
  const Vec3 x = d * dist;
  const double nn = dot(s.face, s.face);
  const double l1 = dot(s.face, cross(x - s.p[0], s.p[2] - s.p[0])) / nn;
  const double l2 = dot(s.face, cross(s.p[1] - s.p[0], x - s.p[0])) / nn;
  const double l0 = 1 - l1 - l2;
  *u = s.uv[0][0] * l0 + s.uv[1][0] * l1 + s.uv[2][0] * l2;
  *v = s.uv[0][1] * l0 + s.uv[1][1] * l1 + s.uv[2][1] * l2;
}

// The texture's linear colour at pixel (i, j): UVs at the pixel centre, the level of detail from
// the UVs at the pixel's 2 x 2 quad (GL's coarse derivatives, mesh_draw_list.h).
Vec3 texture_at(const TriangleShade& s, const Target& t, const Vec3& d, uint32_t i, uint32_t j) {
  double u, v;
  uv_on_plane(s, d, &u, &v);
  const uint32_t qx = i & ~1u, qy = j & ~1u;
  double u00, v00, u10, v10, u01, v01;
  uv_on_plane(s, camera_ray(*t.camera, *t.frame, qx, qy), &u00, &v00);
  uv_on_plane(s, camera_ray(*t.camera, *t.frame, qx + 1, qy), &u10, &v10);
  uv_on_plane(s, camera_ray(*t.camera, *t.frame, qx, qy + 1), &u01, &v01);
  const auto& chain = *s.texture;
  const double lod =
      internal::mesh_texture_lod(chain[0], u10 - u00, v10 - v00, u01 - u00, v01 - v00);
  return internal::sample_mesh_texture(chain, u, v, lod);
}

void shade_pixel(const TriangleShade& s, const Target& t, uint32_t i, uint32_t j) {
  const size_t k = size_t{j} * t.camera->width + i;
  const Vec3& d = (*t.rays)[k];
  const double den = dot(s.face, d);
  if (den == 0) return;
  const double dist = dot(s.face, s.p[0]) / den;
  if (!(dist > 0)) return;
  const float depth = static_cast<float>(dist);
  if (!(depth < t.out->depth[k])) return;  // ties keep the first drawn
  const Vec3 x = d * dist;
  const double nn = dot(s.face, s.face);
  const double l1 = dot(s.face, cross(x - s.p[0], s.p[2] - s.p[0])) / nn;
  const double l2 = dot(s.face, cross(s.p[1] - s.p[0], x - s.p[0])) / nn;
  const double l0 = 1 - l1 - l2;
  const Vec3 normal = s.vertex_normals ? normalize(s.n[0] * l0 + s.n[1] * l1 + s.n[2] * l2) * s.side
                                       : normalize(s.face) * s.side;
  const Vec3 vc = s.colour[0] * l0 + s.colour[1] * l1 + s.colour[2] * l2;
  const Vec3 light{kMeshKeyLight[0], kMeshKeyLight[1], kMeshKeyLight[2]};
  const double lit = kMeshAmbient + (1 - double{kMeshAmbient}) * std::max(0.0, dot(normal, light));
  const MeshDrawMaterial& m = *s.material;
  const Vec3 tex = s.texture ? texture_at(s, t, d, i, j) : Vec3{1, 1, 1};
  const double c[3] = {vc.x * tex.x, vc.y * tex.y, vc.z * tex.z};
  t.out->depth[k] = depth;
  for (int ch = 0; ch < 3; ++ch) {
    t.out->color[3 * k + ch] = static_cast<float>(m.base_colour[ch] * c[ch] * lit + m.emission[ch]);
  }
}

}  // namespace

Status render_mesh_cpu(const MeshDrawList& list, const Camera& camera,
                       const MeshRenderOptions& options, RenderedImage* out) {
  CALF_RETURN_IF_ERROR(validate_camera(camera));
  CALF_RETURN_IF_ERROR(validate_mesh_render_options(options));
  CALF_RETURN_IF_ERROR(validate_mesh_draw_list(list));
  const uint32_t width = camera.width, height = camera.height;
  out->width = width;
  out->height = height;
  out->color.assign(size_t{3} * width * height, 0.0f);
  out->depth.assign(size_t{width} * height, std::numeric_limits<float>::infinity());
  const CameraFrame frame = camera_frame(camera);
  std::vector<Vec3> rays(size_t{width} * height);
  for (uint32_t j = 0; j < height; ++j) {
    for (uint32_t i = 0; i < width; ++i)
      rays[size_t{j} * width + i] = camera_ray(camera, frame, i, j);
  }
  const Target target{&camera, &frame, &rays, out};
  const ViewProjector project(camera);

  for (const MeshDrawObject& object : list.objects) {
    if (!object.visible) continue;
    const MeshDrawPrototype& proto = list.prototypes[object.prototype];
    const internal::ObjectTransform t(object.transform);
    const auto& r = t.r;
    // The eye-relative translation, and the normal matrix (inverse transpose = cofactors / det).
    const Vec3 offset = t.translation() - camera.position;
    const auto& cof = t.cof;
    const auto world = [&](uint32_t v) {
      const float* p = &proto.positions[3 * size_t{v}];
      return Vec3{r[0][0] * p[0] + r[0][1] * p[1] + r[0][2] * p[2],
                  r[1][0] * p[0] + r[1][1] * p[1] + r[1][2] * p[2],
                  r[2][0] * p[0] + r[2][1] * p[1] + r[2][2] * p[2]} +
             offset;
    };
    const auto normal = [&](uint32_t v) {
      const float* n = &proto.normals[3 * size_t{v}];
      return Vec3{cof[0][0] * n[0] + cof[0][1] * n[1] + cof[0][2] * n[2],
                  cof[1][0] * n[0] + cof[1][1] * n[1] + cof[1][2] * n[2],
                  cof[2][0] * n[0] + cof[2][1] * n[1] + cof[2][2] * n[2]};
    };
    const size_t count = object.drawn_triangles(proto);
    for (size_t q = 0; q < count; ++q) {
      const uint32_t tri = object.all_triangles ? static_cast<uint32_t>(q) : object.triangles[q];
      TriangleShade s;
      s.vertex_normals = !proto.normals.empty();
      std::array<ViewVertex, 3> view;
      for (int c = 0; c < 3; ++c) {
        const uint32_t v = proto.indices[3 * size_t{tri} + c];
        s.p[c] = world(v);
        if (s.vertex_normals) s.n[c] = normal(v);
        s.colour[c] = proto.colours.empty()
                          ? Vec3{1, 1, 1}
                          : Vec3{proto.colours[3 * size_t{v}], proto.colours[3 * size_t{v} + 1],
                                 proto.colours[3 * size_t{v} + 2]};
        view[c] = {dot(s.p[c], frame.right), dot(s.p[c], frame.up), dot(s.p[c], frame.forward)};
      }
      s.face = cross(s.p[1] - s.p[0], s.p[2] - s.p[0]);
      if (!(length(s.face) > 0)) continue;  // degenerate: covers nothing
      s.side = dot(s.face, s.p[0]) > 0 ? -1 : 1;
      const uint32_t own =
          proto.triangle_materials.empty() ? kMeshObjectMaterial : proto.triangle_materials[tri];
      s.material = &list.materials[own == kMeshObjectMaterial ? object.material : own];
      if (s.material->base_colour_texture != kMeshNoTexture && !proto.uvs.empty()) {
        s.texture = &list.textures[s.material->base_colour_texture];
        for (int c = 0; c < 3; ++c) {
          const uint32_t v = proto.indices[3 * size_t{tri} + c];
          s.uv[c][0] = proto.uvs[2 * size_t{v}];
          s.uv[c][1] = proto.uvs[2 * size_t{v} + 1];
        }
      }
      internal::rasterise_clipped(view, options.near, project, width, height,
                                  [&](uint32_t i, uint32_t j) { shade_pixel(s, target, i, j); });
    }
  }
  return Status::Ok();
}

}  // namespace calf::player
