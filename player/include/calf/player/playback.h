// Playback of a .calf clip: the loop calf-play runs for each displayed frame, shared by the
// window, the headless mode and the tests. It holds one representation (representation.h) per
// playable track — every lightfield track, played by LightfieldRepresentation, and every mesh
// track (paper 004's full scene or visible set), played by MeshRepresentation — on one
// backend (GL or the CPU reference), and composites their renders by radial depth: per pixel the
// nearest surface wins (ties: the earlier track). With one playable track the render is that
// track's, bit for bit.
//
// The clip's timeline is its first playable track's (fps, frame count); a later track with fewer
// frames shows its last frame past its end.
#pragma once

#include <any>
#include <cstdint>
#include <map>
#include <memory>
#include <span>
#include <string>
#include <typeindex>
#include <typeinfo>
#include <utility>
#include <vector>

#include "calf/format/status.h"
#include "calf/player/gl_context.h"
#include "calf/player/lightfield_representation.h"
#include "calf/player/mesh_representation.h"
#include "calf/player/representation.h"
#include "calf/player/surfel_representation.h"
#include "calf/player/tiles_representation.h"

namespace calf::player {

// What Playback opens a clip's representations with: the backend, and the options of each kind's
// representation by their type (LightfieldOptions, MeshOptions, SurfelOptions, TilesOptions: the
// type a kind's entry in the player table opens with), held by value.
class PlaybackOptions {
 public:
  // true: the GL 4.5 renderers (a current context and its functions are needed); false: the
  // scalar CPU reference renderers.
  bool use_gl = true;

  // The options of type T, set to T's defaults on the first call.
  template <class T>
  T& of() {
    std::any& held = kinds_[std::type_index(typeid(T))];
    if (!held.has_value()) held = T{};
    return *std::any_cast<T>(&held);
  }
  // The options of type T as set, or T's defaults.
  template <class T>
  const T& of() const {
    const auto it = kinds_.find(std::type_index(typeid(T)));
    if (it != kinds_.end()) return *std::any_cast<T>(&it->second);
    static const T defaults{};
    return defaults;
  }

 private:
  std::map<std::type_index, std::any> kinds_;
};

class Playback {
 public:
  // Opens `clip_path` and a representation for each playable track. `gl` is needed when
  // options.use_gl; the GL context it was loaded from must stay current on this thread. Errors:
  // the container's and the representations' (LightfieldRepresentation::open,
  // MeshRepresentation::open); CALF-E460 for a file without a playable track.
  static Expected<std::unique_ptr<Playback>> open(const std::string& clip_path,
                                                  const PlaybackOptions& options,
                                                  const GlFunctions* gl);
  ~Playback();
  Playback(const Playback&) = delete;
  Playback& operator=(const Playback&) = delete;

  uint32_t frame_count() const;
  double fps() const;
  // The clip frame shown at `seconds` (frame f covers [f / fps, (f + 1) / fps)), clamped to the
  // clip: a negative time shows frame 0, a time past the end the last frame.
  uint32_t frame_at_time(double seconds) const;
  // The box the eye may move in: the union of the representations' view volumes.
  const Box3& view_volume() const;
  bool inside_view_volume(const Vec3& p) const;

  // Brings every representation to `frame` for `eyes` (one or more cameras: mono, stereo,
  // several users). CALF-E403 for no eye; the representations' errors.
  Status prepare(uint32_t frame, std::span<const Camera> eyes);
  // Renders `camera` with every representation and composites them by depth into `out`.
  Status render(const Camera& camera, RenderedImage* out);
  // The wall time in ms between the last two displayed frames, for the representations' frame
  // budgets; CALF-E453 for a negative or non-finite time.
  Status report_frame_time(double frame_ms);

  // The representations, in track order.
  std::span<Representation* const> representations() const;
  // The first lightfield track's representation (its view selection, RR switch, decoder
  // figures), or nullptr when the clip has none.
  LightfieldRepresentation* lightfield() const;
  // Every representation's figures of the latest frame, in track order (HUD, reports).
  std::vector<RepresentationStats> stats() const;
  // The representations' numbers of the latest frame together: the triangles drawn summed, the
  // first representation's quads and points (in track order) that has them.
  FrameFigures figures() const;
  // Wall time of the last render(), all representations and the compositing, in ms.
  double last_render_ms() const;
  const PlaybackOptions& options() const;

 private:
  struct Impl;
  explicit Playback(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace calf::player
