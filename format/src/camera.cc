#include "calf/format/camera.h"

#include <algorithm>
#include <string>

namespace calf {
namespace {

Status camera_error(const std::string& what) {
  return Status(ErrorId::kPlayerOptions, what);
}

}  // namespace

Status validate_camera(const Camera& c) {
  if (!is_finite(c.position) || !view_axes_usable(c.forward, c.up))
    return camera_error("camera position, forward or up is not finite, zero or parallel");
  if (!(c.fov_y > 0) || !(c.fov_y < 3.141592653589793)) {
    return camera_error("camera fov_y " + std::to_string(c.fov_y) + " is outside (0, pi)");
  }
  if (c.width < 1 || c.height < 1 || c.width > kMaxCameraImageSize ||
      c.height > kMaxCameraImageSize) {
    return camera_error("image size " + std::to_string(c.width) + " x " + std::to_string(c.height) +
                        " is outside 1..16384");
  }
  return Status::Ok();
}

CameraFrame camera_frame(const Camera& c) {
  CameraFrame frame;
  frame.forward = normalize(c.forward);
  frame.right = normalize(cross(frame.forward, c.up));
  frame.up = cross(frame.right, frame.forward);
  return frame;
}

Vec3 camera_ray(const Camera& camera, const CameraFrame& frame, uint32_t i, uint32_t j) {
  return camera_ray_at(camera, frame, i + 0.5, j + 0.5);
}

Vec3 camera_ray_at(const Camera& camera, const CameraFrame& frame, double x, double y) {
  const double h = std::tan(camera.fov_y / 2);
  const double a = 2.0 * x / camera.width - 1.0;
  const double b = 1.0 - 2.0 * y / camera.height;
  const double aspect = static_cast<double>(camera.width) / camera.height;
  return normalize(frame.forward + frame.right * (a * h * aspect) + frame.up * (b * h));
}

Vec3 camera_ray(const Camera& camera, uint32_t i, uint32_t j) {
  return camera_ray(camera, camera_frame(camera), i, j);
}

EyeView eye_view(const Camera& camera, double near, double far) {
  EyeView v;
  v.position = camera.position;
  v.forward = camera.forward;
  v.up = camera.up;
  v.fov_y = camera.fov_y;
  v.aspect = static_cast<double>(camera.width) / camera.height;
  v.near = near;
  v.far = far;
  return v;
}

Frustum camera_frustum(const Camera& camera, double near, double far) {
  return eye_frustum(eye_view(camera, near, far));
}

}  // namespace calf
