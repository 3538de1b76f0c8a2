// Tile selection (paper 000 Sec. 4.3): a valid tiling picks, for each covered root cell, either
// one of its candidate tilings or the union of valid tilings of its covered children (the And/Or
// tree of the quadtrees). The resources are linear in the selection: triangles (2 per tile), the
// average overdraw (solid angle / 4 pi per tile) and, for each of F 90-degree views from O, the
// modelled fill of the tiles whose centre it sees (their solid angle over the view's 4 units of
// image plane, magnified by 1 / cos^3 off axis, bounded over the view region). The Lagrangian
// relaxation of those bounds decomposes over the tree, so each evaluation is one bottom-up pass;
// the multipliers follow subgradient ascent on the dual (Polyak steps, Fisher 2004) and the best
// feasible selection seen is kept. Every 16th iterate that is infeasible is repaired: its
// multipliers are scaled up by exponential probing and bisection until their selection is
// feasible (as Seurat does once at the end, which is still done when nothing feasible was seen).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "tiles_internal.h"

namespace calf::encoder::tiles {

std::vector<ViewAxes> overdraw_view_axes(uint32_t count) {
  std::vector<ViewAxes> out(count);
  const double golden = 3.14159265358979323846 * (3.0 - std::sqrt(5.0));
  for (uint32_t k = 0; k < count; ++k) {
    const double y = 1.0 - (2.0 * k + 1.0) / count;
    const double r = std::sqrt(std::max(0.0, 1.0 - y * y));
    const double phi = golden * k;
    const Vec3 f{r * std::cos(phi), y, r * std::sin(phi)};
    const Vec3 up = std::abs(y) > 0.99 ? Vec3{0, 0, 1} : Vec3{0, 1, 0};
    const Vec3 right = normalize(cross(f, up));
    out[k] = {f, right, cross(right, f)};
  }
  return out;
}

namespace {

struct CellWeights {
  double area = 0;                                // solid angle / 4 pi (one tile)
  std::vector<std::pair<uint32_t, double>> fill;  // (view, fill of one tile before its bound)
};
struct TilingWeights {
  uint32_t tiles = 0;
  double bound = 0;  // sum over its tiles of the region bound factor
};

struct Totals {
  double triangles = 0, area = 0, distortion = 0;
  std::vector<double> fill;
};

class Selector {
 public:
  Selector(const Candidates& c, const Frame& f, const TilesBuildOptions& o)
      : c_(c), o_(o), views_(overdraw_view_axes(o.overdraw_directions)) {
    cells_.resize(c.cells.size());
    tilings_.resize(c.tilings.size());
    const double four_pi = 4.0 * 3.14159265358979323846;
    for (size_t ci = 0; ci < c.cells.size(); ++ci) {
      const CandidateCell& cell = c.cells[ci];
      const double omega = cell_solid_angle(cell.id, o.tile_dilation);
      cells_[ci].area = omega / four_pi;
      FaceCoord fc;
      fc.face = cube_face_from_index(cell.id.face);
      fc.s = (cell.id.i + 0.5) / double(1u << cell.id.level);
      fc.t = (cell.id.j + 0.5) / double(1u << cell.id.level);
      const Vec3 d = direction_from_face_coord(fc);
      for (uint32_t v = 0; v < views_.size(); ++v) {
        const double z = dot(d, views_[v].forward);
        if (!(z > 0)) continue;
        if (std::abs(dot(d, views_[v].right)) > z || std::abs(dot(d, views_[v].up)) > z) continue;
        cells_[ci].fill.emplace_back(v, omega / (4.0 * z * z * z));
      }
      std::array<Vec3, 4> corner;
      for (int k = 0; k < 4; ++k) corner[k] = cell_corner_direction(cell.id, o.tile_dilation, k);
      for (uint32_t t = cell.first_tiling; t < cell.first_tiling + cell.tiling_count; ++t) {
        const Tiling& tiling = c.tilings[t];
        tilings_[t].tiles = tiling.plane_count;
        for (uint32_t p = tiling.first_plane; p < tiling.first_plane + tiling.plane_count; ++p) {
          double r = 1e300;
          for (const Vec3& cd : corner) r = std::min(r, plane_distance_along(c.planes[p], cd));
          double factor = 1;
          if (o.overdraw_region_bound && f.region_radius > 0) {
            const double near = std::max(r - f.region_radius, 0.25 * r);
            factor = (r / near) * (r / near);
          }
          tilings_[t].bound += factor;
        }
      }
    }
    best_.resize(c.cells.size());
    choice_.resize(c.cells.size());
  }

  size_t view_count() const { return views_.size(); }

  // The selection minimising distortion + sum_j mu_j W_j / Cap_j; returns the dual value
  // (that minimum minus sum_j mu_j) and the selection's totals.
  double evaluate(const std::vector<double>& mu, Totals* totals) {
    const double m_tri = mu[0] / o_.max_triangles;
    const double m_area = mu[1] / o_.max_average_overdraw;
    for (size_t k = c_.cells.size(); k-- > 0;) {
      const CandidateCell& cell = c_.cells[k];
      double fill_price = 0;
      for (const auto& [v, w] : cells_[k].fill) fill_price += mu[2 + v] * w;
      fill_price /= o_.max_peak_overdraw;
      double best = 1e300;
      int32_t choice = -1;
      for (uint32_t t = cell.first_tiling; t < cell.first_tiling + cell.tiling_count; ++t) {
        const TilingWeights& w = tilings_[t];
        const double cost = c_.tilings[t].distortion + m_tri * 2.0 * w.tiles +
                            m_area * cells_[k].area * w.tiles + fill_price * w.bound;
        // The first tiling is taken whatever its cost: prices against a bound near 0 (an
        // overdraw bound of 1e-300) overflow to infinity or NaN, and a cell left with no choice
        // would drop out of the selection, uncovered.
        if (choice < 0 || cost < best) {
          best = cost;
          choice = static_cast<int32_t>(t);
        }
      }
      if (cell.id.level < o_.max_level) {
        double children = 0;
        for (int32_t ch : cell.children) {
          if (ch >= 0) children += best_[ch];
        }
        if (children < best) {
          best = children;
          choice = -1;
        }
      }
      best_[k] = best;
      choice_[k] = choice;
    }
    double dual = 0;
    for (uint32_t r : c_.roots) dual += best_[r];
    for (double m : mu) dual -= m;
    ++evaluations_;
    if (totals) collect(totals, nullptr);
    return dual;
  }

  // The totals (and optionally the tiles) of the last evaluation's selection.
  void collect(Totals* t, std::vector<Selected>* tiles) const {
    t->triangles = t->area = t->distortion = 0;
    t->fill.assign(views_.size(), 0);
    std::vector<uint32_t> stack(c_.roots.rbegin(), c_.roots.rend());
    while (!stack.empty()) {
      const uint32_t k = stack.back();
      stack.pop_back();
      const int32_t choice = choice_[k];
      if (choice < 0) {
        for (int q = 3; q >= 0; --q) {
          if (c_.cells[k].children[q] >= 0) stack.push_back(c_.cells[k].children[q]);
        }
        continue;
      }
      const TilingWeights& w = tilings_[choice];
      t->triangles += 2.0 * w.tiles;
      t->area += cells_[k].area * w.tiles;
      t->distortion += c_.tilings[choice].distortion;
      for (const auto& [v, fw] : cells_[k].fill) t->fill[v] += fw * w.bound;
      if (tiles) {
        const Tiling& tiling = c_.tilings[choice];
        for (uint32_t p = tiling.first_plane; p < tiling.first_plane + tiling.plane_count; ++p) {
          tiles->push_back({c_.cells[k].id, c_.planes[p]});
        }
      }
    }
  }

  bool feasible(const Totals& t) const {
    if (t.triangles > o_.max_triangles) return false;
    if (t.area > o_.max_average_overdraw) return false;
    return peak(t) <= o_.max_peak_overdraw;
  }
  static double peak(const Totals& t) {
    return t.fill.empty() ? 0 : *std::max_element(t.fill.begin(), t.fill.end());
  }
  uint32_t evaluations() const { return evaluations_; }

 private:
  const Candidates& c_;
  const TilesBuildOptions& o_;
  std::vector<ViewAxes> views_;
  std::vector<CellWeights> cells_;
  std::vector<TilingWeights> tilings_;
  std::vector<double> best_;
  std::vector<int32_t> choice_;
  uint32_t evaluations_ = 0;
};

// A bound as the user gave it (%g: 1e-300 stays readable, not 0.000000).
std::string number_text(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

}  // namespace

Expected<Selection> select_tiles(const Candidates& candidates, const Frame& f,
                                 const TilesBuildOptions& options) {
  Selector sel(candidates, f, options);
  const size_t dims = 2 + sel.view_count();
  // One tile per covered root cell is the fewest triangles any valid selection has.
  const uint64_t least_triangles = 2 * uint64_t{candidates.roots.size()};
  if (least_triangles > options.max_triangles) {
    return Status(ErrorId::kTilesBudget,
                  "budget too small to cover the view region: the triangle budget " +
                      std::to_string(options.max_triangles) + " is below the " +
                      std::to_string(least_triangles) +
                      " triangles of one tile per covered root cell (level " +
                      std::to_string(options.min_level) + ")");
  }
  std::vector<double> mu(dims, 0);
  Totals totals;
  Totals coarse;
  sel.evaluate(std::vector<double>(dims, 1e30), &coarse);
  const double scale = std::max(coarse.distortion, 1e-12);

  Selection out;
  std::vector<double> best_mu;
  double best_feasible = 1e300;
  double best_dual = -1e300;
  std::vector<double> best_dual_mu = mu;
  auto consider = [&](const std::vector<double>& m, const Totals& t) {
    if (sel.feasible(t) && t.distortion < best_feasible) {
      best_feasible = t.distortion;
      best_mu = m;
    }
  };
  // Scales multipliers `dir` up until their selection is feasible (doubling, then bisection on
  // the factor), keeping every feasible selection met: a primal selection near `dir`'s prices.
  auto repair = [&](const std::vector<double>& dir, int probes, int halvings) {
    auto at = [&](double c) {
      std::vector<double> m(dims);
      for (size_t j = 0; j < dims; ++j) m[j] = dir[j] * c;
      return m;
    };
    Totals t;
    double hi = 1;
    bool found = false;
    for (int probe = 0; probe < probes; ++probe, hi *= 2) {
      sel.evaluate(at(hi), &t);
      if (sel.feasible(t)) {
        found = true;
        consider(at(hi), t);
        break;
      }
    }
    if (!found) return;
    double lo = hi / 2;
    for (int b = 0; b < halvings; ++b) {
      const double mid = 0.5 * (lo + hi);
      sel.evaluate(at(mid), &t);
      if (sel.feasible(t)) {
        hi = mid;
        consider(at(mid), t);
      } else {
        lo = mid;
      }
    }
  };
  double theta = 2.0;
  uint32_t stalled = 0;
  for (uint32_t it = 0; it < options.selection_iterations; ++it) {
    if (options.progress) options.progress("select", double(it) / options.selection_iterations);
    const double dual = sel.evaluate(mu, &totals);
    consider(mu, totals);
    // Every 16th iteration an infeasible selection is repaired along its own prices: the
    // subgradient's own iterates are rarely feasible, and the kept selection is the best feasible
    // one seen.
    if (it % 16 == 15 && !sel.feasible(totals) &&
        std::any_of(mu.begin(), mu.end(), [](double m) { return m > 0; })) {
      repair(mu, 40, 12);
    }
    if (dual > best_dual + 1e-12 * scale) {
      best_dual = dual;
      best_dual_mu = mu;
      stalled = 0;
    } else if (++stalled >= 8) {
      theta *= 0.5;
      stalled = 0;
    }
    std::vector<double> g(dims);
    g[0] = totals.triangles / options.max_triangles - 1.0;
    g[1] = totals.area / options.max_average_overdraw - 1.0;
    for (size_t v = 0; v < sel.view_count(); ++v) {
      g[2 + v] = totals.fill[v] / options.max_peak_overdraw - 1.0;
    }
    double norm = 0;
    for (size_t j = 0; j < dims; ++j) {
      // Only components that can move (a zero multiplier with slack stays at zero).
      if (mu[j] > 0 || g[j] > 0) norm += g[j] * g[j];
    }
    if (norm == 0) break;  // every constraint met with no price: the optimum without bounds
    // Polyak's step aims at the optimum's value. Until a feasible selection bounds it from above,
    // aim a little above the best dual value: the coarsest selection's distortion (`scale`) can
    // be four orders of magnitude above the optimum, and aiming there threw the multipliers so
    // far that every later selection was degenerate (interior with --tiles-dilation 0.03 kept
    // distortion 2051 against a dual bound of 0.119).
    const double gap = 0.1 * std::abs(best_dual) + 1e-6 * scale;
    const double target = best_feasible < 1e300 ? best_feasible : best_dual + gap;
    const double step = theta * std::max(target - dual, 1e-3 * gap) / norm;
    for (size_t j = 0; j < dims; ++j) mu[j] = std::max(0.0, mu[j] + step * g[j]);
  }

  if (best_feasible == 1e300) {
    // Scale the best dual point's multipliers until the selection is feasible (as Seurat does).
    std::vector<double> dir = best_dual_mu;
    if (std::all_of(dir.begin(), dir.end(), [](double m) { return m == 0; })) {
      dir.assign(dims, scale);
    }
    repair(dir, 80, 30);
  }
  if (best_mu.empty() && sel.feasible(coarse)) best_mu.assign(dims, 1e30);
  if (best_mu.empty()) {
    // No feasible selection: name the bound the most frugal selections still break.
    auto least = [&](size_t j0, size_t j1) {
      std::vector<double> m(dims, 0);
      for (size_t j = j0; j < j1; ++j) m[j] = 1e30;
      Totals t;
      sel.evaluate(m, &t);
      return t;
    };
    const Totals by_area = least(1, 2), by_fill = least(2, dims);
    std::string what;
    if (by_area.area > options.max_average_overdraw) {
      what = "the average overdraw bound " + number_text(options.max_average_overdraw) +
             " is below the " + number_text(by_area.area) + " the covered directions need";
    } else if (Selector::peak(by_fill) > options.max_peak_overdraw) {
      what = "the peak overdraw bound " + number_text(options.max_peak_overdraw) +
             " is below the " + number_text(Selector::peak(by_fill)) +
             " the covered directions need";
    } else {
      what = "no selection meets the triangle, average and peak overdraw bounds together";
    }
    return Status(ErrorId::kTilesBudget, "budget too small to cover the view region: " + what);
  }
  sel.evaluate(best_mu, &totals);
  sel.collect(&totals, &out.tiles);
  if (!sel.feasible(totals)) {
    return Status(ErrorId::kInternal, "tiles selection: the kept selection breaks a bound");
  }
  out.distortion = totals.distortion;
  out.dual_bound = best_dual;
  out.average_overdraw = totals.area;
  out.peak_overdraw = Selector::peak(totals);
  out.evaluations = sel.evaluations();
  if (options.progress) options.progress("select", 1.0);
  return out;
}

}  // namespace calf::encoder::tiles
