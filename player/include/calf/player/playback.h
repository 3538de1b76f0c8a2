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

#include <cstdint>
#include <memory>
#include <span>
#include <string>
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

struct PlaybackOptions {
  // true: the GL 4.5 renderers (a current context and its functions are needed); false: the
  // scalar CPU reference renderers.
  bool use_gl = true;
  // Options of every lightfield track's representation.
  LightfieldOptions lightfield;
  // Options of every mesh track's representation.
  MeshOptions mesh;
  // Options of every surfels track's representation (which also plays its paired mesh track).
  SurfelOptions surfels;
  // Options of every tiles track's representation.
  TilesOptions tiles;
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
