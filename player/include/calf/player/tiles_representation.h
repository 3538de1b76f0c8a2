// The tiles representation (paper 000, Seurat, playback): a tile set (calf/format/tile_set.h) —
// what a tiles track decodes to — drawn as two triangles per tile with the rasterisers of
// tiles_renderer.h (back to front with premultiplied over, or depth + alpha test).
//
//   make:     validates the set, converts its atlas to premultiplied linear halves once
//             (tiles_linear_atlas) and, on GL, uploads corners and atlas once;
//   prepare:  nothing to bring up to date (a tile set is static: one frame);
//   render:   sorts the tiles back to front for this eye (kSorted) and rasterises them: colour +
//             radial depth of the nearest tile at least half covering each pixel, +inf elsewhere.
//
// stats(): tiles, triangles, the last render's measured overdraw (mean fragments per covered
// pixel and peak), atlas size, blend mode and the last render's time in ms ("draw").
#pragma once

#include <memory>
#include <span>
#include <string_view>

#include "calf/format/container.h"
#include "calf/format/status.h"
#include "calf/format/tile_set.h"
#include "calf/player/gl_context.h"
#include "calf/player/representation.h"
#include "calf/player/tiles_renderer.h"

namespace calf::player {

struct TilesOptions {
  TilesRenderOptions render;
};

class TilesRepresentation final : public Representation {
 public:
  // Plays `tiles`, which it keeps, as track `track` of one frame at `fps` (the track's rate, for
  // the timeline). `gl` is needed for RenderBackend::kGl; its context must stay current on this
  // thread. Errors: CALF-E477 (the set is not drawable, its atlas exceeds the GL texture size, or
  // fps is not > 0), CALF-E478 (options), CALF-E404 / E412 from the GL side.
  static Expected<std::unique_ptr<TilesRepresentation>> make(TileSet tiles, uint16_t track,
                                                             double fps,
                                                             const TilesOptions& options,
                                                             RenderBackend backend,
                                                             const GlFunctions* gl);
  // Decodes tiles track `track` of `reader` (calf/decoder/tiles_track.h; its errors CALF-E210 -
  // E213 pass through) and plays it as make() does, at the track's frame rate.
  static Expected<std::unique_ptr<TilesRepresentation>> open(const container::Reader& reader,
                                                             uint16_t track,
                                                             const TilesOptions& options,
                                                             RenderBackend backend,
                                                             const GlFunctions* gl);
  ~TilesRepresentation() override;
  TilesRepresentation(const TilesRepresentation&) = delete;
  TilesRepresentation& operator=(const TilesRepresentation&) = delete;

  // Representation.
  std::string_view kind() const override;  // "tiles"
  uint16_t track() const override;
  RenderBackend backend() const override;
  uint32_t frame_count() const override;  // 1
  double fps() const override;
  // The set's view region.
  const Box3& view_volume() const override;
  // Errors: CALF-E403 (no eye), CALF-E477 (a frame other than 0).
  Status prepare(uint32_t frame, std::span<const Camera> eyes) override;
  Status render(const Camera& camera, RenderedImage* out) override;
  // No frame budget: ignored (CALF-E453 for a negative or non-finite time, as the interface says).
  Status report_frame_time(double frame_ms) override;
  RepresentationStats stats() const override;
  // The quads: the tile count and the last render's overdraw.
  FrameFigures figures() const override;

  const TileSet& tile_set() const;
  // The last render's overdraw and time.
  const TilesFrameStats& last_frame_stats() const;
  double last_render_ms() const;

 private:
  struct Impl;
  explicit TilesRepresentation(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace calf::player
