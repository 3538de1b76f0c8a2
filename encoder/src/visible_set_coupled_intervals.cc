// Coupled motion (paper 004 Sec. 3.2, Eqs. 3-4): the coverage intervals of a moving triangle or
// sphere at one pixel while the eye moves with the same parameter, and depth compositing of their
// rational depths. visible_set_coupled.h states the functions; this file says why they are right.
#include <algorithm>
#include <cmath>

#include "visible_set_coupled.h"

namespace calf::encoder::visibility {
namespace {

// Bisection stops here at the latest; [0, 1] halved 100 times is far below any interval that
// min_interval lets count, and the loop also stops once the midpoint is an end (the last bit).
constexpr int kMaxHalvings = 100;
// Crossings of two depth curves of which one is a sphere's are sampled this finely, then bisected.
constexpr int kSphereSamples = 64;

double horner(const double* c, int deg, double t) {
  double v = c[deg];
  for (int i = deg - 1; i >= 0; --i) v = v * t + c[i];
  return v;
}

int sign(double v) {
  return v > 0 ? 1 : v < 0 ? -1 : 0;
}

// The root of f in (x0, x1) where f(x0), f(x1) have strictly opposite signs (f0 = sign f(x0)).
template <typename F>
double bisect(F&& f, double x0, double x1, int s0) {
  for (int i = 0; i < kMaxHalvings; ++i) {
    const double mid = 0.5 * (x0 + x1);
    if (!(mid > x0 && mid < x1)) break;
    const int sm = sign(f(mid));
    if (sm == 0) return mid;
    if (sm == s0) {
      x0 = mid;
    } else {
      x1 = mid;
    }
  }
  return 0.5 * (x0 + x1);
}

// Insertion sort of a few cut times (std::sort on these small arrays trips GCC's
// -Warray-bounds).
void sort_small(double* a, int n) {
  for (int i = 1; i < n; ++i) {
    const double v = a[i];
    int j = i;
    for (; j > 0 && a[j - 1] > v; --j) a[j] = a[j - 1];
    a[j] = v;
  }
}

Vec3 cross_sum(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  return cross(a, b) + cross(c, d);
}

bool lex_less(const Vec3& a, const Vec3& b) {
  if (a.x != b.x) return a.x < b.x;
  if (a.y != b.y) return a.y < b.y;
  return a.z < b.z;
}

// True when c[0] + ... + c[deg] t^deg (deg <= 5) keeps one strict sign on [lo, hi], shown by its
// Bernstein coefficients there all having that sign (the polynomial is their convex combination).
// A cheap exclusion before root isolation; false when in doubt.
bool one_sign_on(const double* c, int deg, double lo, double hi) {
  // Taylor shift to lo, scale to u in [0, 1]: q(u) = p(lo + (hi - lo) u).
  double q[6];
  std::copy_n(c, deg + 1, q);
  for (int i = 0; i < deg; ++i)
    for (int j = deg - 1; j >= i; --j) q[j] += lo * q[j + 1];
  const double h = hi - lo;
  double scale = 1;
  for (int i = 0; i <= deg; ++i) q[i] *= scale, scale *= h;
  // b_k = sum_{i <= k} C(k, i) / C(deg, i) q_i.
  static constexpr double kBinomial[6][6] = {{1, 0, 0, 0, 0, 0}, {1, 1, 0, 0, 0, 0},
                                             {1, 2, 1, 0, 0, 0}, {1, 3, 3, 1, 0, 0},
                                             {1, 4, 6, 4, 1, 0}, {1, 5, 10, 10, 5, 1}};
  int first = 0;
  for (int k = 0; k <= deg; ++k) {
    double b = 0;
    for (int i = 0; i <= k; ++i) b += kBinomial[k][i] / kBinomial[deg][i] * q[i];
    const int s = sign(b);
    if (s == 0 || (k > 0 && s != first)) return false;
    first = s;
  }
  return true;
}

}  // namespace

int polynomial_roots(const double* c, int deg, double lo, double hi, double* out) {
  while (deg > 0 && c[deg] == 0) --deg;
  if (deg <= 0) return 0;
  int n = 0;
  auto emit = [&](double r) {
    if (r > lo && r < hi && (n == 0 || r > out[n - 1])) out[n++] = r;
  };
  if (deg == 1) {
    emit(-c[0] / c[1]);
    return n;
  }
  if (deg == 2) {
    const double disc = c[1] * c[1] - 4 * c[2] * c[0];
    if (disc < 0) return 0;
    // Stable form; -c gives q' = -q exactly, hence the same roots.
    const double q = -0.5 * (c[1] + std::copysign(std::sqrt(disc), c[1]));
    double r0 = q / c[2], r1 = q != 0 ? c[0] / q : r0;
    if (r1 < r0) std::swap(r0, r1);
    emit(r0);
    emit(r1);
    return n;
  }
  // Monotone pieces between the derivative's roots: one sign change each at most.
  double dc[5], crit[5];
  for (int i = 0; i < deg; ++i) dc[i] = (i + 1) * c[i + 1];
  const int nc = polynomial_roots(dc, deg - 1, lo, hi, crit);
  double x0 = lo;
  double f0 = horner(c, deg, lo);
  for (int i = 0; i <= nc; ++i) {
    const double x1 = i < nc ? crit[i] : hi;
    const double f1 = horner(c, deg, x1);
    if (sign(f0) * sign(f1) < 0)
      emit(bisect([&](double t) { return horner(c, deg, t); }, x0, x1, sign(f0)));
    if (i < nc && f1 == 0) emit(x1);
    x0 = x1, f0 = f1;
  }
  return n;
}

void setup_coupled_triangle(const Vec3* c0, const Vec3* c1, const Vec3& v0, const Vec3& w,
                            const FaceBasis& f, CoupledTriangleSetup* out) {
  const Vec3 zero{};
  for (int k = 0; k < 3; ++k) {
    // Canonical order by (position at the first frame, then at the second): a shared edge gives
    // both of its triangles the same coefficients, negated, hence the same event times.
    int ip = k, iq = (k + 1) % 3;
    double sign_k = 1;
    if (lex_less(c0[iq], c0[ip]) || (c0[iq] == c0[ip] && lex_less(c1[iq], c1[ip])))
      std::swap(ip, iq), sign_k = -1;
    const Vec3 r0 = c0[ip] - v0, r1 = (c1[ip] - c0[ip]) - w;
    const Vec3 e0 = c0[iq] - c0[ip], e1 = (c1[iq] - c1[ip]) - e0;
    // (r0 + t r1) x (e0 + t e1); with no motion r1 = -w and e1 = 0 exactly, so the linear
    // coefficient is -(w x e0) bit for bit and the events are those of the per-frame path.
    const Vec3 m[3] = {cross(r0, e0), cross_sum(r0, e1, r1, e0), cross(r1, e1)};
    for (int j = 0; j < 3; ++j) {
      out->edge[k][j][0] = sign_k * dot(m[j], f.m);
      out->edge[k][j][1] = sign_k * dot(m[j], f.s);
      out->edge[k][j][2] = sign_k * dot(m[j], f.t);
    }
  }
  // N(t) = (u0 + t u1) x (p0 + t p1) with u = B - A, p = C - A.
  const Vec3 u0 = c0[1] - c0[0], p0 = c0[2] - c0[0];
  const Vec3 u1 = (c1[1] - c1[0]) - u0, p1 = (c1[2] - c1[0]) - p0;
  const Vec3 nn[3] = {cross(u0, p0), u1 == zero && p1 == zero ? zero : cross_sum(u0, p1, u1, p0),
                      cross(u1, p1)};
  for (int j = 0; j < 3; ++j) {
    out->normal[j][0] = dot(nn[j], f.m);
    out->normal[j][1] = dot(nn[j], f.s);
    out->normal[j][2] = dot(nn[j], f.t);
  }
  // g(t) = N(t) . (h0 + t h1), h = A - v.
  const Vec3 h0 = c0[0] - v0, h1 = (c1[0] - c0[0]) - w;
  out->g[0] = dot(nn[0], h0);
  out->g[1] = dot(nn[0], h1) + dot(nn[1], h0);
  out->g[2] = dot(nn[1], h1) + dot(nn[2], h0);
  out->g[3] = dot(nn[2], h1);
  out->g_roots = polynomial_roots(out->g, 3, 0, 1, out->g_root);
}

int coupled_triangle_coverage(const CoupledTriangleSetup& t, double sc, double tc, double inv_len,
                              CoupledInterval* out) {
  double fk[3][3], n[3];
  for (int k = 0; k < 3; ++k)
    for (int j = 0; j < 3; ++j)
      fk[k][j] = t.edge[k][j][0] + sc * t.edge[k][j][1] + tc * t.edge[k][j][2];
  for (int j = 0; j < 3; ++j) n[j] = t.normal[j][0] + sc * t.normal[j][1] + tc * t.normal[j][2];
  // Most pixels of a bound are never covered: two edges of fixed, opposite signs over [0, 1]
  // (all three Bernstein coefficients of each of one sign) reject the pixel without roots.
  int fixed = 0;
  for (int k = 0; k < 3; ++k) {
    const double b0 = fk[k][0], b1 = fk[k][0] + 0.5 * fk[k][1], b2 = fk[k][0] + fk[k][1] + fk[k][2];
    const int s = b0 > 0 && b1 > 0 && b2 > 0 ? 1 : b0 < 0 && b1 < 0 && b2 < 0 ? -1 : 0;
    if (s == 0) continue;
    if (fixed == -s) return 0;
    fixed = s;
  }
  // Cut [0, 1] at every event (edges: Eq. 4; the normal: the ray grazes the plane; g: the plane
  // passes through the eye) and test each piece at its middle: a root computed a little off
  // only moves a boundary, never inverts a piece.
  double cuts[16];
  int nc = 0;
  cuts[nc++] = 0;
  for (int k = 0; k < 3; ++k) nc += polynomial_roots(fk[k], 2, 0, 1, cuts + nc);
  nc += polynomial_roots(n, 2, 0, 1, cuts + nc);
  for (int i = 0; i < t.g_roots; ++i) cuts[nc++] = t.g_root[i];
  cuts[nc++] = 1;
  sort_small(cuts + 1, nc - 2);
  int count = 0;
  for (int i = 0; i + 1 < nc; ++i) {
    const double a = cuts[i], b = cuts[i + 1];
    if (!(b > a)) continue;
    const double m = 0.5 * (a + b);
    const int s = sign(horner(fk[0], 2, m));
    if (s == 0 || sign(horner(fk[1], 2, m)) != s || sign(horner(fk[2], 2, m)) != s ||
        sign(horner(n, 2, m)) != s || sign(horner(t.g, 3, m)) != s)
      continue;
    if (count > 0 && out[count - 1].s1 == a) {
      out[count - 1].s1 = b;
    } else if (count < kMaxCoupledIntervals) {
      out[count].s0 = a, out[count].s1 = b;
      ++count;
    }
  }
  for (int i = 0; i < count; ++i) {
    CoupledDepth& d = out[i].depth;
    d.sphere = false;
    std::copy_n(t.g, 4, d.num);
    std::copy_n(n, 3, d.den);
    out[i].near = t.near * inv_len;
    out[i].far = t.far * inv_len;
  }
  return count;
}

int coupled_sphere_coverage(const WorldSphere& s0, const WorldSphere& s1, const Vec3& v0,
                            const Vec3& w, const Vec3& d, double near, double far,
                            CoupledInterval* out) {
  // e(t) = centre(t) - v(t) = e0 + t u, r(t) = r0 + t dr. The ray meets the sphere where
  // (d.e)^2 - |d|^2 (|e|^2 - r^2) >= 0; the near hit is ahead when d.e > 0 and the eye outside.
  const Vec3 e0 = s0.centre - v0, u = (s1.centre - s0.centre) - w;
  const double r0 = s0.radius, dr = s1.radius - s0.radius;
  const double dd = dot(d, d), a0 = dot(d, e0), a1 = dot(d, u);
  const double o[3] = {dot(e0, e0) - r0 * r0, 2 * dot(e0, u) - 2 * r0 * dr,
                       dot(u, u) - dr * dr};  // |e|^2 - r^2
  const double h[3] = {a0 * a0 - dd * o[0], 2 * a0 * a1 - dd * o[1], a1 * a1 - dd * o[2]};
  const double ahead[2] = {a0, a1};
  double cuts[8];
  int nc = 0;
  cuts[nc++] = 0;
  nc += polynomial_roots(h, 2, 0, 1, cuts + nc);
  nc += polynomial_roots(o, 2, 0, 1, cuts + nc);
  nc += polynomial_roots(ahead, 1, 0, 1, cuts + nc);
  cuts[nc++] = 1;
  sort_small(cuts + 1, nc - 2);
  int count = 0;
  for (int i = 0; i + 1 < nc; ++i) {
    const double a = cuts[i], b = cuts[i + 1];
    if (!(b > a)) continue;
    const double m = 0.5 * (a + b);
    if (!(horner(h, 2, m) > 0 && horner(o, 2, m) > 0 && horner(ahead, 1, m) > 0)) continue;
    if (count > 0 && out[count - 1].s1 == a) {
      out[count - 1].s1 = b;
    } else if (count < kMaxCoupledIntervals) {
      out[count].s0 = a, out[count].s1 = b;
      ++count;
    }
  }
  const double dd2 = dd * dd, inv_len = 1 / std::sqrt(dd);
  for (int i = 0; i < count; ++i) {
    CoupledDepth& depth = out[i].depth;
    depth.sphere = true;
    depth.num[0] = a0 / dd, depth.num[1] = a1 / dd, depth.num[2] = depth.num[3] = 0;
    depth.den[0] = h[0] / dd2, depth.den[1] = h[1] / dd2, depth.den[2] = h[2] / dd2;
    out[i].near = near * inv_len;
    out[i].far = far * inv_len;
    out[i].primitive = s0.primitive;
  }
  return count;
}

double coupled_depth_at(const CoupledDepth& d, double t) {
  if (d.sphere) return d.num[0] + d.num[1] * t - std::sqrt(std::max(0.0, horner(d.den, 2, t)));
  return horner(d.num, 3, t) / horner(d.den, 2, t);
}

namespace {

// Sorted times in (lo, hi) where depth(a) - depth(b) changes sign; returns the count (<= 64).
int crossings(const CoupledInterval& a, const CoupledInterval& b, double lo, double hi,
              double* out) {
  if (!a.depth.sphere && !b.depth.sphere) {
    // num_a / den_a - num_b / den_b has the sign of num_a den_b - num_b den_a times that of
    // den_a den_b, which does not vanish inside either coverage interval (n shares the
    // non-zero sign of the edge functions there): the crossings are that polynomial's roots.
    double p[6] = {0, 0, 0, 0, 0, 0};
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 3; ++j)
        p[i + j] += a.depth.num[i] * b.depth.den[j] - b.depth.num[i] * a.depth.den[j];
    int deg = 5;
    while (deg > 0 && p[deg] == 0) --deg;
    if (deg >= 2 && one_sign_on(p, deg, lo, hi)) return 0;
    return polynomial_roots(p, deg, lo, hi, out);
  }
  auto diff = [&](double t) { return coupled_depth_at(a.depth, t) - coupled_depth_at(b.depth, t); };
  int n = 0;
  double t_prev = lo;
  int s_prev = sign(diff(lo));
  for (int i = 1; i <= kSphereSamples; ++i) {
    const double t = i == kSphereSamples ? hi : lo + (hi - lo) * i / kSphereSamples;
    const int s = sign(diff(t));
    if (s * s_prev < 0) {
      const double root = bisect(diff, t_prev, t, s_prev);
      if (root > lo && root < hi && (n == 0 || root > out[n - 1])) out[n++] = root;
    }
    t_prev = t, s_prev = s;
  }
  return n;
}

CoupledInterval piece(const CoupledInterval& i, double s0, double s1) {
  CoupledInterval p = i;
  p.s0 = s0;
  p.s1 = s1;
  return p;
}

}  // namespace

bool coupled_composite(std::vector<CoupledInterval>* list, const CoupledInterval& in,
                       std::vector<CoupledInterval>* scratch) {
  if (list->empty()) {
    list->push_back(in);
    return true;
  }
  const auto first = std::upper_bound(list->begin(), list->end(), in.s0,
                                      [](double s, const CoupledInterval& e) { return s < e.s1; });
  double cuts[kSphereSamples + 2];
  {
    // Hidden everywhere (the common case front to back): no gap, and over each overlap either
    // the bounds already separate the two, or no crossing and `in` no nearer at the middle.
    double cursor = in.s0;
    bool hidden = true;
    for (auto it = first; it != list->end() && it->s0 < in.s1 && hidden; ++it) {
      if (it->s0 > cursor) {
        hidden = false;
        break;
      }
      const double c = std::max(it->s0, in.s0), f = std::min(it->s1, in.s1);
      if (in.near < it->far) {
        const double m = 0.5 * (c + f);
        hidden = crossings(in, *it, c, f, cuts) == 0 &&
                 coupled_depth_at(in.depth, m) >= coupled_depth_at(it->depth, m);
      }
      cursor = f;
    }
    if (hidden && cursor >= in.s1) return false;
  }
  const auto last = std::lower_bound(first, list->end(), in.s1,
                                     [](const CoupledInterval& e, double s) { return e.s0 < s; });
  std::vector<CoupledInterval>& out = *scratch;
  out.clear();
  auto push = [&](const CoupledInterval& p) {
    if (!(p.s1 > p.s0)) return;
    if (!out.empty()) {
      CoupledInterval& back = out.back();
      if (back.primitive == p.primitive && back.depth == p.depth && back.s1 == p.s0) {
        back.s1 = p.s1;
        return;
      }
    }
    out.push_back(p);
  };
  double cursor = in.s0;
  for (auto it = first; it != last; ++it) {
    const CoupledInterval& e = *it;
    const double c = std::max(e.s0, in.s0), f = std::min(e.s1, in.s1);
    if (e.s0 < c) push(piece(e, e.s0, c));
    if (cursor < c) push(piece(in, cursor, c));
    int n = 0;
    cuts[n++] = c;
    if (in.near < e.far) n += crossings(in, e, c, f, cuts + n);
    cuts[n++] = f;
    for (int k = 0; k + 1 < n; ++k) {
      const double a = cuts[k], b = cuts[k + 1];
      const double m = 0.5 * (a + b);
      const bool nearer =
          in.near < e.far && coupled_depth_at(in.depth, m) < coupled_depth_at(e.depth, m);
      push(nearer ? piece(in, a, b) : piece(e, a, b));
    }
    cursor = std::max(cursor, f);
    if (e.s1 > f) push(piece(e, f, e.s1));
  }
  if (cursor < in.s1) push(piece(in, cursor, in.s1));
  const size_t at = static_cast<size_t>(first - list->begin());
  const size_t old_count = static_cast<size_t>(last - first);
  if (out.size() > old_count) {
    list->insert(list->begin() + static_cast<std::ptrdiff_t>(at + old_count),
                 out.size() - old_count, CoupledInterval{});
  } else if (out.size() < old_count) {
    list->erase(list->begin() + static_cast<std::ptrdiff_t>(at + out.size()),
                list->begin() + static_cast<std::ptrdiff_t>(at + old_count));
  }
  std::copy(out.begin(), out.end(), list->begin() + static_cast<std::ptrdiff_t>(at));
  return true;
}

}  // namespace calf::encoder::visibility
