// Temporal pre-filter of render noise on static geometry (calf-encode --denoise-window;
// docs/ENCODER.md "Keyframes and render noise").
//
// A path tracer's noise that changes from frame to frame is coded inside every colour keyframe:
// BCn blocks and their supercompression spend bytes on a new draw of the noise, and the keyframe
// test sees the noise as change. Where a texel's geometry does not move, the frames around it
// are draws of the same signal, and their mean has 1/W of one frame's noise variance. This filter
// replaces each texel's colour by that mean, before any colour coding, where it can tell the
// frames apart only by noise:
//
//   window    frame f averages a window of W frames (fewer where the segment is shorter), as
//             centred on f as the segment allows (closed segments, segment_frames: the window
//             never crosses a segment boundary, so frame-range shards filter as one encode does);
//             from f outwards in both directions it takes frames up to the first one that fails
//             the tests below (the frames where the texel stays static).
//   static    frame g counts for texel x of frame f when x and its 4 neighbours (inside the face)
//             have the same depth code and the same material codes in g as in f.
//   noise     the change must be one noise explains: in the metric of the keyframe test (sRGB
//             values for LDR colour, log2 of max(v, 2^-14) over 8 stops for HDR), with s^2 the
//             noise variance of the texel's 8 x 8 block, every channel's difference g - f at x
//             is within k sqrt(2) s, and the mean difference over x's 3 x 3 neighbourhood (inside
//             the face) within k sqrt(2) s / sqrt(count): a real change (a moving shadow, a
//             lighting change, an edge) bigger than that is never averaged, so the texel keeps
//             its own frame's value.
//   s^2       per 8 x 8 block of a face and per segment, from the segment's consecutive frame
//             pairs: the difference d in the metric through the estimate's spatial high-pass
//             (d less the mean of its 4 neighbours', which cancels smooth change), on texels whose
//             geometry and that of their 4 neighbours is the same in both frames; the median of
//             its squares over 0.455 (a squared Gaussian's median) and 2.5 (the high-pass's gain),
//             at most max_variance. Fewer than 16 such samples in a block: 0.
//
// The mean is taken in linear light (what the decoder interpolates) and stored as half floats,
// like the capture's colour. Where s^2 is 0 (content whose noise does not change between frames:
// converged renders, fixed seeds) only identical values could be averaged, so the colour is left
// as it is, bit for bit. Each output texel depends on the input only, never on the thread count.
#pragma once

#include <cstdint>
#include <limits>
#include <span>

#include "calf/format/status.h"

namespace calf::encoder {

// calf-encode's window when --psnr auto finds the capture noisy (docs/ENCODER.md "Keyframes and
// render noise" measures 0 to 64 on a 12-frame set: the larger, the fewer bytes and the closer
// to the converged render there).
inline constexpr uint32_t kDefaultDenoiseWindow = 16;
// The largest window.
inline constexpr uint32_t kMaxDenoiseWindow = 64;
// k: a change beyond k noise standard deviations is signal, never averaged.
inline constexpr double kDenoiseSigmas = 3;
// The side of the blocks s^2 is measured in.
inline constexpr uint32_t kDenoiseBlock = 8;

struct StaticDenoiseOptions {
  uint32_t window = kDefaultDenoiseWindow;  // W, the most frames averaged, 1..kMaxDenoiseWindow
  double sigmas = kDenoiseSigmas;           // k, > 0
  bool log2 = false;  // the metric: log2 (HDR colour), else sRGB values (LDR colour)
  // The largest s^2 of a block (relative to the metric's peak squared): blocks of dark, noisy
  // texels in log2 count at most this much noise. Infinity: no cap.
  double max_variance = std::numeric_limits<double>::infinity();
  // Closed segments of this many frames (0 = one segment): no window crosses frame N, 2N, ...
  uint32_t segment_frames = 0;
  uint32_t threads = 1;  // 0 = all cores; never changes the result
};

// What the filter did, for the encoder's report.
struct StaticDenoiseStats {
  uint64_t texels = 0;    // texel-frames examined
  uint64_t averaged = 0;  // texel-frames replaced by a mean of two frames or more
};

// Filters the colour of one view in place: `colour` holds frames x 6 faces x face_size^2 texels
// of half-float RGB (frame-major, faces in GL order, rows top to bottom), `depth` the same
// texels' log-16 depth codes, `material` their 3 material codes each, or is empty (no material).
// Errors: kInvalidArgument (sizes that do not match, options out of range).
Expected<StaticDenoiseStats> denoise_static_colour(std::span<uint16_t> colour,
                                                   std::span<const uint16_t> depth,
                                                   std::span<const uint8_t> material,
                                                   uint32_t frames, uint32_t face_size,
                                                   const StaticDenoiseOptions& options);

}  // namespace calf::encoder
