// The interpolation of vertex states (vertex_states.h).
#include "calf/format/vertex_states.h"

#include <algorithm>
#include <cstddef>

namespace calf {

void vertex_states_at(std::span<const float> rest, std::span<const float> times,
                      std::span<const float> states, double time, std::span<float> out) {
  const size_t n = rest.size();
  if (times.empty() || states.size() != times.size() * n) {
    std::copy(rest.begin(), rest.end(), out.begin());
    return;
  }
  // The first state after `time` (times compared in double).
  const size_t next =
      static_cast<size_t>(std::upper_bound(times.begin(), times.end(), time) - times.begin());
  if (next == 0 || next == times.size()) {
    const auto held = states.subspan((next == 0 ? 0 : times.size() - 1) * n, n);
    std::copy(held.begin(), held.end(), out.begin());
    return;
  }
  const double t0 = times[next - 1], t1 = times[next];
  const float w = static_cast<float>((time - t0) / (t1 - t0));
  const float* a = states.data() + (next - 1) * n;
  const float* b = states.data() + next * n;
  for (size_t i = 0; i < n; ++i) out[i] = a[i] + w * (b[i] - a[i]);
}

}  // namespace calf
