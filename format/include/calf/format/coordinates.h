// The one bound on scene coordinates (format/CAPTURE.md "Coordinates", SPEC §11.1.3).
//
// Every position, extent and vertex that enters calf from outside (capture-set manifests, eye
// paths, calf-capture's --rig, scene models) is finite and within +-kMaxCoordinate scene units on
// each axis. Finite is not enough: a viewpoint at 1e300 overflows to infinity the moment anything
// subtracts two positions, and the float ray tracer (Embree) aborts on a ray origin beyond ~1.8e18.
// 1e12 units (a million kilometres in metres) is far beyond any scene calf renders, and the
// difference of two bounded points (2e12) and its square (4e24) stay far inside float range
// (3.4e38), so geometry built from bounded inputs never overflows, in double or in float.
//
// Readers check with check_coordinate(s) where a value enters and report it with their own error
// id and field name, so that the message names the file and field at fault.
#pragma once

#include <cmath>
#include <cstdio>
#include <string>

#include "calf/format/geometry.h"
#include "calf/format/status.h"

namespace calf {

inline constexpr double kMaxCoordinate = 1e12;

// True when v is finite and |v| <= kMaxCoordinate (NaN and +-inf are false).
inline bool coordinate_ok(double v) {
  return std::fabs(v) <= kMaxCoordinate;
}
inline bool coordinates_ok(const Vec3& p) {
  return coordinate_ok(p.x) && coordinate_ok(p.y) && coordinate_ok(p.z);
}

// Ok, or Status(id, "<what>: <value> is not a finite number within +-1e+12 (the coordinate
// bound)"); `what` names the file and field, e.g. "manifest.json: field 'viewpoints[2].position'".
inline Status check_coordinate(double v, ErrorId id, const std::string& what) {
  if (coordinate_ok(v)) return Status::Ok();
  char buf[64];
  std::snprintf(buf, sizeof buf, "%g", v);
  char bound[32];
  std::snprintf(bound, sizeof bound, "%g", kMaxCoordinate);
  return Status(id, what + ": " + buf + " is not a finite number within +-" + bound +
                        " (the coordinate bound)");
}
inline Status check_coordinates(const Vec3& p, ErrorId id, const std::string& what) {
  if (coordinates_ok(p)) return Status::Ok();
  char buf[96];
  std::snprintf(buf, sizeof buf, "(%g, %g, %g)", p.x, p.y, p.z);
  char bound[32];
  std::snprintf(bound, sizeof bound, "%g", kMaxCoordinate);
  return Status(id, what + ": " + buf + " is not finite and within +-" + bound +
                        " on each axis (the coordinate bound)");
}

}  // namespace calf
