// manifest.json: parse, validate, serialize (format/CAPTURE.md, "Manifest").
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>
#include <string>
#include <tuple>

#include "calf/capture/capture_set.h"
#include "calf/format/coordinates.h"
#include "json_fields.h"

namespace calf::capture {

namespace {

using detail::FieldReader;
using detail::Json;

constexpr const char* kFormatName = "calf-capture-set";

std::string point_text(const Vec3& p) {
  // snprintf, not string concatenation: GCC 12 -O3 reports a false -Wrestrict on the latter.
  char buf[96];
  std::snprintf(buf, sizeof buf, "(%g, %g, %g)", p.x, p.y, p.z);
  return buf;
}

// The rules both parse_manifest and validate_manifest apply; `source` prefixes messages.
Status check_manifest(const CaptureManifest& m, std::string_view source) {
  std::string src(source);
  auto fail = [&](ErrorId id, const std::string& what) { return Status(id, src + ": " + what); };
  if (m.version != kCaptureFormatVersion && m.version != kCaptureCoverageVersion) {
    return fail(ErrorId::kManifestVersion,
                "version " + std::to_string(m.version) + " is not supported (expected 1 or 2)");
  }
  if (m.coverage && m.version < kCaptureCoverageVersion) {
    return fail(ErrorId::kManifestVersion, "field 'coverage': needs version 2");
  }
  if (m.frame_count == 0) return fail(ErrorId::kManifestField, "field 'frame_count': is 0");
  if (m.frame_count > kMaxFrames) {
    return fail(ErrorId::kCaptureLimit, "field 'frame_count': " + std::to_string(m.frame_count) +
                                            " exceeds the limit " + std::to_string(kMaxFrames));
  }
  if (!(m.fps > 0 && m.fps <= 1000)) {
    return fail(ErrorId::kManifestField,
                "field 'fps': " + std::to_string(m.fps) + " is outside (0, 1000]");
  }
  if (m.face_size == 0) return fail(ErrorId::kManifestField, "field 'face_size': is 0");
  if (m.face_size > kMaxCaptureFaceSize) {
    return fail(ErrorId::kCaptureLimit, "field 'face_size': " + std::to_string(m.face_size) +
                                            " exceeds the limit " +
                                            std::to_string(kMaxCaptureFaceSize));
  }
  if (m.viewpoints.empty()) return fail(ErrorId::kManifestField, "field 'viewpoints': is empty");
  if (m.viewpoints.size() > kMaxViewpoints) {
    return fail(ErrorId::kCaptureLimit,
                "field 'viewpoints': " + std::to_string(m.viewpoints.size()) +
                    " viewpoints exceed the limit " + std::to_string(kMaxViewpoints));
  }
  const Box3& vv = m.view_volume;
  CALF_RETURN_IF_ERROR(
      check_coordinates(vv.min, ErrorId::kManifestField, src + ": field 'view_volume.min'"));
  CALF_RETURN_IF_ERROR(
      check_coordinates(vv.max, ErrorId::kManifestField, src + ": field 'view_volume.max'"));
  if (vv.min.x > vv.max.x || vv.min.y > vv.max.y || vv.min.z > vv.max.z) {
    return fail(ErrorId::kManifestInconsistent, "field 'view_volume': min " + point_text(vv.min) +
                                                    " exceeds max " + point_text(vv.max));
  }
  // Two viewpoints at one place would be redundant data and break view selection ties; two with
  // one name make error messages ambiguous. Sorting keeps this O(n log n) at the 4096 limit.
  std::set<std::string> names;
  std::set<std::tuple<double, double, double>> positions;
  for (size_t i = 0; i < m.viewpoints.size(); ++i) {
    const Viewpoint& v = m.viewpoints[i];
    std::string field = "field 'viewpoints[" + std::to_string(i) + "]";
    CALF_RETURN_IF_ERROR(
        check_coordinates(v.position, ErrorId::kManifestField, src + ": " + field + ".position'"));
    if (v.name.empty() || v.name.size() > 200) {
      return fail(ErrorId::kManifestField, field + ".name': must hold 1 to 200 characters");
    }
    if (!names.insert(v.name).second) {
      return fail(ErrorId::kManifestInconsistent,
                  field + ".name': \"" + v.name + "\" is used by an earlier viewpoint");
    }
    if (!positions.insert({v.position.x, v.position.y, v.position.z}).second) {
      return fail(ErrorId::kManifestInconsistent, field + ".position': " + point_text(v.position) +
                                                      " is used by an earlier viewpoint");
    }
  }
  if (std::string problem = detail::pattern_problem(m.file_pattern, {"view", "frame"});
      !problem.empty()) {
    return fail(ErrorId::kManifestInconsistent,
                "field 'file_pattern': \"" + m.file_pattern + "\" " + problem);
  }
  return Status::Ok();
}

Expected<Box3> parse_box(const FieldReader& parent, const char* key) {
  CALF_ASSIGN_OR_RETURN(const Json* v, parent.get(key));
  if (!v->is_object())
    return parent.error(parent.field(key), "expected {\"min\": .., \"max\": ..}");
  FieldReader r(*v, parent.field(key), parent.source(), parent.id());
  CALF_RETURN_IF_ERROR(r.check_keys({"min", "max"}));
  Box3 box;
  CALF_ASSIGN_OR_RETURN(box.min, r.point("min"));
  CALF_ASSIGN_OR_RETURN(box.max, r.point("max"));
  return box;
}

}  // namespace

Expected<CaptureManifest> parse_manifest(std::string_view json, std::string_view source) {
  CALF_ASSIGN_OR_RETURN(Json root, detail::parse_json_object(json, source));
  FieldReader r(root, "", source, ErrorId::kManifestField);
  // Format and version first: a newer manifest may have fields this reader does not know.
  CALF_ASSIGN_OR_RETURN(std::string format, r.string("format"));
  if (format != kFormatName) {
    return Status(ErrorId::kManifestVersion, std::string(source) + ": field 'format': \"" + format +
                                                 "\" is not \"" + kFormatName + "\"");
  }
  CaptureManifest m;
  CALF_ASSIGN_OR_RETURN(m.version, r.uint("version", 0, UINT32_MAX));
  if (m.version != kCaptureFormatVersion && m.version != kCaptureCoverageVersion) {
    return check_manifest(m, source);
  }
  // Version 1 has no "coverage" key: a misplaced one is an unknown key there.
  if (m.version == kCaptureFormatVersion) {
    CALF_RETURN_IF_ERROR(
        r.check_keys({"format", "version", "scene", "generator", "frame_count", "fps", "face_size",
                      "file_pattern", "material", "view_volume", "viewpoints"}));
  } else {
    CALF_RETURN_IF_ERROR(
        r.check_keys({"format", "version", "scene", "generator", "frame_count", "fps", "face_size",
                      "file_pattern", "material", "coverage", "view_volume", "viewpoints"}));
    CALF_ASSIGN_OR_RETURN(m.coverage, r.boolean_or("coverage", false));
  }
  CALF_ASSIGN_OR_RETURN(m.scene, r.string_or("scene", ""));
  CALF_ASSIGN_OR_RETURN(m.generator, r.string_or("generator", ""));
  CALF_ASSIGN_OR_RETURN(m.frame_count, r.uint("frame_count", 0, UINT32_MAX));
  CALF_ASSIGN_OR_RETURN(m.fps, r.number("fps"));
  CALF_ASSIGN_OR_RETURN(m.face_size, r.uint("face_size", 0, UINT32_MAX));
  CALF_ASSIGN_OR_RETURN(m.file_pattern, r.string("file_pattern"));
  CALF_ASSIGN_OR_RETURN(m.material, r.boolean_or("material", false));
  CALF_ASSIGN_OR_RETURN(m.view_volume, parse_box(r, "view_volume"));
  CALF_ASSIGN_OR_RETURN(const Json* views, r.get("viewpoints"));
  if (!views->is_array()) return r.error("viewpoints", "expected an array of viewpoints");
  // Checked before the loop so that a hostile count never drives an allocation.
  if (views->size() > kMaxViewpoints) {
    return Status(ErrorId::kCaptureLimit,
                  std::string(source) + ": field 'viewpoints': " + std::to_string(views->size()) +
                      " viewpoints exceed the limit " + std::to_string(kMaxViewpoints));
  }
  m.viewpoints.reserve(views->size());
  for (size_t i = 0; i < views->size(); ++i) {
    std::string path = "viewpoints[" + std::to_string(i) + "]";
    const Json& v = (*views)[i];
    if (!v.is_object()) return r.error(path, "expected {\"name\": .., \"position\": [x, y, z]}");
    FieldReader vr(v, path, source, ErrorId::kManifestField);
    CALF_RETURN_IF_ERROR(vr.check_keys({"name", "position"}));
    Viewpoint vp;
    CALF_ASSIGN_OR_RETURN(vp.name, vr.string_or("name", "view" + std::to_string(i)));
    CALF_ASSIGN_OR_RETURN(vp.position, vr.point("position"));
    m.viewpoints.push_back(std::move(vp));
  }
  CALF_RETURN_IF_ERROR(check_manifest(m, source));
  return m;
}

Status validate_manifest(const CaptureManifest& manifest) {
  return check_manifest(manifest, "manifest");
}

std::string serialize_manifest(const CaptureManifest& m) {
  // ordered_json keeps the documented key order, so that manifests diff cleanly.
  nlohmann::ordered_json j;
  j["format"] = kFormatName;
  j["version"] = m.version;
  if (!m.scene.empty()) j["scene"] = m.scene;
  if (!m.generator.empty()) j["generator"] = m.generator;
  j["frame_count"] = m.frame_count;
  j["fps"] = m.fps;
  j["face_size"] = m.face_size;
  j["file_pattern"] = m.file_pattern;
  j["material"] = m.material;
  if (m.version >= kCaptureCoverageVersion) j["coverage"] = m.coverage;
  j["view_volume"] = {{"min", {m.view_volume.min.x, m.view_volume.min.y, m.view_volume.min.z}},
                      {"max", {m.view_volume.max.x, m.view_volume.max.y, m.view_volume.max.z}}};
  auto views = nlohmann::ordered_json::array();
  for (const Viewpoint& v : m.viewpoints) {
    nlohmann::ordered_json e;
    e["name"] = v.name;
    e["position"] = {v.position.x, v.position.y, v.position.z};
    views.push_back(std::move(e));
  }
  j["viewpoints"] = std::move(views);
  return j.dump(2, ' ', false, nlohmann::ordered_json::error_handler_t::replace) + "\n";
}

std::string capture_file_name(const CaptureManifest& manifest, uint32_t view, uint32_t frame) {
  return detail::expand_pattern_token(
      detail::expand_pattern_token(manifest.file_pattern, "view", view), "frame", frame);
}

}  // namespace calf::capture
