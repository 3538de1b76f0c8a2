// The scalar CPU splatter of a surfel draw list: the reference the GL splatter is tested against
// (what it does is in surfel_renderer.h and surfel_draw_list.h).
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "calf/player/mesh_draw_list.h"
#include "calf/player/surfel_renderer.h"
#include "object_transform.h"

namespace calf::player {
namespace {

// A point in the camera's frame: x along right, y along up, z along forward (eye at 0).
struct ViewPoint {
  double x, y, z;
};

// Sutherland-Hodgman of a convex polygon against z >= near: the clipped vertices (up to 5 for 4).
int clip_near(const std::array<ViewPoint, 4>& in, double near, std::array<ViewPoint, 8>* out) {
  int n = 0;
  for (int i = 0; i < 4; ++i) {
    const ViewPoint& a = in[i];
    const ViewPoint& b = in[(i + 1) % 4];
    const bool a_in = a.z >= near, b_in = b.z >= near;
    if (a_in) (*out)[n++] = a;
    if (a_in != b_in) {
      const double s = (near - a.z) / (b.z - a.z);
      (*out)[n++] = {a.x + s * (b.x - a.x), a.y + s * (b.y - a.y), near};
    }
  }
  return n;
}

}  // namespace

Status render_surfels_cpu(const SurfelDrawList& list, const Camera& camera,
                          const SurfelRenderOptions& options, RenderedImage* out) {
  CALF_RETURN_IF_ERROR(validate_camera(camera));
  CALF_RETURN_IF_ERROR(validate_surfel_render_options(options));
  CALF_RETURN_IF_ERROR(validate_surfel_draw_list(list));
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
  const double h = std::tan(camera.fov_y / 2);
  const double aspect = static_cast<double>(width) / height;
  const Vec3 light{kMeshKeyLight[0], kMeshKeyLight[1], kMeshKeyLight[2]};

  for (const SurfelDrawObject& object : list.objects) {
    const SurfelDrawPrototype& proto = list.prototypes[object.prototype];
    const internal::ObjectTransform t(object.transform);
    const Vec3 offset = t.translation() - camera.position;
    for (uint32_t s = 0; s < object.count; ++s) {
      const float* p = &proto.positions[3 * size_t{s}];
      const float* pn = &proto.normals[3 * size_t{s}];
      const Vec3 n_obj{pn[0], pn[1], pn[2]};
      Vec3 u, v;
      surfel_tangents(n_obj, &u, &v);
      const Vec3 c = t.linear(Vec3{p[0], p[1], p[2]}) + offset;  // eye-relative centre
      const Vec3 du = t.linear(u * object.radius), dv = t.linear(v * object.radius);
      const Vec3 plane = cross(du, dv);  // the disc's world normal, unnormalised
      const double uu = dot(du, du), uv = dot(du, dv), vv = dot(dv, dv);
      const double gram = uu * vv - uv * uv;
      if (!(gram > 0)) continue;
      // The bounding parallelogram in the camera's frame, near-clipped, projected.
      std::array<ViewPoint, 4> corners;
      const double sa[4] = {-1, 1, 1, -1}, sb[4] = {-1, -1, 1, 1};
      for (int k = 0; k < 4; ++k) {
        const Vec3 q = c + du * sa[k] + dv * sb[k];
        corners[k] = {dot(q, frame.right), dot(q, frame.up), dot(q, frame.forward)};
      }
      std::array<ViewPoint, 8> poly;
      const int m = clip_near(corners, options.near, &poly);
      if (m < 3) continue;
      double x0 = std::numeric_limits<double>::infinity(), x1 = -x0, y0 = x0, y1 = -x0;
      for (int k = 0; k < m; ++k) {
        const double ix = (poly[k].x / (poly[k].z * h * aspect) + 1) * 0.5 * width;
        const double iy = (1 - poly[k].y / (poly[k].z * h)) * 0.5 * height;
        x0 = std::min(x0, ix);
        x1 = std::max(x1, ix);
        y0 = std::min(y0, iy);
        y1 = std::max(y1, iy);
      }
      // Pixel centres i + 0.5 within the bounds.
      const double i0 = std::max(0.0, std::ceil(x0 - 0.5)),
                   i1 = std::min(width - 1.0, std::floor(x1 - 0.5));
      const double j0 = std::max(0.0, std::ceil(y0 - 0.5)),
                   j1 = std::min(height - 1.0, std::floor(y1 - 0.5));
      if (!(i0 <= i1 && j0 <= j1)) continue;
      const float* pc = &proto.colours[3 * size_t{s}];
      const double num = dot(plane, c);
      for (double jj = j0; jj <= j1; ++jj) {
        for (double ii = i0; ii <= i1; ++ii) {
          const size_t k = static_cast<size_t>(jj) * width + static_cast<size_t>(ii);
          const Vec3& d = rays[k];
          const double den = dot(plane, d);
          if (den == 0) continue;  // edge-on
          const double dist = num / den;
          if (!(dist > 0)) continue;
          const Vec3 x = d * dist;
          if (!(dot(x, frame.forward) >= options.near)) continue;
          const float depth = static_cast<float>(dist);
          if (!(depth < out->depth[k])) continue;  // ties keep the first drawn
          // x - c = a U + b V: the 2 x 2 normal equations.
          const Vec3 e = x - c;
          const double eu = dot(e, du), ev = dot(e, dv);
          const double a = (eu * vv - ev * uv) / gram, b = (ev * uu - eu * uv) / gram;
          if (!(a * a + b * b <= 1)) continue;
          Vec3 normal = normalize(plane);
          if (dot(normal, x) > 0) normal = -normal;  // the side the eye sees
          const double lit =
              kMeshAmbient + (1 - double{kMeshAmbient}) * std::max(0.0, dot(normal, light));
          out->depth[k] = depth;
          for (int ch = 0; ch < 3; ++ch) {
            out->color[3 * k + ch] = static_cast<float>(object.tint[ch] * pc[ch] * lit);
          }
        }
      }
    }
  }
  return Status::Ok();
}

}  // namespace calf::player
