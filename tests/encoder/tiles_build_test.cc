// Tests of the tiles builder (encoder/include/calf/encoder/tiles_build.h) on a synthetic capture
// set written here: a box room (six walls of known planes and colours) with a square panel in
// front of the +X wall, seen from three viewpoints at 32^2. Checks: the triangle budget is never
// exceeded, the overdraw is reported and within its bounds, tile corners lie on the scene's
// planes, the atlas reproduces the captured colours at tile centres, the output is byte-identical
// run to run and for 1 and 2 threads, and each error id.
#include "calf/encoder/tiles_build.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "../scratch_dir.h"
#include "calf/format/colour.h"
#include "calf/format/cube.h"

namespace calf {
namespace {

namespace fs = std::filesystem;
using encoder::TilesBuildOptions;
using encoder::TilesBuildReport;

constexpr uint32_t kFace = 32;
// The room's walls: x in [-2, 2], y in [-1.5, 1.5], z in [-2.5, 2.5].
constexpr double kLo[3] = {-2.0, -1.5, -2.5};
constexpr double kHi[3] = {2.0, 1.5, 2.5};
// The panel: x = 1, |y| <= 0.4, |z| <= 0.4, facing the centre.
constexpr double kPanelX = 1.0, kPanelHalf = 0.4;
// Linear colours of walls +X, -X, +Y, -Y, +Z, -Z and of the panel.
constexpr float kColour[7][3] = {{0.8f, 0.2f, 0.2f}, {0.2f, 0.8f, 0.2f}, {0.2f, 0.2f, 0.8f},
                                 {0.8f, 0.8f, 0.2f}, {0.2f, 0.8f, 0.8f}, {0.8f, 0.2f, 0.8f},
                                 {0.9f, 0.9f, 0.9f}};

// The surface a ray from `e` along unit `d` hits first: its distance and index (0-5 walls, 6 the
// panel).
std::pair<double, int> trace(const Vec3& e, const Vec3& d) {
  double best = std::numeric_limits<double>::infinity();
  int hit = -1;
  for (int a = 0; a < 3; ++a) {
    const double da = component(d, a), ea = component(e, a);
    if (da > 0) {
      const double t = (kHi[a] - ea) / da;
      if (t < best) best = t, hit = 2 * a;
    } else if (da < 0) {
      const double t = (kLo[a] - ea) / da;
      if (t < best) best = t, hit = 2 * a + 1;
    }
  }
  if (d.x > 0) {
    const double t = (kPanelX - e.x) / d.x;
    const Vec3 p = e + d * t;
    if (t < best && std::abs(p.y) <= kPanelHalf && std::abs(p.z) <= kPanelHalf) best = t, hit = 6;
  }
  return {best, hit};
}

// Writes the room's capture set (`sky`: every depth +inf instead; `open_top`: the +Y wall is sky,
// still in its colour; `blend_edges`: a texel beside one of another surface holds the mean of
// both colours, as a box-filtered capture's silhouette texels do; `view_half`: the view volume's
// half size around the centre) and returns its directory.
fs::path write_room(const std::string& name, bool sky = false, bool open_top = false,
                    bool blend_edges = false, double view_half = 0.1, float top_depth = 0) {
  const fs::path dir = test::scratch_dir("tiles_build_test") / name;
  capture::CaptureManifest m;
  m.frame_count = 1;
  m.face_size = kFace;
  m.view_volume = {{-view_half, -view_half, -view_half}, {view_half, view_half, view_half}};
  m.viewpoints = {{"centre", {0, 0, 0}}, {"a", {0.1, 0.1, 0.1}}, {"b", {-0.1, -0.05, 0.1}}};
  auto w = capture::CaptureSetWriter::create(dir, m);
  EXPECT_TRUE(w.ok()) << w.status().to_string();
  capture::ViewFrame f;
  f.resize(kFace, false);
  for (uint32_t v = 0; v < m.viewpoints.size(); ++v) {
    for (int face = 0; face < 6; ++face) {
      for (uint32_t y = 0; y < kFace; ++y) {
        for (uint32_t x = 0; x < kFace; ++x) {
          const CubeFace cf = cube_face_from_index(face);
          const size_t t = f.texel_index(cf, x, y);
          const auto [depth, hit] =
              trace(m.viewpoints[v].position, direction_from_texel(cf, x, y, kFace));
          f.depth[t] = sky || (open_top && hit == 2) ? std::numeric_limits<float>::infinity()
                                                     : static_cast<float>(depth);
          if (top_depth > 0 && hit == 2) f.depth[t] = top_depth;
          for (int c = 0; c < 3; ++c) f.color[3 * t + c] = kColour[hit][c];
          if (!blend_edges) continue;
          const int dx[4] = {-1, 1, 0, 0}, dy[4] = {0, 0, -1, 1};
          for (int k = 0; k < 4; ++k) {
            const int nx = static_cast<int>(x) + dx[k], ny = static_cast<int>(y) + dy[k];
            if (nx < 0 || ny < 0 || nx >= int(kFace) || ny >= int(kFace)) continue;
            const int other = trace(m.viewpoints[v].position,
                                    direction_from_texel(cf, uint32_t(nx), uint32_t(ny), kFace))
                                  .second;
            if (other == hit) continue;
            for (int c = 0; c < 3; ++c) {
              f.color[3 * t + c] = 0.5f * (kColour[hit][c] + kColour[other][c]);
            }
            break;
          }
        }
      }
    }
    EXPECT_TRUE(w->write(v, 0, f).ok());
  }
  EXPECT_TRUE(w->finish().ok());
  return dir;
}

const fs::path& room() {
  static const fs::path dir = write_room("room");
  return dir;
}

TilesBuildOptions small_options() {
  TilesBuildOptions o;
  o.min_level = 2;        // 96 roots: at least 192 triangles
  o.max_level = 5;        // leaves of 1 x 1 capture texels at 32^2 (the finest case) ...
  o.min_cell_texels = 0;  // ... which the default would cap at level 3 (4 x 4 texels)
  o.measure_resolution = 32;
  return o;
}

Expected<TileSet> build(const TilesBuildOptions& o, TilesBuildReport* r = nullptr,
                        uint32_t frame = 0, const fs::path& dir = room()) {
  auto reader = capture::CaptureSetReader::open(dir);
  if (!reader.ok()) return reader.status();
  return encoder::build_tiles(*reader, frame, o, r);
}

// The distance from `p` to the nearest of the scene's planes, relative to |p|.
double plane_error(const Vec3& p) {
  double e = std::abs(p.x - kPanelX);
  for (int a = 0; a < 3; ++a) {
    e = std::min(e, std::abs(component(p, a) - kLo[a]));
    e = std::min(e, std::abs(component(p, a) - kHi[a]));
  }
  return e / length(p);
}

TEST(TilesBuild, TriangleBudgetIsNeverExceeded) {
  for (uint32_t budget : {72000u, 2000u, 600u, 200u}) {
    TilesBuildOptions o = small_options();
    o.max_triangles = budget;
    TilesBuildReport r;
    auto set = build(o, &r);
    ASSERT_TRUE(set.ok()) << budget << ": " << set.status().to_string();
    EXPECT_LE(2 * set->tiles.size(), budget);
    EXPECT_EQ(r.triangles, 2 * set->tiles.size());
    // The room is covered in every direction: at least one tile per root cell.
    EXPECT_GE(set->tiles.size(), 96u);
  }
}

TEST(TilesBuild, OverdrawIsReportedWithinItsBounds) {
  TilesBuildOptions o = small_options();
  TilesBuildReport r;
  auto set = build(o, &r);
  ASSERT_TRUE(set.ok()) << set.status().to_string();
  EXPECT_GE(r.measured_views, 126u);
  EXPECT_EQ(r.max_peak_overdraw, 5.0);
  EXPECT_EQ(r.max_average_overdraw, 3.0);
  // One closed room seen from inside: every pixel is covered at least once.
  EXPECT_GE(r.measured_mean_overdraw, 1.0);
  EXPECT_LE(r.model_peak_overdraw, r.max_peak_overdraw);
  EXPECT_LE(r.model_average_overdraw, r.max_average_overdraw);
  EXPECT_LE(r.measured_peak_overdraw, r.max_peak_overdraw);
  EXPECT_LE(r.measured_mean_overdraw, r.max_average_overdraw);
  // Tight bounds (a closed room needs an average of at least 1) are still respected as modelled.
  o.max_peak_overdraw = 2.0;
  o.max_average_overdraw = 1.3;
  auto tight = build(o, &r);
  ASSERT_TRUE(tight.ok()) << tight.status().to_string();
  EXPECT_LE(r.model_peak_overdraw, 2.0);
  EXPECT_LE(r.model_average_overdraw, 1.3);
  EXPECT_LE(r.measured_mean_overdraw, 1.3);
  // The bounds bind here, so the multipliers are searched: the selection kept must stay near the
  // dual bound (measured 0.000677 against 0.000528). Before the periodic repair and the step
  // target at the best dual value it kept 0.00172 against 0.00058, and on the interior scene with
  // --tiles-dilation 0.03 a degenerate selection (2051 against 0.119).
  std::printf("tight bounds: distortion %g, dual bound %g, %u evaluations\n", r.distortion,
              r.dual_bound, r.selection_evaluations);
  EXPECT_GT(r.selection_evaluations, 3u);
  EXPECT_LE(r.distortion, 2 * r.dual_bound + 1e-9);
}

TEST(TilesBuild, LeavesAreNeverFinerThanMinCellTexels) {
  TilesBuildOptions o = small_options();
  TilesBuildReport r;
  ASSERT_TRUE(build(o, &r).ok());
  EXPECT_EQ(r.max_level, 5u);  // off: the levels asked for
  o.min_cell_texels = 4;       // 32 / 2^3 = 4 texels across
  TilesBuildReport capped;
  auto set = build(o, &capped);
  ASSERT_TRUE(set.ok()) << set.status().to_string();
  EXPECT_EQ(capped.min_level, 2u);
  EXPECT_EQ(capped.max_level, 3u);
  o.min_cell_texels = 64;  // coarser than the roots: still one level below them
  ASSERT_TRUE(build(o, &capped).ok());
  EXPECT_EQ(capped.max_level, 3u);
  o.max_level = 2;  // ... unless max_level says otherwise
  ASSERT_TRUE(build(o, &capped).ok());
  EXPECT_EQ(capped.max_level, 2u);
}

TEST(TilesBuild, TileCornersLieOnTheScenePlanes) {
  auto set = build(small_options());
  ASSERT_TRUE(set.ok()) << set.status().to_string();
  size_t on = 0, total = 0;
  for (const Tile& t : set->tiles) {
    for (const TileCorner& c : t.corners) {
      ++total;
      on += plane_error({c.position[0], c.position[1], c.position[2]}) < 0.005;
    }
  }
  // Cells across a wall's or the panel's edge may keep a plane split off through a few outlying
  // points (measured: 92.9 % of corners within 0.5 %); nearly all lie on a scene plane.
  EXPECT_GE(on, total * 90 / 100) << on << " of " << total;
}

// A tile's centre (the mean of its corners) and the atlas texel (RGBA8) at its centre's texture
// coordinates.
std::pair<Vec3, const uint8_t*> centre_texel(const TileSet& set, const Tile& t) {
  Vec3 centre;
  double u = 0, v = 0;
  for (const TileCorner& c : t.corners) {
    centre += Vec3{c.position[0], c.position[1], c.position[2]} * 0.25;
    u += c.uvw[0] / c.uvw[2] * 0.25;
    v += c.uvw[1] / c.uvw[2] * 0.25;
  }
  const uint32_t x =
      std::min<uint32_t>(static_cast<uint32_t>(u * set.atlas_width), set.atlas_width - 1);
  const uint32_t y =
      std::min<uint32_t>(static_cast<uint32_t>(v * set.atlas_height), set.atlas_height - 1);
  return {centre, &set.atlas_rgba[(size_t{y} * set.atlas_width + x) * 4]};
}

// Each check of the texturing below runs with both alpha estimates, and the colour with and
// without the least-squares fit.
std::vector<TilesBuildOptions> texturing_variants() {
  std::vector<TilesBuildOptions> out;
  for (auto alpha :
       {encoder::TilesAlphaEstimate::kViewVotes, encoder::TilesAlphaEstimate::kConstraints}) {
    for (uint32_t solve : {32u, 0u}) {
      TilesBuildOptions o = small_options();
      o.alpha_estimate = alpha;
      o.texture_solve_iterations = solve;
      out.push_back(o);
    }
  }
  return out;
}

std::string variant_name(const TilesBuildOptions& o) {
  return std::string(o.alpha_estimate == encoder::TilesAlphaEstimate::kViewVotes ? "votes"
                                                                                 : "constraints") +
         (o.texture_solve_iterations > 0 ? ", least squares" : ", splat");
}

TEST(TilesBuild, AtlasReproducesCapturedColourAtTileCentres) {
  for (const TilesBuildOptions& variant : texturing_variants()) {
    SCOPED_TRACE(variant_name(variant));
    auto set = build(variant);
    ASSERT_TRUE(set.ok()) << set.status().to_string();
    ASSERT_EQ(set->atlas_rgba.size(), size_t{set->atlas_width} * set->atlas_height * 4);
    size_t checked = 0, good = 0;
    for (const Tile& t : set->tiles) {
      const auto [centre, px] = centre_texel(*set, t);
      if (plane_error(centre) > 0.005) continue;
      const auto [dist, hit] = trace({0, 0, 0}, normalize(centre));
      // Only tiles whose centre is on the surface seen there (not a hidden layer or a sliver).
      if (std::abs(dist - length(centre)) > 0.01 * dist) continue;
      if (px[3] < 250) continue;
      ++checked;
      bool match = true;
      for (int c = 0; c < 3; ++c) {
        match &= std::abs(int(px[c]) - int(srgb8_from_linear(kColour[hit][c]))) <= 3;
      }
      good += match;
    }
    EXPECT_GE(checked, set->tiles.size() / 2);
    EXPECT_GE(good, checked * 95 / 100) << good << " of " << checked;
  }
}

// Samples the texture of every tile on the panel's plane on a g x g grid of its own (bilinear in
// uvw: the tile is planar and its w is constant along the panel's axis, x) and calls fn(m, px):
// m = max(|y|, |z|) of the sample's position (the panel's edge is at m = kPanelHalf), px the
// atlas texel's RGBA8.
template <class Fn>
void for_each_panel_texel(const TileSet& set, int g, const Fn& fn) {
  for (const Tile& t : set.tiles) {
    bool on_panel = true;
    for (const TileCorner& c : t.corners) on_panel &= std::abs(c.position[0] - kPanelX) < 0.01;
    if (!on_panel) continue;
    for (int j = 0; j < g; ++j) {
      for (int i = 0; i < g; ++i) {
        const double a = (i + 0.5) / g, b = (j + 0.5) / g;
        double p[3] = {0, 0, 0}, uvw[3] = {0, 0, 0};
        const double wgt[4] = {(1 - a) * (1 - b), a * (1 - b), a * b, (1 - a) * b};
        for (int k = 0; k < 4; ++k) {
          for (int c = 0; c < 3; ++c) {
            p[c] += wgt[k] * t.corners[k].position[c];
            uvw[c] += wgt[k] * t.corners[k].uvw[c];
          }
        }
        const uint32_t x = std::min<uint32_t>(
            static_cast<uint32_t>(uvw[0] / uvw[2] * set.atlas_width), set.atlas_width - 1);
        const uint32_t y = std::min<uint32_t>(
            static_cast<uint32_t>(uvw[1] / uvw[2] * set.atlas_height), set.atlas_height - 1);
        fn(std::max(std::abs(p[1]), std::abs(p[2])),
           &set.atlas_rgba[(size_t{y} * set.atlas_width + x) * 4]);
      }
    }
  }
}

TEST(TilesBuild, PanelSilhouetteIsCarved) {
  // A tile on the panel's plane reaching past its edge is transparent outside the panel.
  for (const TilesBuildOptions& variant : texturing_variants()) {
    SCOPED_TRACE(variant_name(variant));
    auto set = build(variant);
    ASSERT_TRUE(set.ok()) << set.status().to_string();
    size_t solid_inside = 0, clear_outside = 0, inside = 0, outside = 0;
    for_each_panel_texel(*set, 5, [&](double m, const uint8_t* px) {
      if (std::abs(m - kPanelHalf) < 0.08) return;  // the edge itself may be either
      if (m < kPanelHalf) {
        ++inside;
        solid_inside += px[3] >= 200;
      } else {
        ++outside;
        clear_outside += px[3] <= 55;
      }
    });
    EXPECT_GT(inside, 0u);
    EXPECT_GE(solid_inside, inside * 9 / 10) << solid_inside << " of " << inside;
    if (outside > 0) {
      EXPECT_GE(clear_outside, outside * 9 / 10) << clear_outside << " of " << outside;
    }
  }
}

// Box-filtered silhouette texels (the panel's edge texels half panel, half wall) weigh less in
// the colour fit with edge_colour_weight < 1, so the panel's tiles near its edge keep the
// panel's colour: the mean error there against the panel's colour falls.
TEST(TilesBuild, EdgeTexelsWeighLessInTheColour) {
  static const fs::path blended = write_room("blended", false, false, true);
  const auto panel_edge_error = [](double weight) {
    TilesBuildOptions o = small_options();
    o.edge_colour_weight = weight;
    auto set = build(o, nullptr, 0, blended);
    EXPECT_TRUE(set.ok()) << set.status().to_string();
    double sum = 0;
    size_t n = 0;
    for_each_panel_texel(*set, 8, [&](double m, const uint8_t* px) {
      // Inside the panel, within 0.1 of its edge (about two capture texels there).
      if (m > kPanelHalf - 0.02 || m < kPanelHalf - 0.1) return;
      for (int c = 0; c < 3; ++c) {
        sum += std::abs(int(px[c]) - int(srgb8_from_linear(kColour[6][c])));
      }
      n += 3;
    });
    EXPECT_GT(n, 0u);
    return n ? sum / n : 0.0;
  };
  // Here every view sees the same edge texels blended (the viewpoints are 0.1 apart, the panel
  // 1 away), so only the clean texels beside them can outweigh them: weight 0 drops the blended
  // samples and the edge takes the clean colour beside it (measured 6.5 against 28.5 of 255);
  // the default 0.3 moves a little towards it (27.4).
  const double full = panel_edge_error(1.0), light = panel_edge_error(0.3),
               none = panel_edge_error(0.0);
  RecordProperty("edge_error_weight_1", std::to_string(full));
  RecordProperty("edge_error_weight_0_3", std::to_string(light));
  RecordProperty("edge_error_weight_0", std::to_string(none));
  EXPECT_LT(none, full * 0.5) << "weight 1: " << full << ", 0: " << none;
  EXPECT_LT(light, full) << "weight 1: " << full << ", 0.3: " << light;
}

TEST(TilesBuild, SkyLayerHoldsTheSkyWithinTheBudgets) {
  // The room without its +Y wall: the views see sky there. The sky layer puts one far, opaque
  // tile in the sky's colour on each root cell of +Y (the whole face is sky) and on the side
  // faces' root cells that see over the walls' tops; the set keeps every budget.
  static const fs::path open = write_room("open_top", false, true);
  TilesBuildOptions o = small_options();
  o.max_triangles = 600;
  TilesBuildReport r;
  auto set = build(o, &r, 0, open);
  ASSERT_TRUE(set.ok()) << set.status().to_string();
  const uint32_t roots_per_face = (1u << o.min_level) * (1u << o.min_level);
  EXPECT_GE(r.sky_tiles, roots_per_face);
  EXPECT_LE(r.triangles, o.max_triangles);
  EXPECT_EQ(r.triangles, 2 * set->tiles.size());
  EXPECT_LE(r.model_average_overdraw, o.max_average_overdraw);
  EXPECT_LE(r.model_peak_overdraw, o.max_peak_overdraw);
  EXPECT_LE(r.measured_peak_overdraw, o.max_peak_overdraw);
  // Sky tiles: far beyond the room (100 x its farthest point), opaque, in the +Y wall's colour.
  size_t far = 0, checked = 0;
  for (const Tile& t : set->tiles) {
    const auto [centre, px] = centre_texel(*set, t);
    if (length(centre) < 50) continue;
    ++far;
    if (centre.y < 0.9 * length(centre)) continue;  // a tile of the +Y face's centre region
    ++checked;
    EXPECT_EQ(px[3], 255);
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(int(px[c]), int(srgb8_from_linear(kColour[2][c])), 3) << c;
    }
  }
  EXPECT_EQ(far, r.sky_tiles);
  EXPECT_GT(checked, 0u);
  // Without the layer: no far tile; the closed room has none either.
  o.sky_layer = false;
  auto bare = build(o, &r, 0, open);
  ASSERT_TRUE(bare.ok());
  EXPECT_EQ(r.sky_tiles, 0u);
  auto closed = build(small_options(), &r);
  ASSERT_TRUE(closed.ok());
  EXPECT_EQ(r.sky_tiles, 0u);
  // A budget the sky layer alone uses up is refused, naming the sky.
  o.sky_layer = true;
  o.max_triangles = 2 * roots_per_face;
  auto tight = build(o, nullptr, 0, open);
  ASSERT_FALSE(tight.ok());
  EXPECT_EQ(tight.status().id(), ErrorId::kTilesBudget);
  EXPECT_NE(tight.status().message().find("sky"), std::string::npos) << tight.status().to_string();
}

bool same(const TileSet& a, const TileSet& b) {
  if (a.tiles.size() != b.tiles.size() || a.atlas_width != b.atlas_width ||
      a.atlas_height != b.atlas_height || a.atlas_rgba != b.atlas_rgba) {
    return false;
  }
  for (size_t k = 0; k < a.tiles.size(); ++k) {
    for (int c = 0; c < 4; ++c) {
      if (a.tiles[k].corners[c].position != b.tiles[k].corners[c].position ||
          a.tiles[k].corners[c].uvw != b.tiles[k].corners[c].uvw) {
        return false;
      }
    }
  }
  return true;
}

TEST(TilesBuild, DeterministicForAnyThreadCount) {
  TilesBuildOptions o = small_options();
  o.max_triangles = 1000;
  auto a = build(o);
  auto b = build(o);
  o.threads = 2;
  auto c = build(o);
  ASSERT_TRUE(a.ok() && b.ok() && c.ok());
  EXPECT_TRUE(same(*a, *b));
  EXPECT_TRUE(same(*a, *c));
}

// solid_threshold 0 resolves from the capture's face size (32² here): the RANSAC threshold plus
// 1.25 texel angles, written out; a given threshold is used as it is.
TEST(TilesBuild, SolidThresholdFollowsTheCaptureResolution) {
  TilesBuildOptions o = small_options();
  TilesBuildReport r;
  ASSERT_TRUE(build(o, &r).ok());
  EXPECT_NEAR(r.solid_threshold, 0.01 + 1.25 * (std::acos(-1.0) / 2) / 32, 1e-12);
  o.ransac_threshold = 0.02;
  ASSERT_TRUE(build(o, &r).ok());
  EXPECT_NEAR(r.solid_threshold, 0.02 + 1.25 * (std::acos(-1.0) / 2) / 32, 1e-12);
  o.solid_threshold = 0.05;
  ASSERT_TRUE(build(o, &r).ok());
  EXPECT_EQ(r.solid_threshold, 0.05);
  EXPECT_NE(encoder::format_tiles_report(r).find("solid threshold 0.0500"), std::string::npos);
}

TEST(TilesBuild, Errors) {
  TilesBuildOptions o = small_options();
  auto frame = build(o, nullptr, 1);
  ASSERT_FALSE(frame.ok());
  EXPECT_EQ(frame.status().id(), ErrorId::kTilesFrame) << frame.status().to_string();
  EXPECT_NE(frame.status().message().find("frame 1"), std::string::npos);

  auto empty = build(o, nullptr, 0, write_room("sky", true));
  ASSERT_FALSE(empty.ok());
  EXPECT_EQ(empty.status().id(), ErrorId::kTilesEmpty) << empty.status().to_string();

  o.max_triangles = 100;  // below 2 x 96 root cells
  auto budget = build(o);
  ASSERT_FALSE(budget.ok());
  EXPECT_EQ(budget.status().id(), ErrorId::kTilesBudget) << budget.status().to_string();
  EXPECT_NE(budget.status().message().find("192"), std::string::npos)
      << budget.status().to_string();
  EXPECT_EQ(budget.status().message().find("inside the view region"), std::string::npos)
      << budget.status().to_string();
  // A capture around its content (the view volume, 2.4 on each side, holds the panel and the
  // x and y walls): the same budget error says that most of the surface lies inside the region,
  // which no budget cures, and stays one line.
  auto around = build(o, nullptr, 0, write_room("around", false, false, false, 2.4));
  ASSERT_FALSE(around.ok());
  EXPECT_EQ(around.status().id(), ErrorId::kTilesBudget) << around.status().to_string();
  EXPECT_NE(around.status().message().find("of the captured surface lies inside the view region"),
            std::string::npos)
      << around.status().to_string();
  EXPECT_EQ(around.status().message().find('\n'), std::string::npos);

  o = small_options();
  o.max_average_overdraw = 0.5;  // a closed room needs at least 1
  auto area = build(o);
  ASSERT_FALSE(area.ok());
  EXPECT_EQ(area.status().id(), ErrorId::kTilesBudget) << area.status().to_string();

  o = small_options();
  o.max_planes = 0;
  auto option = build(o);
  ASSERT_FALSE(option.ok());
  EXPECT_EQ(option.status().id(), ErrorId::kTilesOption);
  EXPECT_NE(option.status().message().find("max_planes"), std::string::npos);

  // Each double option outside its range: CALF-E250 naming it.
  struct BadDouble {
    double TilesBuildOptions::*field;
    const char* name;
    std::vector<double> values;
  };
  const BadDouble bad_doubles[] = {
      {&TilesBuildOptions::secondary_colour_weight,
       "secondary_colour_weight",
       {-0.5, 1.5, std::nan("")}},
      {&TilesBuildOptions::edge_colour_weight, "edge_colour_weight", {-0.5, 1.5, std::nan("")}},
      {&TilesBuildOptions::solid_threshold, "solid_threshold", {-0.01, 1.0, std::nan("")}},
      {&TilesBuildOptions::edge_depth_ratio, "edge_depth_ratio", {0.0, -1.0, 101.0, std::nan("")}},
  };
  for (const BadDouble& bad : bad_doubles) {
    for (double value : bad.values) {
      o = small_options();
      o.*bad.field = value;
      auto result = build(o);
      ASSERT_FALSE(result.ok()) << bad.name << " " << value;
      EXPECT_EQ(result.status().id(), ErrorId::kTilesOption) << bad.name;
      EXPECT_NE(result.status().message().find(bad.name), std::string::npos) << bad.name;
    }
  }

  // A valid but far depth (CAPTURE.md allows any finite one): an input error, not the track
  // encoder's internal-consistency E214.
  auto far = build(small_options(), nullptr, 0, write_room("far", false, false, false, 0.1, 1e30f));
  ASSERT_FALSE(far.ok());
  EXPECT_EQ(far.status().id(), ErrorId::kEncoderInput) << far.status().to_string();
  auto near_enough =
      build(small_options(), nullptr, 0, write_room("far-1e6", false, false, false, 0.1, 1e6f));
  EXPECT_TRUE(near_enough.ok()) << near_enough.status().to_string();

  // Bounds so near 0 that the selection's prices overflow: still E253, never a tile set that
  // covers nothing.
  for (const double bound : {1e-300, 1e-30}) {
    for (const bool peak : {false, true}) {
      o = small_options();
      (peak ? o.max_peak_overdraw : o.max_average_overdraw) = bound;
      auto tiny = build(o);
      ASSERT_FALSE(tiny.ok()) << bound << " peak " << peak << ": " << tiny->tiles.size()
                              << " tiles";
      EXPECT_EQ(tiny.status().id(), ErrorId::kTilesBudget) << tiny.status().to_string();
      EXPECT_NE(tiny.status().message().find(peak ? "peak" : "average"), std::string::npos)
          << tiny.status().to_string();
    }
  }

  // The iteration and trial counts have upper bounds.
  struct BadCount {
    uint32_t TilesBuildOptions::*field;
    const char* name;
    uint32_t above;
  };
  const BadCount bad_counts[] = {
      {&TilesBuildOptions::ransac_trials, "ransac_trials", 4097},
      {&TilesBuildOptions::refine_iterations, "refine_iterations", 257},
      {&TilesBuildOptions::selection_iterations, "selection_iterations", 20001},
  };
  for (const BadCount& bad : bad_counts) {
    for (const uint32_t value : {0u, bad.above, 1000000000u}) {
      o = small_options();
      o.*bad.field = value;
      const Status s = encoder::validate_tiles_build_options(o);
      EXPECT_EQ(s.id(), ErrorId::kTilesOption) << bad.name << " " << value;
      EXPECT_NE(s.message().find(bad.name), std::string::npos) << s.to_string();
    }
    o = small_options();
    o.*bad.field = bad.above - 1;
    EXPECT_TRUE(encoder::validate_tiles_build_options(o).ok()) << bad.name;
  }

  o = small_options();
  o.max_atlas_size = 16;
  auto atlas = build(o);
  ASSERT_FALSE(atlas.ok());
  EXPECT_EQ(atlas.status().id(), ErrorId::kTilesAtlas) << atlas.status().to_string();
}

}  // namespace
}  // namespace calf
