// Seurat capture manifests: parse and check (format/CAPTURE.md, "Ingest"; googlevr/seurat's
// api/camera.proto and api/image.proto describe the fields). Seurat itself ignores keys it does not
// know and so does calf here: the capture plugins of different engines add their own.
#include <cmath>
#include <string>

#include "calf/capture/ingest.h"
#include "json_fields.h"

namespace calf::capture {
namespace {

using detail::FieldReader;
using detail::Json;

constexpr uint32_t kMaxSeuratImageSize = 16384;

Expected<std::array<double, 16>> matrix(const FieldReader& r, const char* key) {
  CALF_ASSIGN_OR_RETURN(const Json* v, r.get(key));
  if (!v->is_array() || v->size() != 16) {
    return r.error(r.field(key), "expected 16 numbers (a row-major 4x4 matrix)");
  }
  std::array<double, 16> m{};
  for (size_t i = 0; i < 16; ++i) {
    const Json& e = (*v)[i];
    if (!e.is_number() || !std::isfinite(e.get<double>())) {
      return r.error(r.field(key) + "[" + std::to_string(i) + "]", "expected a finite number");
    }
    m[i] = e.get<double>();
  }
  return m;
}

// A relative path that stays in the manifest's directory tree.
bool safe_path(const std::string& p) {
  if (p.empty() || p.front() == '/' || p.find('\0') != std::string::npos) return false;
  size_t start = 0;
  while (start <= p.size()) {
    size_t end = p.find('/', start);
    if (end == std::string::npos) end = p.size();
    if (p.compare(start, end - start, "..") == 0 && end - start == 2) return false;
    start = end + 1;
  }
  return true;
}

Expected<SeuratImageFile> image_file(
    const FieldReader& parent, const char* key,
    std::initializer_list<std::pair<const char*, const char*>> channels) {
  CALF_ASSIGN_OR_RETURN(const Json* v, parent.get(key));
  if (!v->is_object()) return parent.error(parent.field(key), "expected an object");
  FieldReader r(*v, parent.field(key), parent.source(), parent.id());
  SeuratImageFile f;
  CALF_ASSIGN_OR_RETURN(f.path, r.string("path"));
  if (!safe_path(f.path)) {
    return r.error(r.field("path"), "'" + f.path + "' is empty, absolute or holds '..'");
  }
  for (const auto& [name, fallback] : channels) {
    CALF_ASSIGN_OR_RETURN(std::string c, r.string_or(name, fallback));
    if (c.empty()) return r.error(r.field(name), "is empty");
    f.channels.push_back(std::move(c));
  }
  return f;
}

Expected<SeuratView> view(const Json& json, const std::string& path, std::string_view source) {
  if (!json.is_object()) {
    return Status(ErrorId::kSeuratField,
                  std::string(source) + ": field '" + path + "': expected an object");
  }
  FieldReader r(json, path, source, ErrorId::kSeuratField);
  SeuratView v;
  CALF_ASSIGN_OR_RETURN(const Json* cam_json, r.get("projective_camera"));
  if (!cam_json->is_object()) return r.error(r.field("projective_camera"), "expected an object");
  FieldReader cam(*cam_json, r.field("projective_camera"), source, ErrorId::kSeuratField);
  CALF_ASSIGN_OR_RETURN(v.image_width, cam.uint("image_width", 1, kMaxSeuratImageSize));
  CALF_ASSIGN_OR_RETURN(v.image_height, cam.uint("image_height", 1, kMaxSeuratImageSize));
  CALF_ASSIGN_OR_RETURN(v.clip_from_eye, matrix(cam, "clip_from_eye_matrix"));
  CALF_ASSIGN_OR_RETURN(v.world_from_eye, matrix(cam, "world_from_eye_matrix"));
  CALF_ASSIGN_OR_RETURN(std::string depth_type, cam.string("depth_type"));
  if (depth_type == "WINDOW_Z" || depth_type == "DEPTH_TYPE_WINDOW_Z") {
    v.depth_type = SeuratDepthType::kWindowZ;
  } else if (depth_type == "EYE_Z" || depth_type == "DEPTH_TYPE_EYE_Z") {
    v.depth_type = SeuratDepthType::kEyeZ;
  } else if (depth_type == "RAY_DEPTH" || depth_type == "DEPTH_TYPE_RAY_DEPTH") {
    v.depth_type = SeuratDepthType::kRayDepth;
  } else {
    return cam.error(cam.field("depth_type"),
                     "'" + depth_type + "' is not WINDOW_Z, EYE_Z or RAY_DEPTH");
  }
  const auto& w = v.world_from_eye;
  if (std::fabs(w[12]) > 1e-6 || std::fabs(w[13]) > 1e-6 || std::fabs(w[14]) > 1e-6 ||
      std::fabs(w[15] - 1) > 1e-6) {
    return cam.error(cam.field("world_from_eye_matrix"),
                     "last row is not (0, 0, 0, 1): not a rigid or affine camera pose");
  }
  const double det = w[0] * (w[5] * w[10] - w[6] * w[9]) - w[1] * (w[4] * w[10] - w[6] * w[8]) +
                     w[2] * (w[4] * w[9] - w[5] * w[8]);
  if (!(std::fabs(det) > 1e-12)) {
    return cam.error(cam.field("world_from_eye_matrix"), "is singular");
  }
  // A perspective projection from the eye: w_clip = -z_eye * c (c > 0), no shift along x or y
  // that depends on depth, and near / far planes 0 < n < f <= inf.
  const auto& p = v.clip_from_eye;
  const bool perspective = p[12] == 0 && p[13] == 0 && p[15] == 0 && p[14] < 0 && p[3] == 0 &&
                           p[7] == 0 && p[8] == 0 && p[9] == 0 && p[0] != 0 && p[5] != 0;
  if (!perspective) {
    return cam.error(cam.field("clip_from_eye_matrix"),
                     "is not a perspective projection (rows 3 and 4 must be (0, 0, a, b) and "
                     "(0, 0, -c, 0) with c > 0; an orthographic view has no viewpoint)");
  }
  const double c = -p[14];
  const double a = p[10] / c, b = p[11] / c;
  const double near = b / (a - 1);
  const double far = a == -1 ? INFINITY : b / (a + 1);
  if (!(near > 0) || !(far > near)) {
    return cam.error(cam.field("clip_from_eye_matrix"), "has near " + std::to_string(near) +
                                                            " and far " + std::to_string(far) +
                                                            ": expected 0 < near < far");
  }
  CALF_ASSIGN_OR_RETURN(const Json* files, r.get("depth_image_file"));
  if (!files->is_object()) return r.error(r.field("depth_image_file"), "expected an object");
  FieldReader fr(*files, r.field("depth_image_file"), source, ErrorId::kSeuratField);
  CALF_ASSIGN_OR_RETURN(
      v.color,
      image_file(
          fr, "color",
          {{"channel_0", "R"}, {"channel_1", "G"}, {"channel_2", "B"}, {"channel_alpha", "A"}}));
  CALF_ASSIGN_OR_RETURN(v.depth, image_file(fr, "depth", {{"channel_0", "Z"}}));
  return v;
}

}  // namespace

Expected<SeuratCapture> parse_seurat_manifest(std::string_view json, std::string_view source) {
  CALF_ASSIGN_OR_RETURN(Json root, detail::parse_json_object(json, source));
  FieldReader r(root, "", source, ErrorId::kSeuratField);
  SeuratCapture capture;
  if (r.has("headbox_center")) {
    CALF_ASSIGN_OR_RETURN(Vec3 c, r.point("headbox_center"));
    capture.headbox_center = c;
  }
  CALF_ASSIGN_OR_RETURN(const Json* groups, r.get("view_groups"));
  if (!groups->is_array() || groups->empty()) {
    return r.error("view_groups", "expected a non-empty array of view groups");
  }
  if (groups->size() > 4096) return r.error("view_groups", "more than 4096 view groups");
  for (size_t g = 0; g < groups->size(); ++g) {
    const std::string gpath = "view_groups[" + std::to_string(g) + "]";
    const Json& group = (*groups)[g];
    if (!group.is_object()) return r.error(gpath, "expected an object");
    FieldReader gr(group, gpath, source, ErrorId::kSeuratField);
    CALF_ASSIGN_OR_RETURN(const Json* views, gr.get("views"));
    if (!views->is_array() || views->empty() || views->size() > 64) {
      return gr.error(gr.field("views"), "expected an array of 1 to 64 views");
    }
    std::vector<SeuratView> out;
    for (size_t v = 0; v < views->size(); ++v) {
      CALF_ASSIGN_OR_RETURN(
          SeuratView sv,
          view((*views)[v], gr.field("views") + "[" + std::to_string(v) + "]", source));
      out.push_back(std::move(sv));
    }
    capture.view_groups.push_back(std::move(out));
  }
  return capture;
}

}  // namespace calf::capture
