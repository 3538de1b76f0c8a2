// The one camera model of calf: a perspective pinhole camera with an image size. Ground truth
// (calf-capture), both renderers (CPU reference and GL), image comparison, capture views and
// culling all place pixels with it, so a reconstruction and the ground truth for the same pose
// align pixel for pixel (format/CAPTURE.md, "Eye paths", states the same model for files).
//
// Convention (OpenGL): the camera looks along `forward`; image row 0 is the top (towards `up`),
// column 0 the left. The camera frame is
//   f = normalize(forward),  r = normalize(cross(f, up)),  u = cross(r, f)
// (normalize(v) = v * (1 / |v|), calf/format/geometry.h), and the ray through pixel (i, j) of a
// W x H image is
//   d = normalize(f + r * (a * h * (W / H)) + u * (b * h)),
//   a = 2 (i + 0.5) / W - 1,  b = 1 - 2 (j + 0.5) / H,  h = tan(fov_y / 2),
// evaluated in exactly that order (left to right, products as bracketed), so every caller gets
// the same doubles. Depth along a ray is the radial distance from `position` (like cube maps).
//
// An eye-path pose (calf/capture/eye_path.h) becomes a Camera with capture::camera_from_pose().
#pragma once

#include <cstdint>

#include "calf/format/geometry.h"
#include "calf/format/status.h"

namespace calf {

// The largest image side a camera may have, in pixels.
inline constexpr uint32_t kMaxCameraImageSize = 16384;

struct Camera {
  Vec3 position;
  Vec3 forward{0, 0, -1};             // need not be unit length; not parallel to up
  Vec3 up{0, 1, 0};                   // re-orthogonalised against forward
  double fov_y = 1.5707963267948966;  // vertical field of view in radians, (0, pi)
  uint32_t width = 64, height = 64;   // pixels, 1..kMaxCameraImageSize each
  friend bool operator==(const Camera&, const Camera&) = default;
};

// The orthonormal frame of a camera (unit forward, right, up; right-handed: right = f x up).
struct CameraFrame {
  Vec3 forward, right, up;
};

// CALF-E403 (ErrorId::kPlayerOptions) unless `camera` is usable, with the first reason found:
//   "camera position, forward or up is not finite, zero or parallel"  (a non-finite component,
//       forward of length 0, or |cross(f, up)| <= 1e-12 * max(1, |up|))
//   "camera fov_y <value> is outside (0, pi)"
//   "image size <W> x <H> is outside 1..16384"
[[nodiscard]] Status validate_camera(const Camera& camera);

// The frame f, r, u of the formula above. The camera must pass validate_camera() (otherwise the
// result holds NaNs or infinities).
CameraFrame camera_frame(const Camera& camera);

// The unit ray direction through pixel (i, j) of `camera` (formula above). The camera must pass
// validate_camera(). Computes the frame each call; loops over pixels may call the overload
// taking the frame once computed, which gives the same doubles.
Vec3 camera_ray(const Camera& camera, uint32_t i, uint32_t j);
Vec3 camera_ray(const Camera& camera, const CameraFrame& frame, uint32_t i, uint32_t j);

// The unit ray direction through the continuous image position (x, y): x in [0, width] from the
// left edge, y in [0, height] from the top edge, so pixel (i, j)'s centre is (i + 0.5, j + 0.5)
// and camera_ray(camera, frame, i, j) is exactly camera_ray_at(camera, frame, i + 0.5, j + 0.5).
// Sub-pixel samples (a renderer's supersampling) use it.
Vec3 camera_ray_at(const Camera& camera, const CameraFrame& frame, double x, double y);

// The viewing frustum of `camera` between distances `near` and `far` along its forward axis
// (0 < near < far): aspect = W / H, the same frame and field of view, so the frustum's edges are
// the image's edges (its corners lie on the rays through the image corners, not pixel centres).
EyeView eye_view(const Camera& camera, double near, double far);
// eye_frustum(eye_view(camera, near, far)).
Frustum camera_frustum(const Camera& camera, double near, double far);

}  // namespace calf
