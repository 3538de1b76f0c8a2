// Eye paths and ground-truth images (format/CAPTURE.md, "Eye paths").
//
// An eye path is a list of perspective camera poses over time: where a viewer is, where it looks,
// with which field of view, and for stereo which eye. calf-capture renders ground truth along one
// (colour + radial depth per pose); the player renders its reconstruction along the same path and
// compares. A pose is a calf::Camera (calf/format/camera.h, the one camera model: ray formula,
// row 0 at the top towards `up`) with the path's image size: camera_from_pose(). The depth stored
// for a pixel is the radial distance from `position` along its ray (like cube maps).
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "calf/capture/capture_set.h"
#include "calf/format/camera.h"
#include "calf/format/status.h"

namespace calf::capture {

enum class Eye : uint8_t { kMono, kLeft, kRight };
// "mono", "left", "right".
const char* eye_name(Eye eye);

// One pose. forward and up are unit length and orthogonal after parsing (up is re-orthogonalised
// against forward).
struct EyePose {
  double time = 0;  // seconds of scene time (frame f of a capture is at f / fps)
  Vec3 position;
  Vec3 forward{0, 0, -1};
  Vec3 up{0, 1, 0};
  double fov_y_degrees = 60;  // vertical field of view, in (0, 180)
  Eye eye = Eye::kMono;
  friend bool operator==(const EyePose&, const EyePose&) = default;
};

struct EyePath {
  uint32_t width = 256, height = 256;  // image size of every pose, 1..16384
  // Ground-truth image of pose p: the pattern with "{pose}" (or "{pose:0N}") replaced by p, in
  // the directory of the path file. Empty when the path has no images (a path to render).
  std::string image_pattern;
  std::vector<EyePose> poses;
  friend bool operator==(const EyePath&, const EyePath&) = default;
};

inline constexpr const char* kEyePathFileName = "eye_path.json";
inline constexpr const char* kDefaultImagePattern = "gt_{pose:05}.exr";
// The subdirectory of a ground-truth directory holding the same poses rendered with another seed
// (CAPTURE.md, "Noise floor"): its own eye_path.json and images.
inline constexpr const char* kNoiseFloorDirName = "noise-floor";
inline constexpr uint32_t kMaxEyePoses = 1000000;

// Parses and validates eye-path JSON. A pose gives its orientation as exactly one of
//   "forward": [x, y, z] (+ optional "up", default [0, 1, 0]),
//   "look_at": [x, y, z] (+ optional "up"), or
//   "orientation": [w, x, y, z], a unit quaternion rotating the OpenGL camera frame (looking down
//   -Z, +Y up) into the scene.
// "fov_y_degrees" and "eye" are optional per pose (defaults: the path's "fov_y_degrees", else 60;
// "mono"). Errors: E130 syntax, E132 format/version, E142 fields, E134 more than kMaxEyePoses.
Expected<EyePath> parse_eye_path(std::string_view json, std::string_view source_name);
// Reads and parses a file (E002/E003 when it cannot be read).
Expected<EyePath> read_eye_path(const std::filesystem::path& path);
// Canonical JSON (forward + up form, exact doubles): parse_eye_path(serialize_eye_path(p)) == p
// for a parsed path.
std::string serialize_eye_path(const EyePath& path);
// The ground-truth image name of pose `index` ("" when the path has no image pattern).
std::string eye_image_file_name(const EyePath& path, uint32_t index);

// The camera of `pose` for a width x height image: position, forward and up as they are,
// fov_y = fov_y_degrees * pi / 180 (radians). Every renderer, the ground-truth tracer and the
// image comparisons take poses through this one function.
Camera camera_from_pose(const EyePose& pose, uint32_t width, uint32_t height);
// The frame of a clip or capture at `fps` frames a second shown at scene time `seconds`: frame f
// spans [f / fps, (f + 1) / fps); times before 0 (or NaN) give frame 0, times after the last
// frame give the last. frame_count >= 1, fps > 0.
uint32_t frame_at_time(double seconds, double fps, uint32_t frame_count);
// camera_from_pose(path.poses[index], path.width, path.height); index < path.poses.size().
Camera camera_from_pose(const EyePath& path, size_t index);

// A perspective ground-truth image: W x H, row-major from the top row.
struct PerspectiveImage {
  uint32_t width = 0, height = 0;
  std::vector<float> color;  // 3 per pixel, linear RGB
  std::vector<float> depth;  // radial distance from the eye, +inf = sky
};
// Writes an EXR with half R, G, B and float Z, whole (temporary file + rename).
Status write_perspective_image(const std::filesystem::path& path, const PerspectiveImage& image);
// Reads one back, checking channels and pixels like CaptureSetReader::read.
Expected<PerspectiveImage> read_perspective_image(const std::filesystem::path& path);

}  // namespace calf::capture
