// Private to the light-field encoder's view pass: one view in memory, the per-task output, and the
// tasks that code it (colour cells: lightfield_colour.cc; depth, material and coverage regions:
// lightfield_regions.cc), scheduled by lightfield_encode.cc.
#pragma once

#include <cstdint>
#include <limits>
#include <optional>
#include <vector>

#include "calf/capture/capture_set.h"
#include "calf/encoder/lightfield_encode.h"
#include "calf/format/bc.h"
#include "calf/format/container.h"
#include "calf/format/grid.h"
#include "calf/format/lightfield_layout.h"
#include "calf/format/log_depth.h"
#include "calf/format/status.h"

namespace calf::encoder::lightfield_internal {

inline constexpr double kInf = std::numeric_limits<double>::infinity();

// The noise-aware keyframe test and the pre-filter count a block's own render noise up to this
// many times the capture's estimate (darker regions are noisier in log2; docs/ENCODER.md
// "Keyframes and render noise").
inline constexpr double kNoiseBlockCap = 8;

// ---- Colour conversions (SPEC §11.1: 8-bit colour formats hold sRGB-encoded values) ----

inline uint16_t half_from_colour(float v) {
  return bc::float_to_half(std::min(v, 65504.0f));  // input is validated finite and >= 0
}

// ---- One view in memory ----

struct ViewData {
  uint32_t frames = 0, face_size = 0;
  size_t texels = 0;                        // per frame, all six faces
  std::vector<uint16_t> colour;             // half RGB, [frame][texel][3]
  std::vector<uint16_t> depth;              // log-16 codes, [frame][texel]
  std::vector<uint8_t> material;            // [frame][texel][3] codes, empty without material
  std::vector<lf::CoverageTexel> coverage;  // [frame][texel], empty without a coverage stream
  std::optional<LogDepthRange> range;       // none when the view sees only sky
  bool has_material = false;                // some texel of some frame reflects or refracts

  size_t index(uint32_t frame, uint32_t face, uint32_t x, uint32_t y) const {
    return static_cast<size_t>(frame) * texels +
           (static_cast<size_t>(face) * face_size + y) * face_size + x;
  }
};

// Reads frames [first_frame, first_frame + frame_count) of `view` and checks that the images
// still say what the analysis saw (`expected`): the depth codes are taken in the analysis's range.
Status read_view(const capture::CaptureSetReader& input, uint32_t view,
                 const LightfieldViewFacts& expected, bool with_coverage, uint32_t first_frame,
                 uint32_t frame_count, ViewData* out);

// Unmixes the colour of every frame of `view` (LightfieldEncodeOptions::coverage_unmix) from its
// coverage, as a decoded clip gives it (shares in 16ths): lightfield_unmix.cc. Returns the
// texel-frames changed. `view` has coverage and a depth range.
Expected<uint64_t> unmix_view_colour(const capture::CoverageUnmixOptions& options, ViewData* view);

// ---- Per-task output ----

struct Pending {
  container::ChunkKeys keys;
  container::StoredChunk chunk;
};

struct TaskStats {
  StreamBytes colour, depth, material, coverage;
  uint64_t keyframes = 0, depth_keyframes = 0, pframes = 0, empty_pframes = 0;
  double min_quality = kInf;
  double max_rel = 0, sum_rel = 0;
  uint64_t finite_texels = 0, sky_mismatches = 0;
};

struct TaskOut {
  Status status;
  std::vector<Pending> chunks;
  TaskStats stats;
};

struct Context {
  const LightfieldEncodeOptions* options;
  const ViewData* view;
  uint32_t view_index;
  ColourCoding colour;  // resolved (never kAuto)
  bool hdr;
  FaceGrid cells, tiles;
  uint32_t first_frame;  // the clip frame of the view data's frame 0
  bool partial;          // a frame range short of the clip: t chunks stay raw for the merge
  uint32_t fps_numerator = 24, fps_denominator = 1;  // the track's (AV1 colour's timing)
};

// Compresses `raw` into a chunk of the view with `keys` and counts it in `bytes`.
Status add_chunk(const Context& ctx, TaskOut& out, container::ChunkKeys keys,
                 const std::vector<uint8_t>& raw, StreamBytes& bytes, bool uncompressed = false);

// Codes colour cell `cell` of `face` (lightfield_colour.cc).
void colour_task(const Context& ctx, uint32_t face, uint32_t cell, TaskOut& out);

// The region streams a tile is coded in.
enum class RegionStream : uint8_t { kDepth, kMaterial, kCoverage };

// Codes tile `tile` of `face` in `stream` (lightfield_regions.cc).
void region_task(const Context& ctx, uint32_t face, uint32_t tile, RegionStream stream,
                 TaskOut& out);

// A task's figures in the track's terms, so that one merge (add_figures) serves tasks and views.
LightfieldEncodeStats figures_of(const TaskStats& task);

// Adds the counts and bytes of `part` to `total` (formats and hdr are the track's, not summed).
void add_figures(LightfieldEncodeStats& total, const LightfieldEncodeStats& part);

}  // namespace calf::encoder::lightfield_internal
