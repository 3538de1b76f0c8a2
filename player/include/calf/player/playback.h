// Playback of a .calf clip: the loop calf-play runs for each displayed frame, shared by the
// window, the headless mode and the tests.
//
//   prepare(frame, eyes):  view selection (calf/player/view_selection.h) from the eyes' midpoint
//                          -> the view-dependent decoder (calf/decoder/clip_decoder.h) advances
//                          the selected views to `frame` for the eyes' frusta -> the updates go
//                          to the GPU textures (GlViews) or, for the CPU reference renderer, to
//                          CpuTextures and from there into a ViewSet;
//   render(camera, image): ray-marches one eye with the selected views (GlRenderer or
//                          CpuRenderer; the same RenderOptions).
//
// The march range (RenderOptions near / far) is derived per frame from the active views and the
// eye (march_range_for), unless `fixed_march_range` is set. Statistics of the last frame (decoder,
// selection, times) are kept for the HUD and reports.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>

#include "calf/decoder/clip_decoder.h"
#include "calf/format/container.h"
#include "calf/format/status.h"
#include "calf/player/cpu_renderer.h"
#include "calf/player/gl_context.h"
#include "calf/player/view_selection.h"

namespace calf::player {

struct PlaybackOptions {
  // Steps, weights, RR, ... ; active_views, near and far are set per frame.
  RenderOptions render;
  // Keep the march range in `render` instead of deriving it per frame.
  bool fixed_march_range = false;
  ViewSelectionOptions selection;
  decoder::ClipDecoderOptions decoder;
  // true: the GL 4.5 renderer (a current context and its functions are needed); false: the scalar
  // CPU reference renderer.
  bool use_gl = true;
  // GL only: keep BC5 depth compressed on the GPU (gl_views.h explains the trade).
  bool keep_bc5_depth = false;
};

// An eye's view for one frame: the camera (pose, field of view, image size).
using EyeCamera = Camera;

class Playback {
 public:
  // Opens `clip_path` (its first lightfield track). `gl` is needed when options.use_gl; the GL
  // context it was loaded from must stay current on this thread. Errors: the container's and
  // decoder's; CALF-E403 for invalid render options; CALF-E404 / E410 from the GL side;
  // CALF-E460 for a file without a lightfield track.
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
  // Whether any view carries material (the RR variant needs it).
  bool has_material() const;
  // The box the eye may move in: the clip's `view_volume` metadata, else the viewpoints' bounds.
  const Box3& view_volume() const;
  bool inside_view_volume(const Vec3& p) const;
  const std::vector<Vec3>& viewpoints() const;

  // Selects views and brings their textures to `frame` for `eyes` (one or more cameras: mono,
  // stereo, several users). Corrupt chunks are not errors (see last_stats().errors).
  Status prepare(uint32_t frame, std::span<const EyeCamera> eyes);
  // Renders `camera` with the views prepare() selected.
  Status render(const EyeCamera& camera, RenderedImage* out);

  // Changes render options (RR, steps, ...) from the next render; CALF-E403 on invalid ones.
  Status set_render_options(const RenderOptions& options);
  const PlaybackOptions& options() const;
  ViewSelector& selector();

  const decoder::FrameStats& last_stats() const;
  const ViewSelection& last_selection() const;
  double last_render_ms() const;

 private:
  struct Impl;
  explicit Playback(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace calf::player
