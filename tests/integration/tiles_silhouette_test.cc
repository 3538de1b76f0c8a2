// Experiment: where does a tile set put a straight silhouette, against where it is?
// A box room with a square panel (x = 1, rotated 0.3 rad about x so its edges cross pixel rows at
// every sub-pixel phase) in front of the +X wall, captured from 9 viewpoints; the tiles built from
// it are rendered by the CPU reference at a capture viewpoint looking along +X, and each of the
// panel's four edges' signed outward displacement (pixels) is measured against the exact edge.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>

#include "../scratch_dir.h"
#include "calf/capture/capture_set.h"
#include "calf/capture/eye_path.h"
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

// The panel's thickness along x (0: a flat panel); CALF_SIL_DEPTH sets it.
double panel_depth() {
  static const double d = std::getenv("CALF_SIL_DEPTH") ? std::atof(std::getenv("CALF_SIL_DEPTH")) : 0.0;
  return d;
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
  const fs::path dir = test::scratch_dir("tiles_silhouette_test") /
                       ("panel" + std::to_string(n) + "_" + std::to_string(ss) + "_" +
                        std::to_string(panel_depth()));
  capture::CaptureManifest m;
  m.frame_count = 1;
  m.face_size = n;
  m.view_volume = {{-0.25, -0.25, -0.25}, {0.25, 0.25, 0.25}};
  const auto vp = viewpoints(0.25);
  for (size_t k = 0; k < vp.size(); ++k) m.viewpoints.push_back({"v" + std::to_string(k), vp[k]});
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
              const Vec3 d = direction_from_texel_coord(
                  {cf, x + (qx + 0.5) / ss, y + (qy + 0.5) / ss}, n);
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

TEST(TilesSilhouette, EdgeOffsetAtCaptureViewpoints) {
  const char* env = std::getenv("CALF_SIL_FACES");
  std::vector<uint32_t> faces = {64};
  if (env != nullptr) {
    faces.clear();
    for (const char* p = env; *p;) {
      faces.push_back(static_cast<uint32_t>(std::strtoul(p, const_cast<char**>(&p), 10)));
      if (*p == ',') ++p;
    }
  }
  const uint32_t ss = std::getenv("CALF_SIL_SS") ? std::atoi(std::getenv("CALF_SIL_SS")) : 1;
  for (uint32_t n : faces) {
    const fs::path dir = write_capture(n, ss);
    auto reader = capture::CaptureSetReader::open(dir);
    ASSERT_TRUE(reader.ok());
    encoder::TilesBuildOptions o;
    o.threads = 2;
    if (std::getenv("CALF_SIL_CONSTRAINTS")) {
      o.alpha_estimate = encoder::TilesAlphaEstimate::kConstraints;
    }
    encoder::TilesBuildReport report;
    auto set = encoder::build_tiles(*reader, 0, o, &report);
    ASSERT_TRUE(set.ok()) << set.status().to_string();
    const player::TilesLinearAtlas atlas = player::tiles_linear_atlas(*set);
    const auto vp = viewpoints(0.25);
    double mean[4] = {0, 0, 0, 0}, cap_mean[4] = {0, 0, 0, 0};
    capture::ViewFrame view;
    for (uint32_t v = 0; v < vp.size(); ++v) {
      Camera cam;
      cam.position = vp[v];
      cam.forward = {1, 0, 0};
      cam.up = {0, 1, 0};
      cam.width = cam.height = n;
      player::RenderedImage img;
      ASSERT_TRUE(player::render_tiles_cpu(*set, atlas, cam, {}, &img, nullptr).ok());
      const EdgeOffsets t = measure(img.color, vp[v], n);
      // The capture's own +X face as the upright image: pixel (i, j) = texel (n - 1 - i, j).
      ASSERT_TRUE(reader->read(v, 0, &view).ok());
      std::vector<float> cap(3 * size_t{n} * n);
      for (uint32_t j = 0; j < n; ++j) {
        for (uint32_t i = 0; i < n; ++i) {
          const size_t tx = view.texel_index(CubeFace::kPosX, n - 1 - i, j);
          for (int c = 0; c < 3; ++c) cap[3 * (size_t{j} * n + i) + c] = view.color[3 * tx + c];
        }
      }
      const EdgeOffsets c = measure(cap, vp[v], n);
      std::printf("N %u view %u tiles: %+.3f %+.3f %+.3f %+.3f  capture: %+.3f %+.3f %+.3f %+.3f\n",
                  n, v, t.edge[0], t.edge[1], t.edge[2], t.edge[3], c.edge[0], c.edge[1],
                  c.edge[2], c.edge[3]);
      for (int e = 0; e < 4; ++e) {
        mean[e] += t.edge[e] / vp.size();
        cap_mean[e] += c.edge[e] / vp.size();
      }
    }
    const Vec3 novel[6] = {{0.12, -0.07, 0.18}, {-0.15, 0.1, -0.05}, {0.2, 0.2, -0.2},
                           {-0.22, -0.18, 0.1}, {0.05, 0.15, -0.12}, {-0.1, -0.2, -0.2}};
    double nmean[4] = {0, 0, 0, 0}, nabs = 0;
    for (const Vec3& eye : novel) {
      Camera cam;
      cam.position = eye;
      cam.forward = {1, 0, 0};
      cam.up = {0, 1, 0};
      cam.width = cam.height = n;
      player::RenderedImage img;
      ASSERT_TRUE(player::render_tiles_cpu(*set, atlas, cam, {}, &img, nullptr).ok());
      const EdgeOffsets t = measure(img.color, eye, n);
      std::printf("N %u novel (%+.2f %+.2f %+.2f) tiles: %+.3f %+.3f %+.3f %+.3f\n", n, eye.x,
                  eye.y, eye.z, t.edge[0], t.edge[1], t.edge[2], t.edge[3]);
      for (int e = 0; e < 4; ++e) {
        nmean[e] += t.edge[e] / 6;
        nabs += std::abs(t.edge[e]) / 24;
      }
    }
    std::printf("N %u novel mean: %+.3f %+.3f %+.3f %+.3f, mean |offset| %.3f px\n", n, nmean[0],
                nmean[1], nmean[2], nmean[3], nabs);
    std::printf("N %u (%zu tiles) mean tiles: %+.3f %+.3f %+.3f %+.3f  capture: %+.3f %+.3f %+.3f %+.3f\n",
                n, set->tiles.size(), mean[0], mean[1], mean[2], mean[3], cap_mean[0],
                cap_mean[1], cap_mean[2], cap_mean[3]);
  }
}

}  // namespace
}  // namespace calf

namespace calf {
namespace {

// Real data: CALF_SIL_GT (ground-truth dir) against CALF_SIL_RENDER (calf-play --out --format exr
// frames). Per strong horizontal / vertical depth edge of the ground truth (clean on both sides),
// the signed outward offset in pixels of the render's edge (its depth crossing the geometric mean
// of the two sides' depths), as a histogram.
TEST(TilesSilhouette, RealEdgeOffsets) {
  const char* gt_dir = std::getenv("CALF_SIL_GT");
  const char* r_dir = std::getenv("CALF_SIL_RENDER");
  if (gt_dir == nullptr || r_dir == nullptr) GTEST_SKIP();
  long hist[2][9] = {};  // [vertical edges, horizontal edges][offset + 3], 7: none, 8: unused
  double sum[2] = {0, 0};
  long count[2] = {0, 0};
  double csum[2] = {0, 0};
  long ccount[2] = {0, 0};
  for (uint32_t pose = 0;; ++pose) {
    char name[64];
    std::snprintf(name, sizeof name, "gt_%05u.exr", pose);
    const fs::path g = fs::path(gt_dir) / name;
    std::snprintf(name, sizeof name, "frame_%05u.exr", pose);
    const fs::path r = fs::path(r_dir) / name;
    if (!fs::exists(g) || !fs::exists(r)) break;
    auto gi = capture::read_perspective_image(g);
    auto ri = capture::read_perspective_image(r);
    ASSERT_TRUE(gi.ok() && ri.ok());
    const uint32_t w = gi->width, h = gi->height;
    ASSERT_EQ(ri->width, w);
    long ph[2][9] = {};
    double pcsum[2] = {0, 0};
    long pccount[2] = {0, 0};
    for (int dir = 0; dir < 2; ++dir) {
      // dir 0: scan rows (vertical silhouettes), 1: scan columns.
      const uint32_t lines = dir == 0 ? h : w, len = dir == 0 ? w : h;
      const auto at = [&](const std::vector<float>& d, uint32_t line, int k) {
        return dir == 0 ? d[size_t{line} * w + k] : d[size_t(k) * w + line];
      };
      for (uint32_t line = 0; line < lines; ++line) {
        for (int i = 3; i + 4 < int(len); ++i) {
          const float a = at(gi->depth, line, i), b = at(gi->depth, line, i + 1);
          if (!std::isfinite(a) || !std::isfinite(b)) continue;
          const bool fg_left = a < b;
          const float fg = std::min(a, b), bg = std::max(a, b);
          if (bg < 1.3f * fg) continue;
          bool clean = true;
          for (int k = 1; k <= 3; ++k) {
            const float l = at(gi->depth, line, i + 1 - k), rr = at(gi->depth, line, i + k);
            const float want_l = fg_left ? fg : bg, want_r = fg_left ? bg : fg;
            clean &= std::abs(l - want_l) < 0.03f * want_l && std::abs(rr - want_r) < 0.03f * want_r;
          }
          if (!clean) continue;
          {
            // Colour: the foreground's share of the window's pixels, render minus ground truth.
            const auto col = [&](const std::vector<float>& c, int k, int ch) {
              return dir == 0 ? c[3 * (size_t{line} * w + k) + ch] : c[3 * (size_t(k) * w + line) + ch];
            };
            const int kf = fg_left ? i - 2 : i + 3, kb = fg_left ? i + 3 : i - 2;
            double cf[3], cb[3], nn = 0;
            for (int ch = 0; ch < 3; ++ch) {
              cf[ch] = col(gi->color, kf, ch);
              cb[ch] = col(gi->color, kb, ch);
              nn += (cf[ch] - cb[ch]) * (cf[ch] - cb[ch]);
            }
            const double lum = (cf[0] + cf[1] + cf[2] + cb[0] + cb[1] + cb[2]) / 6;
            if (std::sqrt(nn) > 0.3 * lum) {
              double shift = 0;
              for (int k = i - 2; k <= i + 3; ++k) {
                double fr = 0, fgt = 0;
                for (int ch = 0; ch < 3; ++ch) {
                  fr += (col(ri->color, k, ch) - cb[ch]) * (cf[ch] - cb[ch]);
                  fgt += (col(gi->color, k, ch) - cb[ch]) * (cf[ch] - cb[ch]);
                }
                shift += (fr - fgt) / nn;
              }
              csum[dir] += shift;
              ++ccount[dir];
              pcsum[dir] += shift;
              ++pccount[dir];
            }
          }
          const float t = std::sqrt(fg * bg);
          // The render's boundaries k (between k - 1 and k) with the same orientation, nearest
          // to the ground truth's (i + 1).
          int best = 99;
          for (int k = i - 2; k <= i + 4; ++k) {
            const float l = at(ri->depth, line, k - 1), rr = at(ri->depth, line, k);
            const bool l_fg = l < t, r_fg = rr < t;
            if (fg_left ? (l_fg && !r_fg) : (!l_fg && r_fg)) {
              if (std::abs(k - (i + 1)) < std::abs(best)) best = k - (i + 1);
            }
          }
          const int out = best == 99 ? 99 : (fg_left ? best : -best);
          if (std::getenv("CALF_SIL_VERBOSE") && std::atoi(std::getenv("CALF_SIL_VERBOSE")) == int(pose)) {
            std::printf("  dir %d line %u at %d fg %.3f bg %.3f %s out %d\n", dir, line, i, fg, bg,
                        fg_left ? "fg-left" : "fg-right", out);
          }
          const int bin = out == 99 ? 7 : out + 3;
          ++hist[dir][bin];
          ++ph[dir][bin];
          if (out != 99) sum[dir] += out, ++count[dir];
        }
      }
    }
    std::printf("pose %u rows: ", pose);
    for (int b = 0; b < 8; ++b) std::printf("%ld ", ph[0][b]);
    std::printf(" cols: ");
    for (int b = 0; b < 8; ++b) std::printf("%ld ", ph[1][b]);
    std::printf(" colour shift rows %+.3f (%ld) cols %+.3f (%ld)\n",
                pccount[0] ? pcsum[0] / pccount[0] : 0.0, pccount[0],
                pccount[1] ? pcsum[1] / pccount[1] : 0.0, pccount[1]);
  }
  for (int dir = 0; dir < 2; ++dir) {
    std::printf("%s edges, outward offset -3..+3, none: ", dir == 0 ? "vertical" : "horizontal");
    for (int b = 0; b < 8; ++b) std::printf("%ld ", hist[dir][b]);
    std::printf(" mean %+.3f px over %ld; colour shift %+.3f px over %ld\n",
                count[dir] ? sum[dir] / count[dir] : 0.0, count[dir],
                ccount[dir] ? csum[dir] / ccount[dir] : 0.0, ccount[dir]);
  }
}

}  // namespace
}  // namespace calf

namespace calf {
namespace {
// CALF_SIL_DUMP="gt.exr,render.exr,row,col0,col1": both images' pixels along one row.
TEST(TilesSilhouette, DumpRow) {
  const char* spec = std::getenv("CALF_SIL_DUMP");
  if (spec == nullptr) GTEST_SKIP();
  std::string s = spec;
  std::vector<std::string> f;
  for (size_t p = 0;;) {
    const size_t q = s.find(',', p);
    f.push_back(s.substr(p, q - p));
    if (q == std::string::npos) break;
    p = q + 1;
  }
  auto g = capture::read_perspective_image(f[0]);
  auto r = capture::read_perspective_image(f[1]);
  ASSERT_TRUE(g.ok() && r.ok());
  const int row = std::stoi(f[2]), c0 = std::stoi(f[3]), c1 = std::stoi(f[4]);
  for (int c = c0; c <= c1; ++c) {
    const size_t k = size_t(row) * g->width + c;
    std::printf("col %d  gt %.3f %.3f %.3f z %.3f   render %.3f %.3f %.3f z %.3f\n", c,
                g->color[3 * k], g->color[3 * k + 1], g->color[3 * k + 2], g->depth[k],
                r->color[3 * k], r->color[3 * k + 1], r->color[3 * k + 2], r->depth[k]);
  }
}
}  // namespace
}  // namespace calf

#include "calf/decoder/tiles_track.h"
#include "calf/format/bc.h"
#include "calf/format/container.h"

namespace calf {
namespace {
// CALF_SIL_FRAG="clip.calf,eye_path.json,pose,i,j": every tile fragment at pixel (i, j) of the
// pose, back to front, and their composite.
TEST(TilesSilhouette, DumpFragments) {
  const char* spec = std::getenv("CALF_SIL_FRAG");
  if (spec == nullptr) GTEST_SKIP();
  std::string s = spec;
  std::vector<std::string> f;
  for (size_t p = 0;;) {
    const size_t q = s.find(',', p);
    f.push_back(s.substr(p, q - p));
    if (q == std::string::npos) break;
    p = q + 1;
  }
  auto reader = container::Reader::open(f[0]);
  ASSERT_TRUE(reader.ok());
  auto set = decoder::decode_tiles_track(*reader, 0);
  ASSERT_TRUE(set.ok()) << set.status().to_string();
  auto path = capture::read_eye_path(f[1]);
  ASSERT_TRUE(path.ok());
  const Camera cam = capture::camera_from_pose(*path, std::stoi(f[2]));
  const uint32_t pi = std::stoi(f[3]), pj = std::stoi(f[4]);
  const Vec3 d = camera_ray(cam, pi, pj);
  const player::TilesLinearAtlas atlas = player::tiles_linear_atlas(*set);
  std::vector<uint32_t> order;
  player::tiles_back_to_front(*set, cam.position, &order);
  double out[3] = {0, 0, 0};
  for (uint32_t t : order) {
    const Tile& tl = set->tiles[t];
    static constexpr int kTri[2][3] = {{0, 1, 2}, {0, 2, 3}};
    for (const auto& tri : kTri) {
      Vec3 p[3], uvw[3];
      for (int c = 0; c < 3; ++c) {
        const TileCorner& k = tl.corners[tri[c]];
        p[c] = Vec3{k.position[0], k.position[1], k.position[2]} - cam.position;
        uvw[c] = Vec3{k.uvw[0], k.uvw[1], k.uvw[2]};
      }
      const Vec3 n = cross(p[1] - p[0], p[2] - p[0]);
      const double den = dot(n, d);
      if (den == 0) continue;
      const double dist = dot(n, p[0]) / den;
      if (!(dist > 0)) continue;
      const Vec3 x = d * dist;
      const double nn = dot(n, n);
      const double l1 = dot(n, cross(x - p[0], p[2] - p[0])) / nn;
      const double l2 = dot(n, cross(p[1] - p[0], x - p[0])) / nn;
      const double l0 = 1 - l1 - l2;
      if (l0 < 0 || l1 < 0 || l2 < 0) continue;
      const Vec3 q = uvw[0] * l0 + uvw[1] * l1 + uvw[2] * l2;
      const double u = q.x / q.z * atlas.width - 0.5, v = q.y / q.z * atlas.height - 0.5;
      const int x0 = int(std::floor(u)), y0 = int(std::floor(v));
      const double ax = u - x0, ay = v - y0;
      double texel[4] = {0, 0, 0, 0};
      for (int dy = 0; dy < 2; ++dy) {
        for (int dx = 0; dx < 2; ++dx) {
          const size_t k = (size_t(y0 + dy) * atlas.width + (x0 + dx)) * 4;
          const double wgt = (dx ? ax : 1 - ax) * (dy ? ay : 1 - ay);
          for (int c = 0; c < 4; ++c) texel[c] += wgt * bc::half_to_float(atlas.rgba_half[k + c]);
        }
      }
      for (int c = 0; c < 3; ++c) out[c] = texel[c] + (1 - texel[3]) * out[c];
      // The tile's centre and normal.
      Vec3 centre;
      for (const TileCorner& k : tl.corners) centre += Vec3{k.position[0], k.position[1], k.position[2]} * 0.25;
      const Vec3 nu = normalize(n);
      std::printf("tile %u dist %.4f alpha %.3f premult %.3f %.3f %.3f  texel (%.2f, %.2f) centre %.3f %.3f %.3f normal %.2f %.2f %.2f\n",
                  t, dist, texel[3], texel[0], texel[1], texel[2], u, v, centre.x, centre.y,
                  centre.z, nu.x, nu.y, nu.z);
    }
  }
  std::printf("composite %.3f %.3f %.3f\n", out[0], out[1], out[2]);
}
}  // namespace
}  // namespace calf
