// The light-field track encoder (paper 002, Sec. 5): a capture set in, a lightfield track of a
// .calf container out, laid out as format/SPEC.md §11.1 specifies.
//
//   colour    per view, face and cell (default 64 x 64): keyframes chosen by Alg. 2
//             (calf/encoder/color_keyframes.h), each stored as one chunk in the colour format
//             (BC1 for LDR input, BC6H for HDR input, or BC7 / raw RGBA8 / raw RGBA16F), plus one
//             chunk of 8-bit interpolation weights t per cell.
//   depth     per view a log-16 range measured from the data (z_near / z_far over every finite
//             depth of every frame); per face tile (default 2 x 2 per face) one chunk per
//             keyframe interval holding a keyframe and P-frames of at most A rectangles covering
//             the texels that differ from any of the previous W frames (Alg. 3,
//             calf/encoder/depth_aabb.h); raw 16-bit (exact) or BC5 (hi / lo byte, lossy).
//   material  only for views that see a reflective or refractive texel: coded like depth, as
//             raw bytes when depth is raw16 and as BC1 when depth is BC5.
//
// Quality (what Q means). Q bounds the *temporal* loss: every frame x of every cell, as the
// decoder shows it (keyframes after BCn decode, t quantised to 8 bits, interpolated in linear
// light), is within Q dB of frame x as the spatial codec alone would show it (x encoded as if it
// were a keyframe). The spatial codec's own loss is the chosen format's (BC1 ~35-45 dB); measuring
// the interpolation against the original instead would make every frame a keyframe whenever the
// format's own PSNR is below Q, and a static cell would never be one keyframe. LDR cells use
// PSNR on sRGB (psnr_srgb); HDR cells use log2-PSNR (psnr_log2 below).
//
// Determinism: the output bytes depend on the input and the options only, never on `threads`
// (cells and tiles are coded independently into per-task buffers, then appended in a fixed order).
// Memory: one view is held at a time (all its frames: ~13 bytes per texel per frame), never all
// views.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "calf/capture/capture_set.h"
#include "calf/format/container.h"
#include "calf/format/status.h"

namespace calf {

// Colour format choice; kAuto = BC1 for LDR input (every colour value <= 1), BC6H for HDR.
enum class ColourCoding : uint8_t { kAuto, kBc1, kBc7, kBc6h, kRgba8, kRgba16f };
enum class DepthCoding : uint8_t { kRaw16, kBc5 };

struct LightfieldEncodeOptions {
  uint32_t cell_size = 64;            // colour cell side (px), 4..16384 and a multiple of 4
  double min_psnr_db = 50;            // Q, (0, 200]
  ColourCoding colour = ColourCoding::kAuto;
  DepthCoding depth = DepthCoding::kRaw16;
  uint32_t depth_tiles_per_side = 2;  // 1..64
  uint32_t depth_window = 2;          // W, >= 1
  uint32_t max_aabbs = 2;             // A, 1..64
  uint32_t depth_keyframe_interval = 30;  // a depth keyframe every K frames, >= 1
  container::Compression supercompression = container::Compression::kZstd;
  container::CompressionOptions levels;  // zstd level / LZMA preset (fixed per clip)
  uint32_t threads = 1;  // 0 = all cores; never changes the output
  // Called after each view-face is done (done, total); from the calling thread only.
  std::function<void(uint64_t done, uint64_t total)> progress;
};

// Bytes of one stream at each stage of paper 002 Table 1.
struct StreamBytes {
  uint64_t raw = 0;         // every frame uncompressed (colour: RGBA8 or RGBA16F; depth: 16-bit;
                            // material: 3 bytes per texel)
  uint64_t temporal = 0;    // after temporal coding, payload in the raw format (+ t, rect tables)
  uint64_t spatial = 0;     // after spatial (BCn) coding too: the chunks' raw bytes
  uint64_t stored = 0;      // after supercompression: the chunks' stored bytes
  uint64_t chunks = 0;
};

struct LightfieldEncodeStats {
  uint16_t colour_format = 0, depth_format = 0, material_format = 0;  // container::PixelFormat
  bool hdr = false;
  StreamBytes colour;  // keyframe chunks and t chunks together
  StreamBytes depth;
  StreamBytes material;
  uint64_t index_bytes = 0;  // stored bytes of the per-view index chunks
  uint64_t colour_cells = 0, colour_keyframes = 0;
  uint64_t depth_tiles = 0, depth_keyframes = 0, depth_pframes = 0, depth_empty_pframes = 0;
  uint64_t material_views = 0;
  double min_colour_quality_db = 0;  // lowest temporal quality of any frame of any cell (+inf)
  // BC5 depth only: reconstruction error against the quantised input over every finite texel of
  // every frame, as relative depth error |z' / z - 1|, and texels whose sky-ness changed.
  double depth_max_rel_error = 0, depth_mean_rel_error = 0;
  uint64_t depth_sky_mismatches = 0;
};

// Encodes every view of `input` into a new lightfield track of `writer` (does not finish it).
// Errors: kEncoderOption; the capture reader's (file, face and pixel named); kEncoderInput;
// container and block-codec errors passed through.
Expected<LightfieldEncodeStats> encode_lightfield(const capture::CaptureSetReader& input,
                                                  container::Writer& writer,
                                                  const LightfieldEncodeOptions& options);

// Opens the capture set at `capture_dir`, encodes it into `out_path` (written whole or not at
// all), and sets metadata "encoder" and "source_scene".
Expected<LightfieldEncodeStats> encode_lightfield_file(const std::filesystem::path& capture_dir,
                                                       const std::string& out_path,
                                                       const LightfieldEncodeOptions& options);

// A cell of linear RGB (w * h * 3 floats) as the spatial codec alone would show it: coded in
// `coding` (not kAuto) exactly as a keyframe is, then decoded to linear RGB. This is the reference
// Q is measured against; tests use it to check decoded files.
Status spatial_colour_reference(ColourCoding coding, std::span<const float> rgb, uint32_t w,
                                uint32_t h, std::vector<float>* shown);

// HDR metric: 10 log10(8^2 / MSE) over log2(max(v, 2^-14)) of every channel, i.e. PSNR in stops
// with an 8-stop peak (+inf when identical). 50 dB is an RMS error of 0.025 stops (~1.8 %).
double psnr_log2(std::span<const float> reference, std::span<const float> test);

}  // namespace calf
