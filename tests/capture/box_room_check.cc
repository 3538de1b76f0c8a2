// Test tool (not installed): checks a capture set of an axis-aligned box room, seen from inside,
// against calf's own convention. For every texel of every face of every view-frame, the radial
// depth must equal the analytic distance from the viewpoint along direction_from_texel to the
// room's walls, within a relative tolerance. Rendered by another program (the Blender add-on,
// tests/blender/blender_capture.sh), it fails when that program's face order, face orientation or
// planar-to-radial depth conversion differs from calf's.
//   box_room_check CAPTURE_DIR X0,Y0,Z0,X1,Y1,Z1 TOLERANCE
// Prints the worst relative error and the number of texels checked; exit 1 past TOLERANCE.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "calf/capture/capture_set.h"
#include "calf/format/cube.h"

namespace {

using namespace calf;

// Distance from `p` (inside the box) along unit `d` to the box's walls.
double wall_distance(const Vec3& p, const Vec3& d, const Vec3& lo, const Vec3& hi) {
  double t = INFINITY;
  const double pc[3] = {p.x, p.y, p.z}, dc[3] = {d.x, d.y, d.z};
  const double l[3] = {lo.x, lo.y, lo.z}, h[3] = {hi.x, hi.y, hi.z};
  for (int k = 0; k < 3; ++k) {
    if (dc[k] > 0) t = std::min(t, (h[k] - pc[k]) / dc[k]);
    if (dc[k] < 0) t = std::min(t, (l[k] - pc[k]) / dc[k]);
  }
  return t;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 4) {
    std::fprintf(stderr, "usage: box_room_check CAPTURE_DIR X0,Y0,Z0,X1,Y1,Z1 TOLERANCE\n");
    return 2;
  }
  double b[6];
  if (std::sscanf(argv[2], "%lf,%lf,%lf,%lf,%lf,%lf", &b[0], &b[1], &b[2], &b[3], &b[4], &b[5]) !=
      6) {
    std::fprintf(stderr, "box_room_check: bad box '%s'\n", argv[2]);
    return 2;
  }
  const Vec3 lo{b[0], b[1], b[2]}, hi{b[3], b[4], b[5]};
  const double tolerance = std::atof(argv[3]);
  Expected<capture::CaptureSetReader> reader = capture::CaptureSetReader::open(argv[1]);
  if (!reader.ok()) {
    std::fprintf(stderr, "box_room_check: %s\n", reader.status().message().c_str());
    return 1;
  }
  const capture::CaptureManifest& m = reader->manifest();
  capture::ViewFrame frame;
  double worst = 0;
  size_t checked = 0;
  std::string worst_at = "none";
  for (uint32_t v = 0; v < m.viewpoints.size(); ++v) {
    for (uint32_t f = 0; f < m.frame_count; ++f) {
      if (Status s = reader->read(v, f, &frame); !s.ok()) {
        std::fprintf(stderr, "box_room_check: %s\n", s.message().c_str());
        return 1;
      }
      for (int i = 0; i < kCubeFaceCount; ++i) {
        const CubeFace face = cube_face_from_index(i);
        for (uint32_t y = 0; y < m.face_size; ++y) {
          for (uint32_t x = 0; x < m.face_size; ++x) {
            const Vec3 d = direction_from_texel(face, x, y, m.face_size);
            const double want = wall_distance(m.viewpoints[v].position, d, lo, hi);
            const double got = frame.depth[frame.texel_index(face, x, y)];
            const double err = std::fabs(got - want) / want;
            ++checked;
            if (!(err <= worst)) {
              worst = std::isnan(err) ? INFINITY : err;
              worst_at = "view " + std::to_string(v) + " frame " + std::to_string(f) + " face " +
                         cube_face_name(face) + " texel (" + std::to_string(x) + ", " +
                         std::to_string(y) + "): depth " + std::to_string(got) + ", analytic " +
                         std::to_string(want);
            }
          }
        }
      }
    }
  }
  std::printf("box_room_check: %zu texels, worst relative depth error %.3g at %s\n", checked, worst,
              worst_at.c_str());
  return worst <= tolerance ? 0 : 1;
}
