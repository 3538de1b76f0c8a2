// Test tool (not installed): checks a capture set of an axis-aligned box room, seen from inside,
// with an axis-aligned block standing in it, against calf's own convention. For every texel of
// every face of every view-frame, the radial depth must equal the analytic distance from the
// viewpoint along direction_from_texel to the first of the block's faces and the room's walls,
// within a relative tolerance; where the set has coverage (format/CAPTURE.md "Coverage"), every
// texel's near and far shares and cell mask must equal the analytic ones, from the distances along
// direction_from_texel_coord through each cell's centre. Rendered by another program (the Blender
// add-on, tests/blender/blender_capture.sh), it fails when that program's face order, face
// orientation, planar-to-radial depth conversion or cell order differs from calf's. A texel whose
// centre ray passes within 0.05 of a texel of the block's silhouette may take either side (a
// renderer's centre ray is not exact to the bit), so those texels are counted apart and must stay
// under 3 % of all.
//   box_room_check CAPTURE_DIR ROOM_X0,Y0,Z0,X1,Y1,Z1 BLOCK_X0,Y0,Z0,X1,Y1,Z1 TOLERANCE
// Prints the worst relative error and the number of texels checked; exit 1 on a failure.
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "calf/capture/capture_set.h"
#include "calf/format/cube.h"

namespace {

using namespace calf;

struct Scene {
  Vec3 room_lo, room_hi, block_lo, block_hi;
};

// Distance from `p` (inside the room, outside the block) along unit `d` to the first surface.
double first_hit(const Scene& s, const Vec3& p, const Vec3& d) {
  double t = INFINITY;
  const double pc[3] = {p.x, p.y, p.z}, dc[3] = {d.x, d.y, d.z};
  const double l[3] = {s.room_lo.x, s.room_lo.y, s.room_lo.z};
  const double h[3] = {s.room_hi.x, s.room_hi.y, s.room_hi.z};
  for (int k = 0; k < 3; ++k) {
    if (dc[k] > 0) t = std::min(t, (h[k] - pc[k]) / dc[k]);
    if (dc[k] < 0) t = std::min(t, (l[k] - pc[k]) / dc[k]);
  }
  // The block: slabs.
  const double bl[3] = {s.block_lo.x, s.block_lo.y, s.block_lo.z};
  const double bh[3] = {s.block_hi.x, s.block_hi.y, s.block_hi.z};
  double t0 = 0, t1 = INFINITY;
  for (int k = 0; k < 3; ++k) {
    if (dc[k] == 0) {
      if (pc[k] < bl[k] || pc[k] > bh[k]) return t;
      continue;
    }
    double a = (bl[k] - pc[k]) / dc[k], b = (bh[k] - pc[k]) / dc[k];
    if (a > b) std::swap(a, b);
    t0 = std::max(t0, a);
    t1 = std::min(t1, b);
  }
  return t0 <= t1 ? std::min(t, t0) : t;
}

bool parse_box(const char* text, Vec3* lo, Vec3* hi) {
  double b[6];
  if (std::sscanf(text, "%lf,%lf,%lf,%lf,%lf,%lf", &b[0], &b[1], &b[2], &b[3], &b[4], &b[5]) != 6) {
    return false;
  }
  *lo = {b[0], b[1], b[2]};
  *hi = {b[3], b[4], b[5]};
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  Scene scene;
  if (argc != 5 || !parse_box(argv[2], &scene.room_lo, &scene.room_hi) ||
      !parse_box(argv[3], &scene.block_lo, &scene.block_hi)) {
    std::fprintf(stderr, "usage: box_room_check CAPTURE_DIR ROOM_BOX BLOCK_BOX TOLERANCE\n");
    return 2;
  }
  const double tolerance = std::atof(argv[4]);
  Expected<capture::CaptureSetReader> reader = capture::CaptureSetReader::open(argv[1]);
  if (!reader.ok()) {
    std::fprintf(stderr, "box_room_check: %s\n", reader.status().message().c_str());
    return 1;
  }
  const capture::CaptureManifest& m = reader->manifest();
  capture::ViewFrame frame;
  double worst = 0;
  size_t checked = 0, edge_texels = 0, coverage_checked = 0;
  std::string worst_at = "none";
  const uint32_t n = m.face_size;
  const double tol = std::min(4.0 / n, 0.05);  // CAPTURE.md "Coverage": one surface
  std::string failure;
  for (uint32_t v = 0; v < m.viewpoints.size(); ++v) {
    const Vec3 p = m.viewpoints[v].position;
    for (uint32_t f = 0; f < m.frame_count; ++f) {
      if (Status s = reader->read(v, f, &frame); !s.ok()) {
        std::fprintf(stderr, "box_room_check: %s\n", s.message().c_str());
        return 1;
      }
      for (int i = 0; i < kCubeFaceCount; ++i) {
        const CubeFace face = cube_face_from_index(i);
        for (uint32_t y = 0; y < n; ++y) {
          for (uint32_t x = 0; x < n; ++x) {
            const std::string where = "view " + std::to_string(v) + " frame " + std::to_string(f) +
                                      " face " + cube_face_name(face) + " texel (" +
                                      std::to_string(x) + ", " + std::to_string(y) + ")";
            const double want = first_hit(scene, p, direction_from_texel(face, x, y, n));
            // Near the block's silhouette a centre ray may land on either side.
            bool edge = false;
            for (const double dx : {-0.05, 0.05}) {
              for (const double dy : {-0.05, 0.05}) {
                const double e = first_hit(
                    scene, p, direction_from_texel_coord({face, x + 0.5 + dx, y + 0.5 + dy}, n));
                edge = edge || std::fabs(std::log(e / want)) > tol;
              }
            }
            const size_t t = frame.texel_index(face, x, y);
            const double got = frame.depth[t];
            const double err = std::fabs(got - want) / want;
            ++checked;
            if (edge) {
              ++edge_texels;
              continue;
            }
            if (!(err <= worst)) {
              worst = std::isnan(err) ? INFINITY : err;
              worst_at =
                  where + ": depth " + std::to_string(got) + ", analytic " + std::to_string(want);
            }
            if (!frame.has_coverage) continue;
            // The cells against the analytic centre depth.
            uint32_t near = 0, far = 0, mask = 0;
            for (uint32_t cell = 0; cell < 16; ++cell) {
              const double z =
                  first_hit(scene, p,
                            direction_from_texel_coord(
                                {face, x + (cell % 4 + 0.5) / 4, y + (cell / 4 + 0.5) / 4}, n));
              if (std::fabs(std::log(z / want)) > tol) {
                ++(z < want ? near : far);
              } else {
                mask |= 1u << cell;
              }
            }
            ++coverage_checked;
            // A texel wholly on one surface is exactly (0, 0, 65535); elsewhere a cell whose
            // centre ray passes a silhouette closely may take either side, so at most 2 cells of
            // the mask may differ (a mirrored or transposed cell order differs in many).
            const float* c = &frame.coverage[3 * t];
            const uint32_t got_mask = static_cast<uint32_t>(c[2]);
            const bool bad = near + far == 0 ? (c[0] != 0 || c[1] != 0 || got_mask != 65535)
                                             : std::popcount(got_mask ^ mask) > 2;
            if (bad && failure.empty()) {
              failure = where + ": coverage (" + std::to_string(c[0]) + ", " +
                        std::to_string(c[1]) + ", mask " + std::to_string(got_mask) +
                        "), analytic (" + std::to_string(near / 16.0) + ", " +
                        std::to_string(far / 16.0) + ", mask " + std::to_string(mask) + ")";
            }
          }
        }
      }
    }
  }
  std::printf(
      "box_room_check: %zu texels (%zu beside the block's silhouette), worst relative depth error "
      "%.3g at %s; coverage of %zu texels checked%s%s\n",
      checked, edge_texels, worst, worst_at.c_str(), coverage_checked,
      failure.empty() ? "" : ", FAILED at ", failure.c_str());
  const bool ok = worst <= tolerance && failure.empty() && edge_texels * 100 <= checked * 3;
  return ok ? 0 : 1;
}
