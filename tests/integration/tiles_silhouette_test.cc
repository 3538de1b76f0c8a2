// Where a tile set puts a straight silhouette, against where it is (texel, tile, alpha
// and atlas conventions end to end). A box room with a square panel (x = 1, rotated 0.3 rad about
// x so its edges cross pixel rows at every sub-pixel phase) in front of the +X wall, captured from
// 9 viewpoints (colour box-filtered over the texel, depth of its centre ray, as calf-capture);
// the tiles built from it are rendered by the CPU reference looking along +X from every capture
// viewpoint and from 6 novel eyes, and each of the panel's four edges' signed outward
// displacement in pixels is measured from the green channel against the exact edge. A half-texel
// error anywhere between the capture's texel centres and the renderer's sampling moves an edge by
// about 0.5 px (a flat panel: 0.5 px outward on two edges and inward on the others; measured with
// the conventions right: |offset| <= 0.12 px per view, means within 0.1 px at 64^2).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <string>

#include "../scratch_dir.h"
#include "calf/capture/capture_set.h"
#include "calf/encoder/tiles_build.h"
#include "calf/format/camera.h"
#include "calf/format/cube.h"
#include "calf/player/tiles_renderer.h"

namespace calf {
namespace {

namespace fs = std::filesystem;

constexpr double kLo[3] = {-2.0, -1.5, -2.5};
constexpr double kHi[3] = {2.0, 1.5, 2.5};
constexpr double kPanelX = 1.0, kPanelHalf = 0.3, kAngle = 0.3;
constexpr float kWall[3] = {0.8f, 0.2f, 0.2f};
constexpr float kPanel[3] = {0.9f, 0.9f, 0.9f};

// The panel's own coordinates of a point (y, z) of its plane.
void panel_local(double y, double z, double* a, double* b) {
  const double c = std::cos(kAngle), s = std::sin(kAngle);
  *a = c * y + s * z;
  *b = -s * y + c * z;
}

// The panel's thickness along x (0: a flat panel; a box otherwise, whose side faces the off-centre
// viewpoints see).
double g_depth = 0;
double panel_depth() {
  return g_depth;
}

// Distance and whether the panel (else a wall) is hit first.
std::pair<double, bool> trace(const Vec3& e, const Vec3& d) {
  double best = std::numeric_limits<double>::infinity();
  for (int a = 0; a < 3; ++a) {
    const double da = component(d, a), ea = component(e, a);
    if (da > 0) best = std::min(best, (kHi[a] - ea) / da);
    if (da < 0) best = std::min(best, (kLo[a] - ea) / da);
  }
  // The panel as a box in its own frame (x, a, b): slab test.
  double o[3], v[3];
  o[0] = e.x, v[0] = d.x;
  panel_local(e.y, e.z, &o[1], &o[2]);
  panel_local(d.y, d.z, &v[1], &v[2]);
  const double lo[3] = {kPanelX, -kPanelHalf, -kPanelHalf};
  const double hi[3] = {kPanelX + panel_depth(), kPanelHalf, kPanelHalf};
  double t0 = 0, t1 = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 3; ++k) {
    if (v[k] == 0) {
      if (o[k] < lo[k] || o[k] > hi[k]) return {best, false};
      continue;
    }
    double a = (lo[k] - o[k]) / v[k], b = (hi[k] - o[k]) / v[k];
    if (a > b) std::swap(a, b);
    t0 = std::max(t0, a);
    t1 = std::min(t1, b);
  }
  if (t0 <= t1 && t0 < best) return {t0, true};
  return {best, false};
}

std::vector<Vec3> viewpoints(double r) {
  std::vector<Vec3> v = {{0, 0, 0}};
  for (int k = 0; k < 8; ++k) v.push_back({k & 1 ? r : -r, k & 2 ? r : -r, k & 4 ? r : -r});
  return v;
}

// Colour box-filtered over the texel (ss x ss), depth of the centre ray: calf-capture's rule.
fs::path write_capture(uint32_t n, uint32_t ss) {
  std::string name = "panel";  // appends, not operator+: GCC 12 -O3 misfires -Wrestrict on it
  for (const std::string& part :
       {std::to_string(n), std::to_string(ss), std::to_string(panel_depth())}) {
    name += '_';
    name += part;
  }
  const fs::path dir = test::scratch_dir("tiles_silhouette_test") / name;
  capture::CaptureManifest m;
  m.frame_count = 1;
  m.face_size = n;
  m.view_volume = {{-0.25, -0.25, -0.25}, {0.25, 0.25, 0.25}};
  const auto vp = viewpoints(0.25);
  for (size_t k = 0; k < vp.size(); ++k) {
    std::string id = "v";
    id += std::to_string(k);
    m.viewpoints.push_back({id, vp[k]});
  }
  auto w = capture::CaptureSetWriter::create(dir, m);
  EXPECT_TRUE(w.ok()) << w.status().to_string();
  capture::ViewFrame f;
  f.resize(n, false);
  for (uint32_t v = 0; v < vp.size(); ++v) {
    for (int face = 0; face < 6; ++face) {
      const CubeFace cf = cube_face_from_index(face);
      for (uint32_t y = 0; y < n; ++y) {
        for (uint32_t x = 0; x < n; ++x) {
          const size_t t = f.texel_index(cf, x, y);
          f.depth[t] = static_cast<float>(trace(vp[v], direction_from_texel(cf, x, y, n)).first);
          float c[3] = {0, 0, 0};
          for (uint32_t qy = 0; qy < ss; ++qy) {
            for (uint32_t qx = 0; qx < ss; ++qx) {
              const Vec3 d =
                  direction_from_texel_coord({cf, x + (qx + 0.5) / ss, y + (qy + 0.5) / ss}, n);
              const bool panel = trace(vp[v], d).second;
              for (int ch = 0; ch < 3; ++ch) c[ch] += (panel ? kPanel : kWall)[ch];
            }
          }
          // Only the +X wall and the panel matter; other walls get the wall colour too.
          for (int ch = 0; ch < 3; ++ch) f.color[3 * t + ch] = c[ch] / float(ss * ss);
        }
      }
    }
    EXPECT_TRUE(w->write(v, 0, f).ok());
  }
  EXPECT_TRUE(w->finish().ok());
  return dir;
}

struct EdgeOffsets {
  double edge[4] = {0, 0, 0, 0};  // outward displacement in pixels: +a, -a, +b, -b edges
};

// Signed outward displacement of the panel's edges in `image` (linear RGB, N x N, camera at `eye`
// along +X, up +Y), from the green channel's panel fraction against the exact coverage.
EdgeOffsets measure(const std::vector<float>& rgb, const Vec3& eye, uint32_t n) {
  Camera cam;
  cam.position = eye;
  cam.forward = {1, 0, 0};
  cam.up = {0, 1, 0};
  cam.width = cam.height = n;
  const CameraFrame fr = camera_frame(cam);
  const double ps = 2.0 * (kPanelX - eye.x) / n;  // pixel footprint on the panel's plane
  const double band = std::max(5 * ps, panel_depth() > 0 ? 0.12 : 0.0);
  const auto hit = [&](double i, double j) {
    const double a = 2.0 * i / n - 1.0, b = 1.0 - 2.0 * j / n;
    const Vec3 d = fr.forward + fr.right * a + fr.up * b;
    const double t = (kPanelX - eye.x) / d.x;
    return Vec3{kPanelX, eye.y + d.y * t, eye.z + d.z * t};
  };
  EdgeOffsets out;
  double sum[4] = {0, 0, 0, 0};
  constexpr int kSs = 8;
  for (uint32_t j = 0; j < n; ++j) {
    for (uint32_t i = 0; i < n; ++i) {
      const Vec3 p = hit(i + 0.5, j + 0.5);
      double a, b;
      panel_local(p.y, p.z, &a, &b);
      int e;
      if (std::abs(std::abs(a) - kPanelHalf) < band && std::abs(b) < kPanelHalf - band) {
        e = a > 0 ? 0 : 1;
      } else if (std::abs(std::abs(b) - kPanelHalf) < band && std::abs(a) < kPanelHalf - band) {
        e = b > 0 ? 2 : 3;
      } else {
        continue;
      }
      int in = 0;
      for (int qy = 0; qy < kSs; ++qy) {
        for (int qx = 0; qx < kSs; ++qx) {
          const Vec3 q = hit(i + (qx + 0.5) / kSs, j + (qy + 0.5) / kSs);
          in += trace(eye, normalize(q - eye)).second;
        }
      }
      const double truth = double(in) / (kSs * kSs);
      const double g = rgb[3 * (size_t{j} * n + i) + 1];
      const double f = (g - kWall[1]) / (kPanel[1] - kWall[1]);
      sum[e] += f - truth;
    }
  }
  const double len = 2 * (kPanelHalf - band);
  for (int e = 0; e < 4; ++e) out.edge[e] = sum[e] * ps * ps / len / ps;
  return out;
}

TEST(TilesSilhouette, EdgesStayWithinAFractionOfAPixel) {
  constexpr uint32_t n = 64;
  for (double depth : {0.0, 0.3}) {
    SCOPED_TRACE(depth);
    g_depth = depth;
    const fs::path dir = write_capture(n, 4);
    auto reader = capture::CaptureSetReader::open(dir);
    ASSERT_TRUE(reader.ok());
    encoder::TilesBuildOptions o;
    o.threads = 2;
    auto set = encoder::build_tiles(*reader, 0, o, nullptr);
    ASSERT_TRUE(set.ok()) << set.status().to_string();
    const player::TilesLinearAtlas atlas = player::tiles_linear_atlas(*set);
    std::vector<Vec3> eyes = viewpoints(0.25);
    const size_t capture_views = eyes.size();
    for (const Vec3& e :
         {Vec3{0.12, -0.07, 0.18}, Vec3{-0.15, 0.1, -0.05}, Vec3{0.2, 0.2, -0.2},
          Vec3{-0.22, -0.18, 0.1}, Vec3{0.05, 0.15, -0.12}, Vec3{-0.1, -0.2, -0.2}}) {
      eyes.push_back(e);
    }
    double mean[4] = {0, 0, 0, 0};
    for (size_t v = 0; v < eyes.size(); ++v) {
      Camera cam;
      cam.position = eyes[v];
      cam.forward = {1, 0, 0};
      cam.up = {0, 1, 0};
      cam.width = cam.height = n;
      player::RenderedImage img;
      ASSERT_TRUE(player::render_tiles_cpu(*set, atlas, cam, {}, &img, nullptr).ok());
      const EdgeOffsets t = measure(img.color, eyes[v], n);
      std::printf("panel depth %.1f, %s %zu: edge offsets %+.3f %+.3f %+.3f %+.3f px\n", depth,
                  v < capture_views ? "capture viewpoint" : "novel eye", v, t.edge[0], t.edge[1],
                  t.edge[2], t.edge[3]);
      for (int e = 0; e < 4; ++e) {
        EXPECT_LT(std::abs(t.edge[e]), 0.3) << "eye " << v << " edge " << e;
        mean[e] += t.edge[e] / eyes.size();
      }
    }
    for (int e = 0; e < 4; ++e) EXPECT_LT(std::abs(mean[e]), 0.15) << "edge " << e;
  }
}

}  // namespace
}  // namespace calf
