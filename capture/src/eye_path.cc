// Eye paths and ground-truth images (format/CAPTURE.md, "Eye paths").
#include "calf/capture/eye_path.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "calf/format/coordinates.h"

#include "exr_io.h"
#include "image_input.h"
#include "json_fields.h"

namespace calf::capture {

namespace {

using detail::FieldReader;
using detail::Json;

constexpr const char* kFormatName = "calf-eye-path";

// v scaled so that its largest component has magnitude 1 when its length would overflow or
// lose precision ([1e300, 1e300, 0] has a finite direction but an infinite length); false for a
// zero or non-finite v. Moderate vectors are returned unchanged, bit for bit.
bool rescale(Vec3* v) {
  double m = std::max({std::fabs(v->x), std::fabs(v->y), std::fabs(v->z)});
  if (!(m > 0) || !std::isfinite(m)) return false;
  if (m > 1e100 || m < 1e-100) *v = *v / m;
  return true;
}

// Unit forward and an up orthogonal to it; false when either is zero or they are parallel.
// Vectors that are already unit and orthogonal (to 1e-12) are kept bit for bit, so that parsing
// a serialized path gives back the same numbers.
bool orthonormalize(Vec3* forward, Vec3* up) {
  if (!rescale(forward) || !rescale(up)) return false;
  double fl = length(*forward);
  if (std::fabs(fl - 1) > 1e-12) *forward = *forward * (1 / fl);
  double ul = length(*up);
  double along = dot(*up, *forward);
  if (std::fabs(along) > 1e-12 * ul) {
    Vec3 u = *up - *forward * along;
    double rest = length(u);
    if (!(rest > 1e-6 * ul)) return false;
    *up = u * (1 / rest);
  } else if (std::fabs(ul - 1) > 1e-12) {
    *up = *up * (1 / ul);
  }
  return true;
}

// Rotates v by the unit quaternion (w, x, y, z).
Vec3 rotate(const double q[4], const Vec3& v) {
  Vec3 u{q[1], q[2], q[3]};
  Vec3 t = cross(u, v) * 2.0;
  Vec3 c = cross(u, t);
  return v + q[0] * t + c;
}

Expected<EyePose> parse_pose(const Json& j, const std::string& path, std::string_view source,
                             double default_fov) {
  if (!j.is_object()) {
    return Status(ErrorId::kEyePathField,
                  std::string(source) + ": field '" + path + "': expected a pose object");
  }
  FieldReader r(j, path, source, ErrorId::kEyePathField);
  CALF_RETURN_IF_ERROR(r.check_keys(
      {"time", "position", "forward", "look_at", "orientation", "up", "fov_y_degrees", "eye"}));
  EyePose pose;
  CALF_ASSIGN_OR_RETURN(pose.time, r.number("time"));
  CALF_ASSIGN_OR_RETURN(pose.position, r.point("position"));
  CALF_RETURN_IF_ERROR(
      check_coordinates(pose.position, ErrorId::kEyePathField,
                        std::string(source) + ": field '" + r.field("position") + "'"));
  int forms = int{r.has("forward")} + int{r.has("look_at")} + int{r.has("orientation")};
  if (forms != 1) {
    return r.error(path, "give exactly one of \"forward\", \"look_at\", \"orientation\"");
  }
  if (r.has("orientation")) {
    if (r.has("up")) return r.error(r.field("up"), "not allowed with \"orientation\"");
    CALF_ASSIGN_OR_RETURN(const Json* q, r.get("orientation"));
    double qv[4];
    if (!q->is_array() || q->size() != 4) {
      return r.error(r.field("orientation"), "expected a quaternion [w, x, y, z]");
    }
    for (size_t i = 0; i < 4; ++i) {
      if (!(*q)[i].is_number() || !std::isfinite((*q)[i].get<double>())) {
        return r.error(r.field("orientation"), "expected four finite numbers");
      }
      qv[i] = (*q)[i].get<double>();
    }
    double norm = std::sqrt(qv[0] * qv[0] + qv[1] * qv[1] + qv[2] * qv[2] + qv[3] * qv[3]);
    if (std::fabs(norm - 1) > 1e-3) {
      return r.error(r.field("orientation"),
                     "quaternion length " + std::to_string(norm) + " is not 1 (tolerance 1e-3)");
    }
    for (double& c : qv) c /= norm;
    pose.forward = rotate(qv, {0, 0, -1});
    pose.up = rotate(qv, {0, 1, 0});
  } else {
    if (r.has("forward")) {
      CALF_ASSIGN_OR_RETURN(pose.forward, r.point("forward"));
    } else {
      CALF_ASSIGN_OR_RETURN(Vec3 target, r.point("look_at"));
      CALF_RETURN_IF_ERROR(
          check_coordinates(target, ErrorId::kEyePathField,
                            std::string(source) + ": field '" + r.field("look_at") + "'"));
      pose.forward = target - pose.position;
    }
    if (r.has("up")) {
      CALF_ASSIGN_OR_RETURN(pose.up, r.point("up"));
    }
  }
  if (!orthonormalize(&pose.forward, &pose.up)) {
    return r.error(path, "the view direction is zero or parallel to \"up\"");
  }
  CALF_ASSIGN_OR_RETURN(pose.fov_y_degrees, r.number_or("fov_y_degrees", default_fov));
  if (!(pose.fov_y_degrees > 0 && pose.fov_y_degrees < 180)) {
    return r.error(r.field("fov_y_degrees"), "must be in (0, 180)");
  }
  CALF_ASSIGN_OR_RETURN(std::string eye, r.string_or("eye", "mono"));
  if (eye == "mono") {
    pose.eye = Eye::kMono;
  } else if (eye == "left") {
    pose.eye = Eye::kLeft;
  } else if (eye == "right") {
    pose.eye = Eye::kRight;
  } else {
    return r.error(r.field("eye"), "\"" + eye + "\" is not \"mono\", \"left\" or \"right\"");
  }
  return pose;
}

}  // namespace

const char* eye_name(Eye eye) {
  switch (eye) {
    case Eye::kLeft:
      return "left";
    case Eye::kRight:
      return "right";
    case Eye::kMono:
      break;
  }
  return "mono";
}

Expected<EyePath> parse_eye_path(std::string_view json, std::string_view source) {
  CALF_ASSIGN_OR_RETURN(Json root, detail::parse_json_object(json, source));
  FieldReader r(root, "", source, ErrorId::kEyePathField);
  CALF_ASSIGN_OR_RETURN(std::string format, r.string("format"));
  CALF_ASSIGN_OR_RETURN(uint32_t version, r.uint("version", 0, UINT32_MAX));
  if (format != kFormatName || version != 1) {
    return Status(ErrorId::kManifestVersion, std::string(source) + ": format \"" + format +
                                                 "\" version " + std::to_string(version) +
                                                 " is not \"calf-eye-path\" version 1");
  }
  CALF_RETURN_IF_ERROR(r.check_keys(
      {"format", "version", "width", "height", "fov_y_degrees", "image_pattern", "poses"}));
  EyePath path;
  CALF_ASSIGN_OR_RETURN(path.width, r.uint("width", 1, 16384));
  CALF_ASSIGN_OR_RETURN(path.height, r.uint("height", 1, 16384));
  CALF_ASSIGN_OR_RETURN(double fov, r.number_or("fov_y_degrees", 60));
  if (!(fov > 0 && fov < 180)) return r.error("fov_y_degrees", "must be in (0, 180)");
  CALF_ASSIGN_OR_RETURN(path.image_pattern, r.string_or("image_pattern", ""));
  if (!path.image_pattern.empty()) {
    if (std::string problem = detail::pattern_problem(path.image_pattern, {"pose"});
        !problem.empty()) {
      return r.error("image_pattern", "\"" + path.image_pattern + "\" " + problem);
    }
  }
  CALF_ASSIGN_OR_RETURN(const Json* poses, r.get("poses"));
  if (!poses->is_array() || poses->empty()) {
    return r.error("poses", "expected a non-empty array of poses");
  }
  if (poses->size() > kMaxEyePoses) {
    return Status(ErrorId::kCaptureLimit,
                  std::string(source) + ": field 'poses': " + std::to_string(poses->size()) +
                      " poses exceed the limit " + std::to_string(kMaxEyePoses));
  }
  path.poses.reserve(poses->size());
  for (size_t i = 0; i < poses->size(); ++i) {
    CALF_ASSIGN_OR_RETURN(EyePose pose,
                          parse_pose((*poses)[i], "poses[" + std::to_string(i) + "]", source, fov));
    path.poses.push_back(pose);
  }
  return path;
}

Expected<EyePath> read_eye_path(const std::filesystem::path& file) {
  CALF_ASSIGN_OR_RETURN(std::string text, read_small_file(file));
  return parse_eye_path(text, file.string());
}

std::string serialize_eye_path(const EyePath& path) {
  nlohmann::ordered_json j;
  j["format"] = kFormatName;
  j["version"] = 1;
  j["width"] = path.width;
  j["height"] = path.height;
  if (!path.image_pattern.empty()) j["image_pattern"] = path.image_pattern;
  auto poses = nlohmann::ordered_json::array();
  for (const EyePose& p : path.poses) {
    nlohmann::ordered_json e;
    e["time"] = p.time;
    e["position"] = {p.position.x, p.position.y, p.position.z};
    e["forward"] = {p.forward.x, p.forward.y, p.forward.z};
    e["up"] = {p.up.x, p.up.y, p.up.z};
    e["fov_y_degrees"] = p.fov_y_degrees;
    if (p.eye != Eye::kMono) e["eye"] = eye_name(p.eye);
    poses.push_back(std::move(e));
  }
  j["poses"] = std::move(poses);
  return j.dump(2, ' ', false, nlohmann::ordered_json::error_handler_t::replace) + "\n";
}

Camera camera_from_pose(const EyePose& pose, uint32_t width, uint32_t height) {
  Camera c;
  c.position = pose.position;
  c.forward = pose.forward;
  c.up = pose.up;
  // (degrees * pi) / 180, the rounding calf-play and the tracer always used.
  c.fov_y = pose.fov_y_degrees * std::numbers::pi / 180.0;
  c.width = width;
  c.height = height;
  return c;
}

Camera camera_from_pose(const EyePath& path, size_t index) {
  return camera_from_pose(path.poses[index], path.width, path.height);
}

std::string eye_image_file_name(const EyePath& path, uint32_t index) {
  if (path.image_pattern.empty()) return "";
  return detail::expand_pattern_token(path.image_pattern, "pose", index);
}

Status write_perspective_image(const std::filesystem::path& file, const PerspectiveImage& image) {
  const size_t n = static_cast<size_t>(image.width) * image.height;
  if (n == 0 || image.color.size() != 3 * n || image.depth.size() != n) {
    return Status(ErrorId::kInvalidArgument,
                  file.string() + ": image buffers do not match its size");
  }
  return detail::write_exr(file, image.width, image.height,
                           {{"R", true, image.color.data() + 0, 3},
                            {"G", true, image.color.data() + 1, 3},
                            {"B", true, image.color.data() + 2, 3},
                            {"Z", false, image.depth.data(), 1}});
}

Expected<PerspectiveImage> read_perspective_image(const std::filesystem::path& file) {
  CALF_ASSIGN_OR_RETURN(detail::ExrReader exr, detail::ExrReader::open(file));
  // The image rule (its size from the header, within the default budget) before any row is read.
  CALF_RETURN_IF_ERROR(
      detail::check_image_size(file.string(), exr.width(), exr.height(), detail::ImageExpect{}));
  int idx[4];
  const char* const names[4] = {"R", "G", "B", "Z"};
  for (int c = 0; c < 4; ++c) {
    idx[c] = exr.channel(names[c]);
    if (idx[c] < 0) {
      return Status(ErrorId::kCaptureImageFormat,
                    file.string() + ": channel '" + names[c] + "' is missing");
    }
    CALF_RETURN_IF_ERROR(exr.require_float(idx[c]));
  }
  PerspectiveImage image;
  image.width = exr.width();
  image.height = exr.height();
  std::vector<float> rows;
  CALF_RETURN_IF_ERROR(exr.read_rows(0, image.height, &rows));
  const size_t n = static_cast<size_t>(image.width) * image.height;
  const size_t nch = static_cast<size_t>(exr.channel_count());
  image.color.resize(3 * n);
  image.depth.resize(n);
  for (size_t i = 0; i < n; ++i) {
    for (int c = 0; c < 3; ++c) {
      float v = rows[i * nch + idx[c]];
      if (!(v >= 0 && std::isfinite(v))) {
        return Status(ErrorId::kCaptureColourPixel,
                      file.string() + ": pixel (" + std::to_string(i % image.width) + ", " +
                          std::to_string(i / image.width) + "): colour is not finite and >= 0");
      }
      image.color[3 * i + c] = v;
    }
    float z = rows[i * nch + idx[3]];
    if (std::isnan(z) || z <= 0) {
      return Status(ErrorId::kCaptureDepthPixel,
                    file.string() + ": pixel (" + std::to_string(i % image.width) + ", " +
                        std::to_string(i / image.width) + "): depth is NaN or <= 0");
    }
    image.depth[i] = z;
  }
  return image;
}

uint32_t frame_at_time(double seconds, double fps, uint32_t frame_count) {
  if (!(seconds > 0)) return 0;  // negative or NaN
  // The epsilon keeps f / fps itself in frame f despite rounding of the division.
  const double f = std::floor(seconds * fps + 1e-9);
  return static_cast<uint32_t>(std::min<double>(f, frame_count - 1));
}

}  // namespace calf::capture
