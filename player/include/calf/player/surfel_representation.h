// The surfel representation (paper 001 playback): a surfels track (kind 3,
// calf/decoder/surfels_track.h) with the mesh track it pairs with (calf/decoder/mesh_track.h),
// played so that far objects cost a prefix of their prototype's surfel buffer and near objects are
// drawn as their mesh.
//
//   open:     decodes every prototype's surfels (once; instances share them) and opens the paired
//             mesh track as a MeshRepresentation (mesh_representation.h), which keeps objects'
//             transforms and vertex states at each frame;
//   prepare:  per object, from its bounding sphere (the prototype's quantisation box placed by
//             the object's transform) and the nearest eye: d = the distance from the eye to the
//             sphere (at least the near distance), the world size of one pixel there
//             w = d * 2 tan(fov_y / 2) / height, the disc radius r = point_size / 2 * w (in object
//             units: divided by the transform's scale, cbrt |det|) and the prefix
//             p = ceil(p_m (r_m / r)²) (paper 001 Eq. 1, surfels::prefix_for_radius). When p would
//             exceed blend_share * N the object is also drawn from the mesh; past N (the buffer
//             cannot cover the surface at that size) it is drawn from the mesh only. Between the
//             two both are drawn and composited by depth (the blend zone: no hole opens while an
//             object changes representation). A prototype without surfels is always a mesh.
//             With foveation on (paper 001 Sec. 4.4, fixed foveated rendering), the point size
//             of an object grows with the screen position of its sphere's centre: e = the
//             centre's distance from the image centre, 1 at the image corners (the smallest e
//             over the eyes); size x 1 inside `inner`, x periphery_scale beyond `outer`, linear in
//             e between, so the periphery draws shorter prefixes and changes quality smoothly;
//   render:   the mesh objects through the mesh renderer, the surfel objects through the surfel
//             splatter (surfel_renderer.h), composited by radial depth;
//             With target_frame_ms > 0, prepare first asks the frame-time controller
//             (frame_controller.h) for the point size: it is given the exact work (surfels
//             and mesh triangles) this view needs at any point size and picks the size its model
//             of the two passes predicts to meet the target;
//   render:   the mesh pass and the surfel pass are timed apart (wall and process CPU time);
//   report_frame_time: the frame (every render since the prepare) took frame_ms: its work and
//             its passes' times refit the controller's model (controller_clock kCpu: the
//             renders' process CPU times stand for the frame time instead).
//
// stats(): objects as surfels / mesh / both, surfels and triangles drawn, point size, and the last
// prepare's and render's times in ms.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string_view>

#include "calf/format/container.h"
#include "calf/format/status.h"
#include "calf/player/gl_context.h"
#include "calf/player/mesh_representation.h"
#include "calf/player/representation.h"
#include "calf/player/surfel_draw_list.h"

namespace calf::player {

// Fixed foveated rendering (paper 001 Sec. 4.4): zones by e, the distance from the image centre
// in units of the half-diagonal (0 at the centre, 1 at the corners, > 1 off screen or behind).
struct SurfelFoveation {
  bool enabled = false;
  double inner = 0.35;           // the fovea: e <= inner keeps the point size, [0, outer]
  double outer = 0.75;           // the periphery starts here, [inner, 4]
  double periphery_scale = 2.0;  // point-size factor at e >= outer, [1, 16]
};

enum class SurfelClock : uint8_t { kWall, kCpu };

struct SurfelOptions {
  SurfelRenderOptions render;
  MeshOptions mesh;
  // Disc diameter in pixels the prefixes are chosen for (the start value when the controller is
  // on), within [min_point_size, max_point_size]; 0 < min <= max <= 64. 1.5: on the factory's
  // ground-level walk the worst pose's SSIM against the full mesh is 0.914 (2 px: 0.896) at 51x
  // its frame rate (docs/SURFELS.md).
  double point_size = 1.5;
  double min_point_size = 1.0;
  double max_point_size = 16.0;
  // Frame-time target in ms (finite, >= 0); 0: the point size stays fixed.
  double target_frame_ms = 0.0;
  // The controller keeps the point size while its predicted frame time is within +-deadband x
  // target, [0, 1).
  double controller_deadband = 0.05;
  // The time the controller follows: the reported frame time (kWall), or the process CPU time of
  // the renders (kCpu: all threads, llvmpipe's included; less sensitive to other processes on a
  // shared machine, but CPU ms, not display ms).
  SurfelClock controller_clock = SurfelClock::kWall;
  // An object whose prefix would exceed blend_share * N surfels is drawn from the mesh as well,
  // [0, 1]; 1: no blend zone.
  double blend_share = 0.5;
  SurfelFoveation foveation;
};

class SurfelRepresentation final : public Representation {
 public:
  // Plays surfels track `track` of `reader` (which must outlive the representation) with the mesh
  // track it pairs with. `gl` is needed for RenderBackend::kGl. Errors: CALF-E473 (not a
  // surfels track), CALF-E461 (options out of range), the surfels and mesh tracks' decoding and
  // pairing errors (CALF-E230 - E235), MeshRepresentation::open's, CALF-E474 / E404 / E412.
  static Expected<std::unique_ptr<SurfelRepresentation>> open(const container::Reader& reader,
                                                              uint16_t track,
                                                              const SurfelOptions& options,
                                                              RenderBackend backend,
                                                              const GlFunctions* gl);
  ~SurfelRepresentation() override;
  SurfelRepresentation(const SurfelRepresentation&) = delete;
  SurfelRepresentation& operator=(const SurfelRepresentation&) = delete;

  // Representation.
  std::string_view kind() const override;
  uint16_t track() const override;
  RenderBackend backend() const override;
  uint32_t frame_count() const override;
  double fps() const override;
  const Box3& view_volume() const override;
  Status prepare(uint32_t frame, std::span<const Camera> eyes) override;
  Status render(const Camera& camera, RenderedImage* out) override;
  Status report_frame_time(double frame_ms) override;
  RepresentationStats stats() const override;
  // Triangles and points drawn, the point size, peripheral objects, the passes' times and the
  // controller's prediction.
  FrameFigures figures() const override;

  // The mesh track this representation also plays (Playback does not open it again).
  uint16_t mesh_track() const;
  double point_size() const;
  // The controller's predicted frame time for the prepared point size (0 without a target or
  // before the first report).
  double predicted_frame_ms() const;
  SurfelPassTimes last_pass_times() const;
  uint64_t surfels_drawn() const;
  uint64_t triangles_drawn() const;
  // Objects drawn with a foveation factor above 1 at the prepared frame (0 without foveation).
  uint32_t peripheral_objects() const;
  // The surfel draw list at the prepared frame.
  const SurfelDrawList& draw_list() const;

 private:
  struct Impl;
  explicit SurfelRepresentation(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

// CALF-E461 naming the first option out of its range, else OK.
[[nodiscard]] Status validate_surfel_options(const SurfelOptions& options);

}  // namespace calf::player
