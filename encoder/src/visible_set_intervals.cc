// Depth compositing of coverage intervals (paper 004, Alg. 1 line 9): a pixel keeps a sorted list
// of disjoint intervals of the segment parameter, each with the primitive nearest over it and its
// depth function; a new coverage interval replaces the list where it is nearer and fills the gaps.
// The list is the lower envelope of every depth function inserted so far, so the order of
// insertion matters only for exact ties (kept by the earlier primitive).
#include <algorithm>
#include <cmath>

#include "visible_set_internal.h"

namespace calf::encoder::visibility {
namespace {

// Nonlinear (sphere) depth differences are sampled at this many steps, then bisected.
constexpr int kCrossingSamples = 32;
constexpr int kBisections = 60;

// Sorted times in (lo, hi) where depth(a) - depth(b) changes sign; returns the count.
int crossings(const Interval& a, const Interval& b, std::span<const SphereDepth> spheres, double lo,
              double hi, double* out) {
  if (a.sphere < 0 && b.sphere < 0) {
    // Two lines (Fig. 2 right; intersecting triangles split an interval at their hinge).
    const double dq = a.q - b.q;
    if (dq == 0) return 0;
    const double s = (b.p - a.p) / dq;
    if (s > lo && s < hi) {
      out[0] = s;
      return 1;
    }
    return 0;
  }
  auto diff = [&](double s) { return depth_at(a, spheres, s) - depth_at(b, spheres, s); };
  int n = 0;
  double s_prev = lo, f_prev = diff(lo);
  for (int i = 1; i <= kCrossingSamples; ++i) {
    const double s = i == kCrossingSamples ? hi : lo + (hi - lo) * i / kCrossingSamples;
    const double f = diff(s);
    if ((f_prev < 0 && f > 0) || (f_prev > 0 && f < 0)) {
      double x0 = s_prev, x1 = s, f0 = f_prev;
      for (int k = 0; k < kBisections; ++k) {
        const double mid = 0.5 * (x0 + x1);
        const double fm = diff(mid);
        if ((fm < 0) == (f0 < 0)) {
          x0 = mid, f0 = fm;
        } else {
          x1 = mid;
        }
      }
      const double root = 0.5 * (x0 + x1);
      if (root > lo && root < hi && (n == 0 || root > out[n - 1])) out[n++] = root;
    }
    s_prev = s, f_prev = f;
  }
  return n;
}

Interval piece(const Interval& i, double s0, double s1) {
  Interval p = i;
  p.s0 = s0;
  p.s1 = s1;
  return p;
}

}  // namespace

double sphere_depth_at(const Interval& i, std::span<const SphereDepth> spheres, double s) {
  const SphereDepth& d = spheres[static_cast<size_t>(i.sphere)];
  return d.k0 + d.k1 * s - std::sqrt(std::max(0.0, d.c0 + s * (d.c1 + s * d.c2)));
}

bool composite(IntervalList* list, IntervalPool* pool, const Interval& in,
               std::span<const SphereDepth> spheres, CompositeScratch* scratch) {
  if (list->empty()) {
    list->replace(pool, list->begin(), list->end(), {&in, 1}, spheres, &scratch->tmp);
    return true;
  }
  // The first interval ending after in.s0 (the list is sorted and disjoint).
  const IntervalList::Pos first = list->first_ending_after(*pool, in.s0);
  const IntervalList::Pos end = list->end();
  if (in.sphere < 0) {
    // Most insertions in a dense scene are hidden: `in` is no nearer than the list at both ends
    // of every overlap (lines: then nowhere in between) and finds no gap. Nothing changes.
    double cursor = in.s0;
    bool hidden = true;
    for (IntervalList::Pos p = first; p != end; list->next(&p)) {
      const Interval& e = list->at(*pool, p);
      if (!(e.s0 < in.s1)) break;
      if (e.s0 > cursor || e.sphere >= 0) {
        hidden = false;
        break;
      }
      const double c = std::max(e.s0, in.s0), f = std::min(e.s1, in.s1);
      hidden = in.p + in.q * c >= e.p + e.q * c && in.p + in.q * f >= e.p + e.q * f;
      cursor = f;
      if (!hidden) break;
    }
    if (hidden && cursor >= in.s1) return false;
  }
  // The overlapped range [first, last) (intervals starting before in.s1) is rebuilt in `out` and
  // replaces it.
  std::vector<Interval>& out = scratch->out;
  out.clear();
  auto push = [&](const Interval& p) {
    if (!(p.s1 > p.s0)) return;
    if (!out.empty()) {
      Interval& back = out.back();
      if (back.primitive == p.primitive && back.sphere == p.sphere && back.p == p.p &&
          back.q == p.q && back.s1 == p.s0) {
        back.s1 = p.s1;
        return;
      }
    }
    out.push_back(p);
  };
  double cursor = in.s0;  // the part of `in` before it has been placed
  IntervalList::Pos last = first;
  for (; last != end; list->next(&last)) {
    const Interval& e = list->at(*pool, last);
    if (!(e.s0 < in.s1)) break;
    const double c = std::max(e.s0, in.s0), f = std::min(e.s1, in.s1);
    if (e.s0 < c) push(piece(e, e.s0, c));
    if (cursor < c) push(piece(in, cursor, c));
    double cuts[kCrossingSamples + 2];
    int n = 0;
    cuts[n++] = c;
    n += crossings(in, e, spheres, c, f, cuts + n);
    cuts[n++] = f;
    for (int k = 0; k + 1 < n; ++k) {
      const double a = cuts[k], b = cuts[k + 1];
      const double m = 0.5 * (a + b);
      push(depth_at(in, spheres, m) < depth_at(e, spheres, m) ? piece(in, a, b) : piece(e, a, b));
    }
    cursor = std::max(cursor, f);
    if (e.s1 > f) push(piece(e, f, e.s1));
  }
  if (cursor < in.s1) push(piece(in, cursor, in.s1));
  list->replace(pool, first, last, out, spheres, &scratch->tmp);
  return true;
}

}  // namespace calf::encoder::visibility
