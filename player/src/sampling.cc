#include "sampling.h"

#include <algorithm>

namespace calf::player::internal {

BilinearTaps bilinear_taps(const FaceTexelCoord& c, uint32_t n) {
  // Texel centres sit at half-integers: the taps are the centres around (u - 0.5, v - 0.5).
  const double u = c.u - 0.5, v = c.v - 0.5;
  const double fx0 = std::floor(u), fy0 = std::floor(v);
  const double ax = u - fx0, ay = v - fy0;
  const auto x0 = static_cast<int64_t>(fx0), y0 = static_cast<int64_t>(fy0);
  BilinearTaps t;
  t.texel[0] = texel_beyond_face(c.face, x0, y0, n);
  t.texel[1] = texel_beyond_face(c.face, x0 + 1, y0, n);
  t.texel[2] = texel_beyond_face(c.face, x0, y0 + 1, n);
  t.texel[3] = texel_beyond_face(c.face, x0 + 1, y0 + 1, n);
  t.weight[0] = (1 - ax) * (1 - ay);
  t.weight[1] = ax * (1 - ay);
  t.weight[2] = (1 - ax) * ay;
  t.weight[3] = ax * ay;
  t.offset[0] = std::max(ax, ay);
  t.offset[1] = std::max(1 - ax, ay);
  t.offset[2] = std::max(ax, 1 - ay);
  t.offset[3] = std::max(1 - ax, 1 - ay);
  return t;
}

void sharpen_strengths(const BilinearTaps& taps, double k, double strength[2]) {
  const double ax = taps.weight[1] + taps.weight[3], ay = taps.weight[2] + taps.weight[3];
  strength[0] = k * 4 * ax * (1 - ax);
  strength[1] = k * 4 * ay * (1 - ay);
}

}  // namespace calf::player::internal
