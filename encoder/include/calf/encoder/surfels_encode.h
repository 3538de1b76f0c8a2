// The surfels track encoder (kind 3, format/SPEC.md §11.3): per prototype of a clip's mesh track,
// an ordered surfel buffer (paper 001: every prefix a level of detail) in, a surfels track of a
// .calf container out.
//
// The encoder does not sample: the buffers come ordered from the surfel builder (its
// progressive sampler decides the order and measures r_m, p_m). What it does:
//   validate  every array size, value and prefix parameter (CALF-E235 names the prototype and
//             surfel at fault), before anything is written;
//   plan      per prototype the quantisation box (the tight float bounds of its positions), its
//             record, the index chunk and the track header;
//   quantise  each surfel to 3 x u16 position codes in the box, 2 x u16 octahedral normal codes
//             (of the four codes around the projection, the one nearest in angle) and 3 sRGB bytes
//             (the byte whose decoded linear value is nearest), and code each level chunk
//             (§11.3.1): independent parts, options.threads at a time;
//   assemble  index, then per prototype its levels in order.
// The bytes depend on the input and the options only, never on `threads`. What a decoder gets
// back is within half a quantisation step of the input: a position within (box extent) / 131070
// per axis (plus float rounding), a normal within 5e-5 rad (measured max 4.3e-5), a colour the
// nearest of the 256 sRGB levels in linear value. Input already on the grid (decoded surfels) comes
// back bit for bit, so re-encoding a decoded track gives the same bytes.
#pragma once

#include <cstdint>
#include <vector>

#include "calf/format/container.h"
#include "calf/format/status.h"
#include "calf/format/surfels_layout.h"

namespace calf::encoder {

// One prototype's surfels, in prefix order (the sampler's order: surfel 0 first).
struct SurfelPrototypeInput {
  std::vector<float> positions;  // 3 per surfel, object space, finite, within +-1e12
  std::vector<float> normals;    // 3 per surfel, finite, non-zero (normalised by the encoder)
  std::vector<float> colours;    // 3 per surfel, linear RGB in [0, 1]
  // Paper 001 Eq. 1: r_m, the median nearest-neighbour distance (object space) among the first
  // p_m surfels. With surfels: 1 <= prefix_count <= count, prefix_radius finite and > 0. Without
  // (count 0, the prototype is drawn from the mesh): both 0.
  uint32_t prefix_count = 0;
  float prefix_radius = 0;
  // true: the colours are the surface's own base colour; false: they multiply the object's
  // material base colour, as mesh vertex colours do (SPEC §11.3.2 flags bit 0).
  bool colour_is_base = false;
  size_t size() const { return positions.size() / 3; }
};

// The whole track's input: one entry per prototype of the mesh track `mesh_track` of the same
// clip, in that track's prototype order (entry p approximates mesh prototype p).
struct SurfelsTrackInput {
  uint16_t mesh_track = 0;
  // The mesh track's timing (informative in a surfels track; copy it from MeshTrackHeader).
  uint32_t frame_count = 1;
  uint32_t fps_numerator = 24;
  uint32_t fps_denominator = 1;
  std::vector<SurfelPrototypeInput> prototypes;
};

struct SurfelsEncodeOptions {
  // Supercompression of every chunk of the track (zstd decodes fast; LZMA2 is smallest).
  container::Compression supercompression = container::Compression::kZstd;
  container::CompressionOptions levels;  // zstd level / LZMA preset (fixed per clip)
  uint32_t threads = 1;                  // 0 = all cores; never changes the output
};

struct SurfelsEncodeStats {
  uint32_t prototypes = 0;  // the header's object_count
  uint32_t prototypes_with_surfels = 0;
  uint64_t surfels = 0;  // the header's surfel_count
  uint64_t level_chunks = 0;
  uint64_t index_stored = 0;    // the index chunk's stored bytes
  uint64_t surfels_raw = 0;     // level chunks' raw bytes (13 per surfel)
  uint64_t surfels_stored = 0;  // level chunks' stored bytes
  uint64_t plain_bytes = 0;     // the input as plain f32 (36 per surfel): the baseline
};

// Checks `input` without writing (what encode_surfels_track checks first). Errors: kSurfelsInput
// (array sizes that disagree, a non-finite or out-of-bound position, a zero or non-finite
// normal, a colour outside [0, 1] or NaN, prefix parameters out of range, a mesh track id above
// 255), kSurfelsLimit (more prototypes or surfels than §11.3 holds).
Status validate_surfels_input(const SurfelsTrackInput& input);

// Encodes `input` into a new surfels track of `writer` (does not finish the writer; the caller
// adds the mesh track too, with the id input.mesh_track). `stats` (optional) receives the figures.
// Errors: validate_surfels_input's; kEncoderOption (threads above 256, an unknown
// supercompression); container errors passed through.
Status encode_surfels_track(const SurfelsTrackInput& input, const SurfelsEncodeOptions& options,
                            container::Writer* writer, SurfelsEncodeStats* stats = nullptr);

// The codes one prototype's surfels quantise to, in the box `record` gives (exposed for tests
// and tools; encode_surfels_track uses it). The input must have passed validation.
surfels::SurfelCodes quantise_surfels(const SurfelPrototypeInput& in,
                                      const surfels::PrototypeRecord& record);

}  // namespace calf::encoder
