// Camera rigs and the --rig syntax.
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include "calf/samples/scene.h"
#include "glm_vec.h"

namespace calf::samples {

const char* const kRigSyntaxHelp =
    "default                          the scene's own rig\n"
    "box:CX,CY,CZ,HX,HY,HZ            centre of a box, then its 8 corners (box half-sizes H)\n"
    "ring:N,R,CX,CY,CZ                N views on a horizontal circle of radius R around C\n"
    "sphere:N,R,CX,CY,CZ              N views spread on a sphere of radius R around C\n"
    "grid:NX,NY,NZ,X0,Y0,Z0,X1,Y1,Z1  NX*NY*NZ views on a grid spanning (X0,Y0,Z0)-(X1,Y1,Z1)\n"
    "list:X,Y,Z/X,Y,Z/...             explicit positions";

namespace {

Box3 bounds(const std::vector<capture::Viewpoint>& views) {
  Box3 b{views[0].position, views[0].position};
  for (const capture::Viewpoint& v : views) b = box_union(b, v.position);
  return b;
}

// The shortest text that reads back as exactly v, so that a description makes the same rig
// (std::to_string's six decimals turned 1e-300 into 0).
std::string num(double v) {
  char buf[32];
  std::to_chars_result r = std::to_chars(buf, buf + sizeof(buf), v);
  return std::string(buf, r.ptr);
}

// Parses a comma-separated list of finite numbers; false on anything else.
bool parse_numbers(std::string_view text, std::vector<double>* out) {
  out->clear();
  size_t at = 0;
  while (at <= text.size()) {
    size_t comma = text.find(',', at);
    std::string item(text.substr(at, comma == std::string_view::npos ? text.npos : comma - at));
    if (item.empty()) return false;
    char* end = nullptr;
    double v = std::strtod(item.c_str(), &end);
    if (end != item.c_str() + item.size() || !std::isfinite(v)) return false;
    out->push_back(v);
    if (comma == std::string_view::npos) break;
    at = comma + 1;
  }
  return true;
}

bool is_count(double v, double max) {
  return v >= 1 && v <= max && v == std::floor(v);
}

Status rig_error(std::string_view text, const std::string& why) {
  return Status(ErrorId::kRigSyntax, "--rig '" + std::string(text) + "': " + why +
                                         "; accepted forms:\n" + kRigSyntaxHelp);
}

// Finite arguments can still make a rig no capture set may have: an overflow to infinity
// (box:1e308,0,0,1e308,1,1) or one position twice (list:0,0,0/0,0,0). The manifest's own rules
// (validate_manifest) decide, reported at the --rig text rather than when the set is written.
Expected<Rig> checked_rig(std::string_view text, Rig rig) {
  capture::CaptureManifest m;
  m.frame_count = 1;
  m.face_size = 1;
  m.viewpoints = rig.viewpoints;
  m.view_volume = rig.view_volume;
  if (Status st = capture::validate_manifest(m); !st.ok()) return rig_error(text, st.message());
  return rig;
}

}  // namespace

Rig box_rig(const glm::dvec3& c, const glm::dvec3& h) {
  Rig rig;
  rig.viewpoints.push_back({"centre", to_vec3(c)});
  for (int i = 0; i < 8; ++i) {
    glm::dvec3 s((i & 1) ? 1 : -1, (i & 2) ? 1 : -1, (i & 4) ? 1 : -1);
    std::string name = std::string("corner") + (s.x > 0 ? "+x" : "-x") + (s.y > 0 ? "+y" : "-y") +
                       (s.z > 0 ? "+z" : "-z");
    rig.viewpoints.push_back({name, to_vec3(c + s * h)});
  }
  rig.view_volume = {to_vec3(c - h), to_vec3(c + h)};
  rig.description = "box:" + num(c.x) + "," + num(c.y) + "," + num(c.z) + "," + num(h.x) + "," +
                    num(h.y) + "," + num(h.z);
  return rig;
}

Rig ring_rig(uint32_t n, double r, const glm::dvec3& c) {
  Rig rig;
  for (uint32_t i = 0; i < n; ++i) {
    double a = 2 * M_PI * i / n;
    rig.viewpoints.push_back(
        {"ring" + std::to_string(i), to_vec3(c + glm::dvec3(r * std::cos(a), 0, r * std::sin(a)))});
  }
  rig.view_volume = {to_vec3(c - glm::dvec3(r, r / 4, r)), to_vec3(c + glm::dvec3(r, r / 4, r))};
  rig.description =
      "ring:" + std::to_string(n) + "," + num(r) + "," + num(c.x) + "," + num(c.y) + "," + num(c.z);
  return rig;
}

Rig sphere_rig(uint32_t n, double r, const glm::dvec3& c) {
  Rig rig;
  // Fibonacci lattice: heights evenly spaced in (-1, 1), longitudes by the golden angle.
  const double golden = M_PI * (3 - std::sqrt(5.0));
  for (uint32_t i = 0; i < n; ++i) {
    double y = 1 - (2 * i + 1.0) / n;
    double ring = std::sqrt(std::max(0.0, 1 - y * y));
    double a = golden * i;
    glm::dvec3 d(ring * std::cos(a), y, ring * std::sin(a));
    rig.viewpoints.push_back({"sphere" + std::to_string(i), to_vec3(c + r * d)});
  }
  rig.view_volume = {to_vec3(c - glm::dvec3(r)), to_vec3(c + glm::dvec3(r))};
  rig.description = "sphere:" + std::to_string(n) + "," + num(r) + "," + num(c.x) + "," + num(c.y) +
                    "," + num(c.z);
  return rig;
}

Rig grid_rig(const glm::uvec3& n, const glm::dvec3& lo, const glm::dvec3& hi) {
  Rig rig;
  auto at = [](uint32_t i, uint32_t count, double a, double b) {
    return count == 1 ? (a + b) / 2 : a + (b - a) * i / (count - 1);
  };
  for (uint32_t z = 0; z < n.z; ++z) {
    for (uint32_t y = 0; y < n.y; ++y) {
      for (uint32_t x = 0; x < n.x; ++x) {
        glm::dvec3 p(at(x, n.x, lo.x, hi.x), at(y, n.y, lo.y, hi.y), at(z, n.z, lo.z, hi.z));
        rig.viewpoints.push_back(
            {"grid" + std::to_string(x) + "_" + std::to_string(y) + "_" + std::to_string(z),
             to_vec3(p)});
      }
    }
  }
  rig.view_volume = {to_vec3(glm::min(lo, hi)), to_vec3(glm::max(lo, hi))};
  rig.description = "grid:" + std::to_string(n.x) + "," + std::to_string(n.y) + "," +
                    std::to_string(n.z) + "," + num(lo.x) + "," + num(lo.y) + "," + num(lo.z) +
                    "," + num(hi.x) + "," + num(hi.y) + "," + num(hi.z);
  return rig;
}

Rig list_rig(const std::vector<glm::dvec3>& positions) {
  Rig rig;
  rig.description = "list:";
  for (size_t i = 0; i < positions.size(); ++i) {
    const glm::dvec3& p = positions[i];
    rig.viewpoints.push_back({"view" + std::to_string(i), to_vec3(p)});
    // Appends, not operator+ chains: GCC 12 -O3 reports a false -Wrestrict on those.
    if (i) rig.description.append("/");
    rig.description.append(num(p.x)).append(",").append(num(p.y)).append(",").append(num(p.z));
  }
  if (!rig.viewpoints.empty()) rig.view_volume = bounds(rig.viewpoints);
  return rig;
}

Expected<Rig> parse_rig(std::string_view text) {
  size_t colon = text.find(':');
  if (colon == std::string_view::npos) return rig_error(text, "missing ':'");
  std::string_view kind = text.substr(0, colon);
  std::string_view args = text.substr(colon + 1);
  std::vector<double> v;
  constexpr double kMaxViews = capture::kMaxViewpoints;
  if (kind == "list") {
    std::vector<glm::dvec3> positions;
    size_t at = 0;
    while (at <= args.size()) {
      size_t slash = args.find('/', at);
      std::string_view item = args.substr(at, slash == args.npos ? args.npos : slash - at);
      if (!parse_numbers(item, &v) || v.size() != 3) {
        return rig_error(text, "position '" + std::string(item) + "' is not X,Y,Z");
      }
      positions.emplace_back(v[0], v[1], v[2]);
      if (positions.size() > kMaxViews) return rig_error(text, "more than 4096 viewpoints");
      if (slash == args.npos) break;
      at = slash + 1;
    }
    return checked_rig(text, list_rig(positions));
  }
  if (!parse_numbers(args, &v)) return rig_error(text, "expected comma-separated numbers");
  if (kind == "box") {
    if (v.size() != 6) return rig_error(text, "box takes 6 numbers");
    if (!(v[3] > 0 && v[4] > 0 && v[5] > 0)) return rig_error(text, "half-sizes must be > 0");
    return checked_rig(text, box_rig({v[0], v[1], v[2]}, {v[3], v[4], v[5]}));
  }
  if (kind == "ring" || kind == "sphere") {
    if (v.size() != 5) return rig_error(text, std::string(kind) + " takes 5 numbers");
    if (!is_count(v[0], kMaxViews)) return rig_error(text, "N must be an integer in 1..4096");
    if (!(v[1] > 0)) return rig_error(text, "the radius must be > 0");
    uint32_t n = static_cast<uint32_t>(v[0]);
    glm::dvec3 c(v[2], v[3], v[4]);
    return checked_rig(text, kind == "ring" ? ring_rig(n, v[1], c) : sphere_rig(n, v[1], c));
  }
  if (kind == "grid") {
    if (v.size() != 9) return rig_error(text, "grid takes 9 numbers");
    for (int i = 0; i < 3; ++i) {
      if (!is_count(v[i], kMaxViews)) return rig_error(text, "counts must be integers >= 1");
    }
    if (v[0] * v[1] * v[2] > kMaxViews) return rig_error(text, "more than 4096 viewpoints");
    glm::uvec3 n(static_cast<uint32_t>(v[0]), static_cast<uint32_t>(v[1]),
                 static_cast<uint32_t>(v[2]));
    glm::dvec3 lo(v[3], v[4], v[5]), hi(v[6], v[7], v[8]);
    for (int i = 0; i < 3; ++i) {
      if (n[i] > 1 && lo[i] == hi[i]) {
        return rig_error(text, "an axis with several views needs distinct ends");
      }
    }
    return checked_rig(text, grid_rig(n, lo, hi));
  }
  return rig_error(text, "unknown rig kind '" + std::string(kind) + "'");
}

}  // namespace calf::samples
