// The light-field representation (paper 002): a lightfield track played by ray-marching the
// nearest viewpoints' colour + depth cube maps.
//
//   prepare(frame, eyes):  view selection (view_selection.h, which asks its frame budget) from
//                          the eyes' midpoint -> the view-dependent decoder
//                          (calf/decoder/lightfield_decoder.h) advances the selected views to
//                          `frame` for the eyes' frusta -> the updates go to the GPU textures
//                          (GlViews) or, for the CPU reference renderer, to CpuTextures and from
//                          there into the CPU views (only the faces the updates changed are
//                          converted again);
//   render(camera, image): ray-marches one eye with the selected views (LightfieldGlRenderer or
//                          LightfieldCpuRenderer; the same LightfieldRenderOptions).
//
// The march range (LightfieldRenderOptions near / far) is derived per frame from the clip's views
// and the eye (march_range_for), unless `fixed_march_range` is set. With RR on and material in the
// clip, the decoder keeps every cell current (secondary rays read texels outside the eyes' frusta);
// this is decided when the options are set, not per frame.
#pragma once

#include <memory>
#include <span>
#include <string_view>
#include <utility>
#include <vector>

#include "calf/decoder/lightfield_decoder.h"
#include "calf/format/container.h"
#include "calf/format/status.h"
#include "calf/player/gl_context.h"
#include "calf/player/lightfield_cpu_renderer.h"
#include "calf/player/representation.h"
#include "calf/player/view_selection.h"

namespace calf::player {

struct LightfieldOptions {
  // Steps, weights, RR, ... ; near and far are set per frame. The frame's active views (view
  // selection's) go to the renderer's render() apart from these options.
  LightfieldRenderOptions render;
  // Keep the march range in `render` instead of deriving it per frame.
  bool fixed_march_range = false;
  ViewSelectionOptions selection;
  decoder::LightfieldDecoderOptions decoder;
  // GL only: keep BC5 depth compressed on the GPU (gl_views.h explains the trade).
  bool keep_bc5_depth = false;
  // Decode and upload the track's coverage stream (SPEC §11.1.11) even where `render` reads none
  // of it (coverage 0 and surface_hint_coverage 0), so that set_render_options() can turn it on
  // while playing (the window's C key). false: opened with such options, the representation
  // reads none of the stream and decodes, renders and costs what the same clip without it does;
  // coverage turned on later then changes nothing, as on a clip without coverage.
  bool keep_coverage = true;
};

class LightfieldRepresentation final : public Representation {
 public:
  // Plays lightfield track `track` of `reader`, which must outlive the representation. `gl` is
  // needed for RenderBackend::kGl; the GL context it was loaded from must stay current on this
  // thread. Errors: the decoder's; CALF-E403 for invalid render options; CALF-E404 / E410 from
  // the GL side; CALF-E460 when the track is not a lightfield track.
  static Expected<std::unique_ptr<LightfieldRepresentation>> open(const container::Reader& reader,
                                                                  uint16_t track,
                                                                  const LightfieldOptions& options,
                                                                  RenderBackend backend,
                                                                  const GlFunctions* gl);
  ~LightfieldRepresentation() override;
  LightfieldRepresentation(const LightfieldRepresentation&) = delete;
  LightfieldRepresentation& operator=(const LightfieldRepresentation&) = delete;

  // Representation.
  std::string_view kind() const override;
  uint16_t track() const override;
  RenderBackend backend() const override;
  uint32_t frame_count() const override;
  double fps() const override;
  // The clip's `view_volume` metadata, else the viewpoints' bounds.
  const Box3& view_volume() const override;
  // Selects views and brings their textures to `frame` for `eyes`. Errors: CALF-E403 (no eye),
  // the selector's (CALF-E452), the decoder's (CALF-E300) and the texture side's.
  Status prepare(uint32_t frame, std::span<const Camera> eyes) override;
  Status render(const Camera& camera, RenderedImage* out) override;
  // Feeds view selection's frame budget (performance culling).
  Status report_frame_time(double frame_ms) override;
  RepresentationStats stats() const override;

  // Whether any view carries material (the RR variant needs it).
  bool has_material() const;
  // Whether the track has a coverage stream (LightfieldRenderOptions::coverage needs it; SPEC
  // §11.1.11), whether or not it is decoded (LightfieldOptions::keep_coverage).
  bool has_coverage() const;
  // The CPU backend's views after the last prepare(), indexed like the clip (a view never active
  // yet is a one-texel placeholder), with the clip's coverage where it has a coverage stream;
  // nullptr for the GL backend. For tests and tools.
  const ViewSet* cpu_views() const;
  const std::vector<Vec3>& viewpoints() const;
  // Changes render options (RR, steps, ...) from the next render; CALF-E403 on invalid ones.
  Status set_render_options(const LightfieldRenderOptions& options);
  const LightfieldOptions& options() const;
  ViewSelector& selector();

  // The views the decoder dropped at open (an unusable index chunk;
  // LightfieldDecoder::view_problem), increasing, each with why. They are never selected; the
  // others play.
  std::vector<std::pair<uint32_t, Status>> dropped_views() const;

  const decoder::FrameStats& last_stats() const;
  const ViewSelection& last_selection() const;
  double last_render_ms() const;
  // Time of the last prepare() spent bringing the renderer's views up to date after decoding
  // (GL: texture uploads; CPU: converting changed faces into the CPU views), in ms.
  double last_upload_ms() const;

 private:
  struct Impl;
  explicit LightfieldRepresentation(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace calf::player
