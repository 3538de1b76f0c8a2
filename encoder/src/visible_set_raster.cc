// Rasterisation from a segment (paper 004, Alg. 1 lines 4-8): which pixels of a cube face a
// primitive can touch while the eye moves along the segment, and over which interval of the
// segment it covers one pixel centre (Eq. 2 for triangles, Sec. 3.3 for spheres).
#include <algorithm>
#include <cmath>
#include <limits>

#include "visible_set_internal.h"

namespace calf::encoder::visibility {
namespace {

// Pixel bounds are grown by this much (pixels): the hull is computed in floating point and a
// pixel centre on its boundary must still be tried (the coverage test decides exactly).
constexpr double kBoundMargin = 1e-3;

bool lex_less(const Vec3& a, const Vec3& b) {
  if (a.x != b.x) return a.x < b.x;
  if (a.y != b.y) return a.y < b.y;
  return a.z < b.z;
}

double cross2(const double* o, const double* a, const double* b) {
  return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
}

// The pieces of [lo, hi] where c2 s^2 + c1 s + c0 >= 0 (strict: > 0) as up to 3 [a, b] pairs
// (a <= b) in `out`; returns the count. The roots split [lo, hi]; each piece's sign is read at
// its middle, so a root computed a little off only shifts a boundary.
int quadratic_pieces(double c2, double c1, double c0, double lo, double hi, bool strict,
                     double* out) {
  double cut[4];
  int n = 0;
  cut[n++] = lo;
  const double scale = std::max({std::fabs(c2), std::fabs(c1), std::fabs(c0)});
  if (scale == 0) {
    if (strict) return 0;
    out[0] = lo, out[1] = hi;
    return 1;
  }
  double roots[2];
  int nr = 0;
  if (std::fabs(c2) <= 1e-14 * scale) {
    if (c1 != 0) roots[nr++] = -c0 / c1;
  } else {
    const double disc = c1 * c1 - 4 * c2 * c0;
    if (disc >= 0) {
      const double q = -0.5 * (c1 + std::copysign(std::sqrt(disc), c1));
      roots[nr++] = q / c2;
      if (q != 0) roots[nr++] = c0 / q;
      if (nr == 2 && roots[0] > roots[1]) std::swap(roots[0], roots[1]);
    }
  }
  for (int i = 0; i < nr; ++i)
    if (roots[i] > lo && roots[i] < hi) cut[n++] = roots[i];
  cut[n++] = hi;
  int count = 0;
  for (int i = 0; i + 1 < n; ++i) {
    const double a = cut[i], b = cut[i + 1];
    const double m = 0.5 * (a + b);
    const double v = (c2 * m + c1) * m + c0;
    if (strict ? v > 0 : v >= 0) {
      if (count > 0 && out[2 * count - 1] == a) {
        out[2 * count - 1] = b;
      } else {
        out[2 * count] = a, out[2 * count + 1] = b;
        ++count;
      }
    }
  }
  return count;
}

}  // namespace

FaceBasis face_basis(int face) {
  // OpenGL's cube-map table (calf/format/cube.h): d = m + sc s + tc t.
  switch (face) {
    case 0:
      return {{1, 0, 0}, {0, 0, -1}, {0, -1, 0}};
    case 1:
      return {{-1, 0, 0}, {0, 0, 1}, {0, -1, 0}};
    case 2:
      return {{0, 1, 0}, {1, 0, 0}, {0, 0, 1}};
    case 3:
      return {{0, -1, 0}, {1, 0, 0}, {0, 0, -1}};
    case 4:
      return {{0, 0, 1}, {1, 0, 0}, {0, -1, 0}};
    default:
      return {{0, 0, -1}, {-1, 0, 0}, {0, -1, 0}};
  }
}

bool PixelBound::compute(std::span<const Vec3> points, const Vec3& v0, const Vec3& v1,
                         const FaceBasis& f, uint32_t n, double delta) {
  // The six (or more) points P - v, in face coordinates (u, v, z).
  double pu[32], pv[32], pz[32];
  int np = 0;
  bool out_right = true, out_left = true, out_top = true, out_bottom = true, behind = true;
  for (const Vec3& p : points)
    for (const Vec3* eye : {&v0, &v1}) {
      const Vec3 r = p - *eye;
      const double z = dot(r, f.m), u = dot(r, f.s), v = dot(r, f.t);
      out_right &= u > z, out_left &= u<-z, out_top &= v> z, out_bottom &= v < -z;
      behind &= z < delta;
      pu[np] = u, pv[np] = v, pz[np] = z;
      ++np;
    }
  if (out_right || out_left || out_top || out_bottom || behind) return false;
  n_ = static_cast<int>(n);
  // Clip the hull at z = delta: its vertices are kept points and crossings of point pairs.
  const double half = 0.5 * n;
  double xs[160], ys[160];
  int m = 0;
  auto add = [&](double u, double v, double z) {
    xs[m] = (u / z + 1) * half - 0.5;
    ys[m] = (v / z + 1) * half - 0.5;
    ++m;
  };
  for (int i = 0; i < np; ++i)
    if (pz[i] >= delta) add(pu[i], pv[i], pz[i]);
  for (int i = 0; i < np; ++i)
    for (int j = i + 1; j < np; ++j)
      if ((pz[i] - delta) * (pz[j] - delta) < 0) {
        const double t = (delta - pz[i]) / (pz[j] - pz[i]);
        add(pu[i] + t * (pu[j] - pu[i]), pv[i] + t * (pv[j] - pv[i]), delta);
      }
  double xmin = xs[0], xmax = xs[0], ymin = ys[0], ymax = ys[0];
  for (int i = 1; i < m; ++i) {
    xmin = std::min(xmin, xs[i]), xmax = std::max(xmax, xs[i]);
    ymin = std::min(ymin, ys[i]), ymax = std::max(ymax, ys[i]);
  }
  if (!(xmax >= -kBoundMargin && xmin <= n - 1 + kBoundMargin && ymax >= -kBoundMargin &&
        ymin <= n - 1 + kBoundMargin))
    return false;
  auto clamp_floor = [&](double v) {
    return static_cast<int>(std::floor(std::min<double>(n - 1, v + kBoundMargin)));
  };
  auto clamp_ceil = [&](double v) {
    return static_cast<int>(std::ceil(std::max<double>(0, v - kBoundMargin)));
  };
  x0_ = clamp_ceil(xmin), x1_ = clamp_floor(xmax);
  y0_ = clamp_ceil(ymin), y1_ = clamp_floor(ymax);
  if (x0_ > x1_ || y0_ > y1_) return false;
  // Far outside the face (points near z = delta project far away) the hull's arithmetic loses
  // its precision: the bounding rectangle is used instead (conservative).
  const double far = 4.0 * n + 4;
  rect_ = !(xmin > -far && xmax < far && ymin > -far && ymax < far);
  if (rect_) return true;
  // Convex hull (monotone chain), counter-clockwise.
  int idx[160];
  for (int i = 0; i < m; ++i) idx[i] = i;
  std::sort(idx, idx + m,
            [&](int a, int b) { return xs[a] != xs[b] ? xs[a] < xs[b] : ys[a] < ys[b]; });
  double pts[2 * 160];
  for (int i = 0; i < m; ++i) pts[2 * i] = xs[idx[i]], pts[2 * i + 1] = ys[idx[i]];
  int k = 0;
  double* h = hull_.data();
  for (int i = 0; i < m; ++i) {
    while (k >= 2 && cross2(h + 2 * (k - 2), h + 2 * (k - 1), pts + 2 * i) <= 0) --k;
    h[2 * k] = pts[2 * i], h[2 * k + 1] = pts[2 * i + 1];
    ++k;
  }
  for (int i = m - 2, lower = k + 1; i >= 0; --i) {
    while (k >= lower && cross2(h + 2 * (k - 2), h + 2 * (k - 1), pts + 2 * i) <= 0) --k;
    h[2 * k] = pts[2 * i], h[2 * k + 1] = pts[2 * i + 1];
    ++k;
  }
  hull_n_ = std::max(1, k - 1);  // the last point repeats the first
  return true;
}

bool PixelBound::row_span(int y, int* xa, int* xb) const {
  if (y < y0_ || y > y1_) return false;
  if (rect_) {
    *xa = x0_, *xb = x1_;
    return true;
  }
  const double yy = y;
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  const double* h = hull_.data();
  for (int i = 0; i < hull_n_; ++i) {
    const double* a = h + 2 * i;
    const double* b = h + 2 * ((i + 1) % hull_n_);
    const double ylo = std::min(a[1], b[1]), yhi = std::max(a[1], b[1]);
    if (yy < ylo - kBoundMargin || yy > yhi + kBoundMargin) continue;
    const double xlo = std::min(a[0], b[0]), xhi = std::max(a[0], b[0]);
    if (yhi - ylo <= 1e-12) {
      lo = std::min(lo, xlo), hi = std::max(hi, xhi);
      continue;
    }
    const double x = std::clamp(a[0] + (yy - a[1]) * (b[0] - a[0]) / (b[1] - a[1]), xlo, xhi);
    lo = std::min(lo, x), hi = std::max(hi, x);
  }
  if (!(lo <= hi)) return false;
  *xa = static_cast<int>(std::ceil(std::max<double>(x0_, lo - kBoundMargin)));
  *xb = static_cast<int>(std::floor(std::min<double>(x1_, hi + kBoundMargin)));
  return *xa <= *xb;
}

void setup_triangle(const Vec3* c, const Vec3& v0, const Vec3& w, const FaceBasis& f,
                    TriangleSetup* out) {
  for (int k = 0; k < 3; ++k) {
    // Canonical order: a shared edge gives both of its triangles the same numbers (negated).
    Vec3 p = c[k], q = c[(k + 1) % 3];
    double sign = 1;
    if (lex_less(q, p)) std::swap(p, q), sign = -1;
    const Vec3 e = q - p;
    const Vec3 m = cross(p - v0, e);
    const Vec3 b = cross(w, e);
    out->alpha[k][0] = sign * dot(m, f.m);
    out->alpha[k][1] = sign * dot(m, f.s);
    out->alpha[k][2] = sign * dot(m, f.t);
    out->beta[k][0] = sign * dot(b, f.m);
    out->beta[k][1] = sign * dot(b, f.s);
    out->beta[k][2] = sign * dot(b, f.t);
  }
  const Vec3 normal = cross(c[1] - c[0], c[2] - c[0]);
  out->normal[0] = dot(normal, f.m);
  out->normal[1] = dot(normal, f.s);
  out->normal[2] = dot(normal, f.t);
  out->g0 = dot(normal, c[0] - v0);
  out->g1 = dot(normal, w);
}

bool triangle_coverage(const TriangleSetup& t, double sc, double tc, Interval* out) {
  const double d = t.normal[0] + sc * t.normal[1] + tc * t.normal[2];
  if (d == 0) return false;  // the ray is parallel to the triangle's plane
  const double sigma = d > 0 ? 1.0 : -1.0;
  double lo = 0, hi = 1;
  for (int k = 0; k < 3; ++k) {
    // sigma * f(s) = a - s b >= 0: the pixel centre on the inner side of edge k.
    const double a = sigma * (t.alpha[k][0] + sc * t.alpha[k][1] + tc * t.alpha[k][2]);
    const double b = sigma * (t.beta[k][0] + sc * t.beta[k][1] + tc * t.beta[k][2]);
    if (b > 0) {
      hi = std::min(hi, a / b);
    } else if (b < 0) {
      lo = std::max(lo, a / b);
    } else if (a < 0) {
      return false;
    }
  }
  // Ahead of the eye: sigma * (g0 - s g1) > 0.
  const double a = sigma * t.g0, b = sigma * t.g1;
  if (b > 0) {
    hi = std::min(hi, a / b);
  } else if (b < 0) {
    lo = std::max(lo, a / b);
  } else if (a <= 0) {
    return false;
  }
  if (!(hi > lo)) return false;
  out->s0 = lo;
  out->s1 = hi;
  out->p = t.g0 / d;
  out->q = -t.g1 / d;
  out->sphere = -1;
  return true;
}

int sphere_coverage(const WorldSphere& sphere, const Vec3& v0, const Vec3& w, const Vec3& d,
                    Interval out[2], SphereDepth* depth) {
  // Eye v(s) = v0 + s w, e(s) = centre - v(s). The ray meets the sphere where the discriminant
  // (d.e)^2 - |d|^2 (|e|^2 - r^2) >= 0; the near hit is ahead when d.e > 0 and the eye is
  // outside (|e|^2 > r^2).
  const Vec3 e0 = sphere.centre - v0;
  const double dd = dot(d, d), a0 = dot(d, e0), a1 = dot(d, w);
  const double ww = dot(w, w), ew = dot(e0, w), ee = dot(e0, e0),
               r2 = sphere.radius * sphere.radius;
  const double c2 = a1 * a1 - dd * ww, c1 = -2 * a0 * a1 + 2 * dd * ew,
               c0 = a0 * a0 - dd * (ee - r2);
  double hit[6], outside[6];
  const int nh = quadratic_pieces(c2, c1, c0, 0, 1, false, hit);
  if (nh == 0) return 0;
  const int no = quadratic_pieces(ww, -2 * ew, ee - r2, 0, 1, true, outside);
  // d.e(s) = a0 - s a1 > 0.
  double lo = 0, hi = 1;
  if (a1 > 0) {
    hi = a0 / a1;
  } else if (a1 < 0) {
    lo = a0 / a1;
  } else if (a0 <= 0) {
    return 0;
  }
  int count = 0;
  for (int i = 0; i < nh; ++i)
    for (int j = 0; j < no; ++j) {
      const double s0 = std::max({hit[2 * i], outside[2 * j], lo});
      const double s1 = std::min({hit[2 * i + 1], outside[2 * j + 1], hi});
      if (s1 > s0 && count < 2) {
        out[count].s0 = s0, out[count].s1 = s1;
        out[count].p = out[count].q = 0;
        out[count].primitive = sphere.primitive;
        ++count;
      }
    }
  const double dd2 = dd * dd;
  *depth = {a0 / dd, -a1 / dd, c0 / dd2, c1 / dd2, c2 / dd2};
  return count;
}

}  // namespace calf::encoder::visibility
