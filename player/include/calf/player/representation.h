// A representation: what plays one track of a clip. Each track kind that calf can play (the light
// field today; layered tiles, progressive surfels and a visible-set mesh next) has one
// implementation of this interface, with two backends: the GL renderer (the product) and the
// scalar CPU reference it is tested against. Playback (playback.h) holds one representation per
// playable track and composites their outputs by radial depth.
//
// Per displayed frame the player calls, for every representation:
//   prepare(frame, eyes)  bring the representation's state (decoded data, GPU textures, chosen
//                         subset) to clip frame `frame` for the viewers `eyes` (all eyes of the
//                         frame together: stereo or several users share the decoded data);
//   render(camera, out)   one eye: colour plus radial depth (RenderedImage) of what this
//                         representation shows, +inf depth where it shows nothing;
//   report_frame_time(ms) after the frame is displayed: the wall time between displayed frames,
//                         for representations that fit their work to a frame budget
//                         (frame_controller.h);
//   stats()               what the HUD and reports print, generically;
//   figures()             the numbers reports compute with, the same struct for every kind.
//
// Adding a representation: implement this interface in player/src/<kind>_representation.cc with
// its header player/include/calf/player/<kind>_representation.h, give both backends, add its
// entry to the player's kind table (player/src/kind_table.h) and a GL-vs-CPU test.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "calf/format/status.h"
#include "calf/player/lightfield_cpu_renderer.h"
#include "calf/player/rendered_image.h"

namespace calf::player {

// Which renderer a representation draws with.
enum class RenderBackend : uint8_t {
  kGl,   // OpenGL 4.5 (a current context and its functions, gl_context.h)
  kCpu,  // the scalar CPU reference
};

// One figure for the HUD or a report, already formatted: "active views" = "7 (max 9, distance)".
struct Statistic {
  std::string name;
  std::string value;
  bool alert = false;  // worth the viewer's attention (damaged data, a fallback in use)
};

// A representation's figures of its latest frame, in the order to show them.
struct RepresentationStats {
  std::string title;  // e.g. "lightfield track 0 (gl)"
  std::vector<Statistic> entries;
};

// The passes' times of the renders since the latest prepare, ms: wall clock and process CPU time.
// frame_* is every render() call whole (both passes, the compositing and what lies between).
struct SurfelPassTimes {
  double mesh_ms = 0, surfels_ms = 0, frame_ms = 0;
  double mesh_cpu_ms = 0, surfels_cpu_ms = 0, frame_cpu_ms = 0;
};

// The numbers of the latest frame that reports compute with (calf-play's headless line per pose),
// one struct for every kind: a representation fills what it draws and leaves the rest empty, and
// Playback::figures() gathers them over a clip's representations.
struct FrameFigures {
  // Triangles rasterised from meshes (mesh tracks, a surfels track's near objects).
  uint64_t triangles_drawn = 0;
  // Textured quads (a tiles track): how many, and the last render's overdraw.
  struct Quads {
    size_t count = 0;
    double mean_overdraw = 0;  // fragments per covered pixel
    uint32_t peak_overdraw = 0;
  };
  std::optional<Quads> quads;
  // Points (a surfels track): how many were drawn, at which diameter in pixels, the objects a
  // foveation factor above 1 enlarged, the passes' times and the frame-time controller's
  // prediction (0 without a target).
  struct Points {
    uint64_t drawn = 0;
    double point_size = 0;
    uint32_t peripheral_objects = 0;
    SurfelPassTimes passes;
    double predicted_frame_ms = 0;
  };
  std::optional<Points> points;
};

class Representation {
 public:
  virtual ~Representation() = default;

  // The track kind's name as calf-info prints it ("lightfield"), the track index in the clip
  // and the backend.
  virtual std::string_view kind() const = 0;
  virtual uint16_t track() const = 0;
  virtual RenderBackend backend() const = 0;

  // The track's timeline: frames and frames per second.
  virtual uint32_t frame_count() const = 0;
  virtual double fps() const = 0;
  // The box (low, high corners) the eye may move in for this track.
  virtual const Box3& view_volume() const = 0;

  // See above. At least one eye, else CALF-E403; other errors (a frame past the end among them)
  // are the implementation's, documented there. Damaged data is not an error: it shows in
  // stats().
  virtual Status prepare(uint32_t frame, std::span<const Camera> eyes) = 0;
  // Renders `camera` with the state prepare() reached; `out` is resized to the camera's image.
  virtual Status render(const Camera& camera, RenderedImage* out) = 0;
  // The wall time in ms (finite, >= 0) between the last two displayed frames; CALF-E453
  // otherwise. Representations without a frame budget ignore it.
  virtual Status report_frame_time(double frame_ms) = 0;
  // The figures of the latest prepare() / render().
  virtual RepresentationStats stats() const = 0;
  // The numbers of the latest prepare() / render() (empty: a kind that draws none of them).
  virtual FrameFigures figures() const { return {}; }
};

}  // namespace calf::player
