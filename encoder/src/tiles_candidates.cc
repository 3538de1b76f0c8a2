// Candidate tiles (paper 000 Sec. 4.2): for every quadtree cell holding points, tilings of
// 1 .. K planes fitted to them by divisive clustering.
//
// Seurat parameterises tiles as discs and minimises E + gamma R + B with Levenberg-Marquardt;
// here a plane is fitted by reweighted total least squares whose weights turn the residual into
// the relative radial error 1 - t_hit of Seurat's energy E (divide by n.q) and clip outliers
// (Huber), started from a RANSAC plane (deterministic: seeded by the cell). Planes that miss a
// corner of the cell's frustum or meet it outside [r_min, r_max] (Seurat's penalty B) are
// rejected rather than penalised; a cell always has the fronto-parallel plane through its
// points' weighted median radius to fall back on.
#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>

#include "tiles_internal.h"

namespace calf::encoder::tiles {

void cell_corner_st(const CellId& c, double dilation, int k, double* s, double* t) {
  const double w = 1.0 / double(1u << c.level);
  const double i = c.i + ((k == 1 || k == 2) ? 1.0 + dilation : -dilation);
  const double j = c.j + ((k == 2 || k == 3) ? 1.0 + dilation : -dilation);
  *s = i * w;
  *t = j * w;
}

Vec3 cell_corner_direction(const CellId& c, double dilation, int k) {
  FaceCoord fc;
  fc.face = cube_face_from_index(c.face);
  cell_corner_st(c, dilation, k, &fc.s, &fc.t);
  return direction_from_face_coord(fc);
}

namespace {

// Solid angle of the spherical triangle (a, b, c) of unit vectors (Van Oosterom & Strackee).
double triangle_solid_angle(const Vec3& a, const Vec3& b, const Vec3& c) {
  const double num = std::abs(dot(a, cross(b, c)));
  const double den = 1.0 + dot(a, b) + dot(b, c) + dot(c, a);
  return 2.0 * std::atan2(num, den);
}

}  // namespace

double cell_solid_angle(const CellId& c, double dilation) {
  std::array<Vec3, 4> d;
  for (int k = 0; k < 4; ++k) d[k] = cell_corner_direction(c, dilation, k);
  return triangle_solid_angle(d[0], d[1], d[2]) + triangle_solid_angle(d[0], d[2], d[3]);
}

double plane_distance_along(const Plane& p, const Vec3& d) {
  const double nd = dot(p.normal, d);
  if (!(nd > 1e-12)) return -1;
  return p.offset / nd;
}

namespace {

// A deterministic random stream (splitmix64).
struct Rng {
  uint64_t state;
  uint64_t next() {
    uint64_t z = (state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  uint32_t below(uint32_t n) { return static_cast<uint32_t>(next() % n); }
};

// Seurat's E(p, t) = (1 - t_hit)^2, capped at 1 (a plane behind or parallel to the point's ray).
double energy(const Plane& p, const Vec3& q) {
  const double nq = dot(p.normal, q);
  if (!(nq > 0)) return 1.0;
  const double e = 1.0 - p.offset / nq;
  return std::min(1.0, e * e);
}

// The eigenvector of the smallest eigenvalue of a symmetric 3x3 matrix (cyclic Jacobi).
Vec3 smallest_eigenvector(std::array<std::array<double, 3>, 3> a) {
  std::array<std::array<double, 3>, 3> v{{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
  for (int sweep = 0; sweep < 24; ++sweep) {
    const double off = a[0][1] * a[0][1] + a[0][2] * a[0][2] + a[1][2] * a[1][2];
    const double diag = a[0][0] * a[0][0] + a[1][1] * a[1][1] + a[2][2] * a[2][2];
    if (off <= 1e-30 * diag || off == 0) break;
    for (int p = 0; p < 2; ++p) {
      for (int q = p + 1; q < 3; ++q) {
        if (a[p][q] == 0) continue;
        const double theta = (a[q][q] - a[p][p]) / (2 * a[p][q]);
        const double t =
            (theta >= 0 ? 1.0 : -1.0) / (std::abs(theta) + std::sqrt(theta * theta + 1));
        const double c = 1 / std::sqrt(t * t + 1), s = t * c;
        for (int k = 0; k < 3; ++k) {
          const double akp = a[k][p], akq = a[k][q];
          a[k][p] = c * akp - s * akq;
          a[k][q] = s * akp + c * akq;
        }
        for (int k = 0; k < 3; ++k) {
          const double apk = a[p][k], aqk = a[q][k];
          a[p][k] = c * apk - s * aqk;
          a[q][k] = s * apk + c * aqk;
        }
        for (int k = 0; k < 3; ++k) {
          const double vkp = v[k][p], vkq = v[k][q];
          v[k][p] = c * vkp - s * vkq;
          v[k][q] = s * vkp + c * vkq;
        }
      }
    }
  }
  int m = 0;
  for (int k = 1; k < 3; ++k) {
    if (a[k][k] < a[m][m]) m = k;
  }
  return {v[0][m], v[1][m], v[2][m]};
}

struct CellFit {
  const std::vector<Vec3>* pos;
  const std::vector<float>* weight;
  std::array<Vec3, 4> corner;  // dilated corner directions
  Vec3 centre;                 // direction through the cell's centre
  double r_min, r_max;
  const TilesBuildOptions* options;

  bool valid(const Plane& p) const {
    if (!(p.offset > 0) || !is_finite(p.normal)) return false;
    for (const Vec3& d : corner) {
      const double r = plane_distance_along(p, d);
      if (!(r >= r_min && r <= r_max)) return false;
    }
    return true;
  }

  // Reweighted total least squares from `start` over points `idx`; false when degenerate.
  bool refit(const std::vector<uint32_t>& idx, const Plane& start, Plane* out) const {
    if (idx.size() < 3) return false;
    Plane p = start;
    const double huber = 3 * options->ransac_threshold;
    for (int iter = 0; iter < 2; ++iter) {
      double sw = 0;
      Vec3 mean;
      std::vector<double> w(idx.size());
      for (size_t k = 0; k < idx.size(); ++k) {
        const Vec3& q = (*pos)[idx[k]];
        const double nq = dot(p.normal, q);
        double omega = (*weight)[idx[k]];
        if (nq > 0) {
          omega /= nq * nq;
          const double res = std::abs(1.0 - p.offset / nq);
          if (res > huber) omega *= huber / res;
        } else {
          omega /= dot(q, q);
        }
        w[k] = omega;
        sw += omega;
        mean += q * omega;
      }
      if (!(sw > 0)) return false;
      mean = mean / sw;
      std::array<std::array<double, 3>, 3> cov{};
      for (size_t k = 0; k < idx.size(); ++k) {
        const Vec3 d = (*pos)[idx[k]] - mean;
        const double e[3] = {d.x, d.y, d.z};
        for (int a = 0; a < 3; ++a) {
          for (int b = 0; b < 3; ++b) cov[a][b] += w[k] * e[a] * e[b];
        }
      }
      Vec3 n = smallest_eigenvector(cov);
      const double len = length(n);
      if (!(len > 0)) return false;
      n = n / len;
      if (dot(n, mean) < 0) n = -n;
      p.normal = n;
      p.offset = dot(n, mean);
      if (!(p.offset > 0)) return false;
    }
    *out = p;
    return true;
  }

  // The plane facing O through the weighted median radius along the cell's centre direction.
  Plane fallback(uint32_t begin, uint32_t end) const {
    std::vector<std::pair<double, float>> r;
    double total = 0;
    for (uint32_t k = begin; k < end; ++k) {
      r.emplace_back(dot(centre, (*pos)[k]), (*weight)[k]);
      total += (*weight)[k];
    }
    std::sort(r.begin(), r.end());
    double acc = 0, median = r.back().first;
    for (const auto& [d, w] : r) {
      acc += w;
      if (acc >= 0.5 * total) {
        median = d;
        break;
      }
    }
    return {centre, std::clamp(median, r_min, 0.5 * r_max)};
  }
};

}  // namespace

Candidates generate_candidates(const MergedPoints& points, const Frame& f,
                               const TilesBuildOptions& options) {
  Candidates out;
  // The cells holding points, breadth first per root so that children follow their parents.
  const uint32_t shift_base = kMortonLevel;
  auto range_of = [&](const CellId& c, uint32_t* begin, uint32_t* end) {
    const uint32_t sh = shift_base - c.level;
    const uint64_t lo = morton_code(c.i << sh, c.j << sh);
    const uint64_t hi = lo + (uint64_t{1} << (2 * sh));
    auto key_less = [&](size_t k, uint8_t face, uint64_t code) {
      return points.face[k] < face || (points.face[k] == face && points.morton[k] < code);
    };
    // Binary searches over the (face, morton) order.
    size_t a = 0, b = points.face.size();
    while (a < b) {
      const size_t m = (a + b) / 2;
      if (key_less(m, c.face, lo))
        a = m + 1;
      else
        b = m;
    }
    size_t a2 = a, b2 = points.face.size();
    while (a2 < b2) {
      const size_t m = (a2 + b2) / 2;
      if (key_less(m, c.face, hi))
        a2 = m + 1;
      else
        b2 = m;
    }
    *begin = static_cast<uint32_t>(a);
    *end = static_cast<uint32_t>(a2);
  };
  const uint32_t roots_per_side = 1u << options.min_level;
  for (uint8_t face = 0; face < 6; ++face) {
    for (uint32_t j = 0; j < roots_per_side; ++j) {
      for (uint32_t i = 0; i < roots_per_side; ++i) {
        CandidateCell cell;
        cell.id = {face, static_cast<uint8_t>(options.min_level), i, j};
        range_of(cell.id, &cell.point_begin, &cell.point_end);
        if (cell.point_begin == cell.point_end) continue;
        out.roots.push_back(static_cast<uint32_t>(out.cells.size()));
        out.cells.push_back(cell);
      }
    }
  }
  for (size_t k = 0; k < out.cells.size(); ++k) {
    const CellId id = out.cells[k].id;
    if (id.level >= options.max_level) continue;
    for (int q = 0; q < 4; ++q) {
      CandidateCell child;
      child.id = {id.face, static_cast<uint8_t>(id.level + 1), 2 * id.i + (q & 1),
                  2 * id.j + (q >> 1)};
      child.parent = static_cast<int32_t>(k);
      range_of(child.id, &child.point_begin, &child.point_end);
      if (child.point_begin == child.point_end) continue;
      out.cells[k].children[q] = static_cast<int32_t>(out.cells.size());
      out.cells.push_back(child);
    }
  }

  // Fits per cell in parallel, each into its own slot.
  struct Local {
    std::vector<Tiling> tilings;
    std::vector<Plane> planes;
  };
  std::vector<Local> local(out.cells.size());
  const double r_min = std::max(1e-9, 0.01 * f.region_radius);
  const double r_max = 4.0 * std::max(points.max_radius, r_min * 4);
  auto fit_cell = [&](size_t ci) {
    const CandidateCell& cell = out.cells[ci];
    CellFit fit{&points.position, &points.weight, {}, {}, r_min, r_max, &options};
    for (int k = 0; k < 4; ++k) {
      fit.corner[k] = cell_corner_direction(cell.id, options.tile_dilation, k);
    }
    {
      FaceCoord fc;
      fc.face = cube_face_from_index(cell.id.face);
      fc.s = (cell.id.i + 0.5) / double(1u << cell.id.level);
      fc.t = (cell.id.j + 0.5) / double(1u << cell.id.level);
      fit.centre = direction_from_face_coord(fc);
    }
    const uint32_t begin = cell.point_begin, end = cell.point_end, n = end - begin;
    double total_weight = 0;
    for (uint32_t k = begin; k < end; ++k) total_weight += points.weight[k];
    if (n < options.min_cell_points && cell.parent >= 0) {
      // Too few points to fit a plane (a fronto-parallel plane through one point fits it
      // exactly and is wrong): the parent's tilings restricted to the planes these points choose.
      const Local& up = local[cell.parent];
      Local& L = local[ci];
      uint32_t last_count = 0;
      double last_d = 1e300;
      for (const Tiling& pt : up.tilings) {
        std::vector<double> chosen(pt.plane_count, -1);
        double d = 0;
        for (uint32_t k = begin; k < end; ++k) {
          double e = 2;
          uint32_t arg = 0;
          for (uint32_t p = 0; p < pt.plane_count; ++p) {
            const double ep = energy(up.planes[pt.first_plane + p], points.position[k]);
            if (ep < e) e = ep, arg = p;
          }
          chosen[arg] = 1;
          d += e * points.weight[k];
        }
        Tiling t;
        t.first_plane = static_cast<uint32_t>(L.planes.size());
        for (uint32_t p = 0; p < pt.plane_count; ++p) {
          const Plane& plane = up.planes[pt.first_plane + p];
          if (chosen[p] > 0 && fit.valid(plane)) L.planes.push_back(plane);
        }
        t.plane_count = static_cast<uint32_t>(L.planes.size()) - t.first_plane;
        t.distortion = d;
        if (t.plane_count > last_count && d < last_d &&
            t.plane_count == std::count(chosen.begin(), chosen.end(), 1.0)) {
          L.tilings.push_back(t);
          last_count = t.plane_count;
          last_d = d;
        } else {
          L.planes.resize(t.first_plane);
        }
      }
      if (!L.tilings.empty()) return;
      L.planes.clear();
    }
    // The strided subset used by RANSAC scoring and intermediate refits.
    std::vector<uint32_t> subset;
    const uint32_t stride = std::max<uint32_t>(1, n / options.refine_sample_limit);
    for (uint32_t k = begin; k < end; k += stride) subset.push_back(k);

    // First plane: RANSAC on the subset, then a robust refit on its inliers.
    Rng rng{(uint64_t{cell.id.face} << 56) ^ (uint64_t{cell.id.level} << 48) ^
            (uint64_t{cell.id.j} << 24) ^ cell.id.i};
    Plane best = fit.fallback(begin, end);
    double best_score = -1;
    if (subset.size() >= 3) {
      for (uint32_t trial = 0; trial < options.ransac_trials; ++trial) {
        const uint32_t a = subset[rng.below(static_cast<uint32_t>(subset.size()))];
        const uint32_t b = subset[rng.below(static_cast<uint32_t>(subset.size()))];
        const uint32_t c = subset[rng.below(static_cast<uint32_t>(subset.size()))];
        Vec3 nrm =
            cross(points.position[b] - points.position[a], points.position[c] - points.position[a]);
        const double len = length(nrm);
        if (!(len > 0)) continue;
        nrm = nrm / len;
        if (dot(nrm, points.position[a]) < 0) nrm = -nrm;
        const Plane p{nrm, dot(nrm, points.position[a])};
        if (!fit.valid(p)) continue;
        double score = 0;
        for (uint32_t k : subset) {
          if (energy(p, points.position[k]) < options.ransac_threshold * options.ransac_threshold) {
            score += points.weight[k];
          }
        }
        if (score > best_score) {
          best_score = score;
          best = p;
        }
      }
    }
    {
      std::vector<uint32_t> inliers;
      const double thr = options.ransac_threshold * options.ransac_threshold;
      for (uint32_t k : subset) {
        if (energy(best, points.position[k]) < thr) inliers.push_back(k);
      }
      Plane refined;
      if (fit.refit(inliers, best, &refined) && fit.valid(refined)) best = refined;
      if (!fit.valid(best)) best = fit.fallback(begin, end);
    }

    Local& L = local[ci];
    std::vector<Plane> planes{best};
    std::vector<uint8_t> assign(n, 0);
    auto assign_all = [&](double* d, std::vector<double>* cluster_energy) {
      *d = 0;
      if (cluster_energy) cluster_energy->assign(planes.size(), 0);
      for (uint32_t k = 0; k < n; ++k) {
        const Vec3& q = points.position[begin + k];
        double e = energy(planes[0], q);
        uint8_t arg = 0;
        for (uint8_t p = 1; p < planes.size(); ++p) {
          const double ep = energy(planes[p], q);
          if (ep < e) {
            e = ep;
            arg = p;
          }
        }
        assign[k] = arg;
        const double we = e * points.weight[begin + k];
        *d += we;
        if (cluster_energy) (*cluster_energy)[arg] += we;
      }
    };
    auto emit = [&](double d) {
      Tiling t;
      t.first_plane = static_cast<uint32_t>(L.planes.size());
      t.plane_count = static_cast<uint32_t>(planes.size());
      t.distortion = d;
      L.planes.insert(L.planes.end(), planes.begin(), planes.end());
      L.tilings.push_back(t);
    };
    double d = 0;
    std::vector<double> cluster_energy;
    assign_all(&d, &cluster_energy);
    emit(d);
    uint32_t emitted_count = 1;
    double emitted_d = d;
    while (planes.size() < options.max_planes && d > options.split_stop_energy * total_weight) {
      // Split the worst cluster: a new fronto-parallel plane through its worst point.
      const size_t worst =
          std::max_element(cluster_energy.begin(), cluster_energy.end()) - cluster_energy.begin();
      double worst_e = -1;
      uint32_t worst_k = 0;
      for (uint32_t k = 0; k < n; ++k) {
        if (assign[k] != worst) continue;
        const double e = energy(planes[worst], points.position[begin + k]);
        if (e > worst_e) {
          worst_e = e;
          worst_k = k;
        }
      }
      const Vec3 q = points.position[begin + worst_k];
      const double r = length(q);
      Plane fresh{q / r, r};
      if (!fit.valid(fresh))
        fresh = Plane{fit.centre, std::clamp(dot(fit.centre, q), r_min, r_max)};
      if (!fit.valid(fresh)) break;
      planes.push_back(fresh);
      for (uint32_t it = 0; it < options.refine_iterations; ++it) {
        std::vector<std::vector<uint32_t>> members(planes.size());
        for (uint32_t k : subset) {
          const Vec3& p = points.position[k];
          double e = energy(planes[0], p);
          size_t arg = 0;
          for (size_t pl = 1; pl < planes.size(); ++pl) {
            const double ep = energy(planes[pl], p);
            if (ep < e) {
              e = ep;
              arg = pl;
            }
          }
          members[arg].push_back(k);
        }
        for (size_t pl = 0; pl < planes.size(); ++pl) {
          Plane refined;
          if (fit.refit(members[pl], planes[pl], &refined) && fit.valid(refined)) {
            planes[pl] = refined;
          }
        }
      }
      assign_all(&d, &cluster_energy);
      // Planes no point chose are dropped.
      std::vector<Plane> kept;
      for (size_t pl = 0; pl < planes.size(); ++pl) {
        if (cluster_energy[pl] > 0 ||
            std::any_of(assign.begin(), assign.end(), [&](uint8_t a) { return a == pl; })) {
          kept.push_back(planes[pl]);
        }
      }
      if (kept.size() != planes.size()) {
        planes = kept;
        assign_all(&d, &cluster_energy);
      }
      if (planes.size() > emitted_count && d < emitted_d) {
        emit(d);
        emitted_count = static_cast<uint32_t>(planes.size());
        emitted_d = d;
      } else {
        break;
      }
    }
  };
  // Level by level (cells are breadth first), so that parents are fitted before their children.
  for (size_t first = 0; first < out.cells.size();) {
    size_t last = first;
    while (last < out.cells.size() && out.cells[last].id.level == out.cells[first].id.level) ++last;
    parallel_for(options.threads, last - first, [&](size_t k) { fit_cell(first + k); });
    first = last;
  }

  for (size_t ci = 0; ci < out.cells.size(); ++ci) {
    out.cells[ci].first_tiling = static_cast<uint32_t>(out.tilings.size());
    out.cells[ci].tiling_count = static_cast<uint32_t>(local[ci].tilings.size());
    const uint32_t plane_base = static_cast<uint32_t>(out.planes.size());
    for (Tiling t : local[ci].tilings) {
      t.first_plane += plane_base;
      out.tilings.push_back(t);
    }
    out.planes.insert(out.planes.end(), local[ci].planes.begin(), local[ci].planes.end());
  }
  return out;
}

}  // namespace calf::encoder::tiles
