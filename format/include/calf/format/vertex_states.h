// Piecewise-linear vertex states (format/SCENE.md "Vertex states", paper 004 Eqs. 3-4): the one
// interpolation of vertex positions between states, called by the scene-file reader
// (capture::positions_at), the mesh track reader (decoder::positions_at) and the ray tracer's
// scenes (samples::positions_at), so that a scene, its mesh track and its capture show the same
// floats at every time.
#pragma once

#include <span>

namespace calf {

// Writes the positions at `time` seconds into `out` (rest.size() floats, 3 per vertex).
// `times` are the states' times, strictly increasing; `states` holds times.size() * rest.size()
// floats, state-major. Without states (or with a `states` array of another size) the result is
// `rest`; before the first state and after the last the state is held; between states k and
// k + 1 each float is a + w * (b - a) in float, with w = (time - t_k) / (t_k+1 - t_k) computed
// in double and rounded to float once.
void vertex_states_at(std::span<const float> rest, std::span<const float> times,
                      std::span<const float> states, double time, std::span<float> out);

}  // namespace calf
