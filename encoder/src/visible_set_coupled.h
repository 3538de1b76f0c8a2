// The visible-set builder's coupled motion (paper 004 Sec. 3.2, Eqs. 3-4;
// VisibilityMotion::kCoupled in calf/encoder/visible_set.h), shared by its two files:
//   visible_set_coupled_intervals.cc  polynomial roots, per-pixel coverage intervals of a moving
//                                     triangle or sphere, depth compositing of rational depths
//   visible_set_coupled.cc            the driver: motion steps, segments, tiles, threads
//
// Over one motion step the eye is at v(t) = a + t w (w = b - a) and a world-space point X at
// X0 + t (X1 - X0), t in [0, 1]. Along the ray of a pixel direction d (non-unit, as in
// visible_set_internal.h) from v(t):
//   edge PQ:  f(t) = d . ((P(t) - v(t)) x (Q(t) - P(t)))     quadratic (Eq. 4)
//   normal:   n(t) = d . N(t), N = (B - A) x (C - A)         quadratic (the sum of the three f)
//   ahead:    g(t) = N(t) . (A(t) - v(t))                    cubic, independent of d
//   depth:    g(t) / n(t)                                    along d, in units of |d|
// The ray crosses the triangle where the three f share a sign and the hit is ahead where g and n
// share it: [0, 1] is cut at the real roots of the f, of n and of g, and each piece is tested at
// its middle. Depths of two triangles cross where g1 n2 - g2 n1 (degree <= 5) changes sign.
#pragma once

#include <chrono>
#include <cstdint>
#include <span>
#include <vector>

#include "visible_set_internal.h"

namespace calf::encoder::visibility {

// The real roots of c[0] + c[1] t + ... + c[deg] t^deg in the open interval (lo, hi), sorted,
// into `out` (room for deg entries); returns their count. Exact-zero leading coefficients lower
// the degree. Degree <= 2: closed form (the stable quadratic formula; negating every coefficient
// gives the same bits, so an edge shared by two triangles gets one event time). Higher degrees
// (<= 5): the roots of the derivative cut (lo, hi) into monotone pieces, each piece whose ends
// have strictly opposite signs holds one root, found by bisection to the last bit (at most 100
// halvings); a critical point where the value is exactly 0 is a root too. Roots of even
// multiplicity that never make the value change sign may be missed: they change nothing here.
// Deterministic: a pure function of its arguments.
int polynomial_roots(const double* c, int deg, double lo, double hi, double* out);

// A moving triangle seen from a segment through one face: every per-pixel polynomial's
// coefficients are affine in (1, sc, tc).
struct CoupledTriangleSetup {
  double edge[3][3][3];  // edge k, power j of t, (1, sc, tc): f_k (canonical order, signed)
  double normal[3][3];   // power j, (1, sc, tc): n(t)
  double g[4];           // g(t), powers 0..3
  double g_root[3];      // its roots in (0, 1) (pixel-independent, found once)
  int g_roots = 0;
  double near = 0, far = 0;  // bounds of the distance from v(t) to any point of the triangle at t
};
// corners0/corners1: the triangle at the step's first and second frame (same corner order).
void setup_coupled_triangle(const Vec3* corners0, const Vec3* corners1, const Vec3& v0,
                            const Vec3& w, const FaceBasis& f, CoupledTriangleSetup* out);

// Depth along one pixel's ray as a function of t (units of |d|).
struct CoupledDepth {
  bool sphere = false;
  // Triangle: num[0..3] / den[0..2]. Sphere: num[0] + num[1] t - sqrt(max(0, den[0] + den[1] t
  // + den[2] t^2)) (the near hit).
  double num[4] = {0, 0, 0, 0};
  double den[3] = {0, 0, 0};
  friend bool operator==(const CoupledDepth&, const CoupledDepth&) = default;
};

struct CoupledInterval {
  double s0 = 0, s1 = 0;
  double near = 0, far = 0;  // bounds of the depth over [s0, s1] (units of |d|)
  CoupledDepth depth;
  uint32_t primitive = 0;
};

// Most intervals one primitive covers one pixel with.
inline constexpr int kMaxCoupledIntervals = 8;

// The intervals over which the triangle covers pixel (sc, tc) ahead of the eye (`inv_len`:
// 1 / |d|, to turn the setup's metric bounds into depth units); returns their count.
int coupled_triangle_coverage(const CoupledTriangleSetup& t, double sc, double tc, double inv_len,
                              CoupledInterval* out);

// A sphere moving from (centre0, r0) to (centre1, r1) seen from v(t) = v0 + t w through the
// direction d: the intervals where the ray meets it ahead with the eye outside (at most
// kMaxCoupledIntervals); near/far are the metric bounds of the distance. Returns the count.
int coupled_sphere_coverage(const WorldSphere& s0, const WorldSphere& s1, const Vec3& v0,
                            const Vec3& w, const Vec3& d, double near, double far,
                            CoupledInterval* out);

double coupled_depth_at(const CoupledDepth& d, double t);

// Depth-composites `in` into the sorted, disjoint list (as visibility::composite: where `in` is
// strictly nearer it replaces the list, gaps are filled, ties keep the list). Crossings of two
// triangle depths: none when the cross-multiplied numerators' Bernstein coefficients over the
// overlap share a sign, else their polynomial_roots (exact up to rounding);
// with a sphere: 64 samples and bisection (two crossings within 1/64 of an overlap can be
// missed). Returns false when nothing changed.
bool coupled_composite(std::vector<CoupledInterval>* list, const CoupledInterval& in,
                       std::vector<CoupledInterval>* scratch);

// The coupled driver, called by compute_visible_set after its checks (`t0`: its start time).
Expected<VisibleSet> solve_coupled(const capture::SceneFile& scene,
                                   std::span<const ViewSegment> segments,
                                   const VisibleSetOptions& options, const Prepared& prepared,
                                   std::chrono::steady_clock::time_point t0);

}  // namespace calf::encoder::visibility
