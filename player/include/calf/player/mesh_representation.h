// The mesh representation (paper 004 playback): a mesh track (kind 4, calf/decoder/mesh_track.h)
// — the full scene or its visible set — played as a mesh with the rasterisers of mesh_renderer.h.
//
//   open:     reads the track's index, every prototype and object (their transforms and triangle
//             subsets) and the materials into a MeshDrawList (mesh_draw_list.h); the GL backend
//             uploads it once (one set of buffers per prototype, shared by its instances);
//   prepare:  the frame's time is frame / fps: prototypes with vertex states get their positions
//             at that time (decoder::positions_at) and, on GL, only those are re-uploaded; every
//             object takes its transform at the frame (decoder::transform_at, a uniform on GL);
//   render:   rasterises the draw list for one eye: colour + radial depth, +inf where nothing.
//
// stats(): objects, triangles drawn (the objects' subsets) of the track's total, prototypes with
// states, and the last prepare's and render's times in ms ("draw").
#pragma once

#include <memory>
#include <span>
#include <string_view>

#include "calf/format/container.h"
#include "calf/format/status.h"
#include "calf/player/gl_context.h"
#include "calf/player/mesh_draw_list.h"
#include "calf/player/mesh_renderer.h"
#include "calf/player/representation.h"

namespace calf::player {

struct MeshOptions {
  MeshRenderOptions render;
};

class MeshRepresentation final : public Representation {
 public:
  // Plays mesh track `track` of `reader`, which must outlive the representation. `gl` is needed
  // for RenderBackend::kGl; its context must stay current on this thread. Errors: CALF-E473 (not
  // a mesh track; an object naming a prototype or material the track lacks), the track's
  // decoding errors, CALF-E470 (the decoded list is not drawable), CALF-E471, CALF-E404 / E412
  // from the GL side.
  static Expected<std::unique_ptr<MeshRepresentation>> open(const container::Reader& reader,
                                                            uint16_t track,
                                                            const MeshOptions& options,
                                                            RenderBackend backend,
                                                            const GlFunctions* gl);
  // The same from a draw list built by the caller (tests, tools): `list` at every frame (no
  // states, static transforms), one frame at `fps`, the view volume given.
  static Expected<std::unique_ptr<MeshRepresentation>> from_draw_list(MeshDrawList list,
                                                                      const Box3& view_volume,
                                                                      const MeshOptions& options,
                                                                      RenderBackend backend,
                                                                      const GlFunctions* gl);
  ~MeshRepresentation() override;
  MeshRepresentation(const MeshRepresentation&) = delete;
  MeshRepresentation& operator=(const MeshRepresentation&) = delete;

  // Representation.
  std::string_view kind() const override;
  uint16_t track() const override;
  RenderBackend backend() const override;
  uint32_t frame_count() const override;
  double fps() const override;
  const Box3& view_volume() const override;
  // Brings positions and transforms to `frame`. Errors: CALF-E403 (no eye), CALF-E473 (a frame
  // past the end), GL upload errors.
  Status prepare(uint32_t frame, std::span<const Camera> eyes) override;
  Status render(const Camera& camera, RenderedImage* out) override;
  // No frame budget: ignored (CALF-E453 for a negative or non-finite time, as the interface says).
  Status report_frame_time(double frame_ms) override;
  RepresentationStats stats() const override;
  // The triangles drawn.
  FrameFigures figures() const override;

  // The draw list at the prepared frame.
  const MeshDrawList& draw_list() const;
  // Shows or hides object `o` (< the draw list's object count) from the next render on; the
  // surfel representation hides the objects it draws as surfels. Triangles drawn follow.
  void set_object_visible(size_t o, bool visible);
  // Triangles drawn per render (the objects' subsets) and the prototypes' total over the objects.
  uint64_t triangles_drawn() const;
  uint64_t triangles_total() const;
  double last_render_ms() const;
  double last_prepare_ms() const;

 private:
  struct Impl;
  explicit MeshRepresentation(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace calf::player
