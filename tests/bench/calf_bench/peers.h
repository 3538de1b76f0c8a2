// calf-bench: the peers of a scene, measured in the same run on the same capture (DESIGN.md
// "Measuring"): general-purpose coders on the raw streams, ffmpeg's lossless video coders
// on the log-16 depth and x265 on the colour at the PSNR calf's colour reached.
//
// The frames every peer codes: per clip frame one image holding every view's six cube faces, a
// row of faces per view (6 F wide, V F tall for V views of F x F faces), so that a video coder
// sees whole frames and the peers code exactly what the clip holds:
//   depth   log-16 codes (calf/format/log_depth.h), one LogDepthRange per view covering the finite
//           depths of all its frames (the encoder's rule, docs/ENCODER.md step 1), sky = kLog16Sky;
//           checked code for code against the base clip's decoded depth when it is raw16;
//   colour  8-bit sRGB (calf/format/colour.h srgb8_from_linear: HDR values clip to 255), the
//           display-referred frames the PSNR / SSIM of the sweep judge too. calf keeps HDR colour
//           HDR (BC6H); its PSNR here is measured the same way, on its decoded colour.
// Raw-stream peers: `xz -9` = liblzma LZMA2 preset 9 and `zstd -19` = libzstd level 19, through
// calf's own chunk coder (container::compress_chunk, one stream, no container framing), each
// decoded back and timed (fastest of 3 decodes); the two run side by side on two threads.
// ffmpeg peers: tests/bench/ffmpeg_peers.h.
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "../ffmpeg_peers.h"
#include "calf/format/status.h"
#include "sweep.h"

namespace calf::bench {

struct PeerSettings {
  bool ffmpeg = true;  // false: the ffmpeg rows say "skipped (--no-ffmpeg)"
  std::string x265_preset = "medium";
  std::string x265_params;           // further x265 parameters of the colour peer, e.g. "keyint=1"
  double colour_tolerance_db = 0.5;  // how close x265's PSNR must come to calf's (dB)
  // The x265 colour peer's pixel format in match_colour_to_x265: "auto" (yuv444p, else gbrp) or an
  // ffmpeg pix_fmt such as yuv420p (the AV1 mode's subsampling).
  std::string x265_pix_fmt = "auto";
};

// calf's numbers the peer table compares against, from the sweep.
struct CalfReference {
  std::filesystem::path base_clip;  // the base configuration's clip (decoded here)
  PointResult base;                 // its encode numbers
  std::string base_label;           // e.g. "BC6H + raw16 + zstd, cell 32, Q 50"
  // Further calf rows from the sweep (e.g. LZMA2, BC5 depth): stream, method, bytes, encode s.
  struct Extra {
    std::string stream, method;
    uint64_t bytes = 0;
    double encode_s = 0;
  };
  std::vector<Extra> extra;
};

// Measures every peer of the scene whose capture set is `capture_dir`; rows for calf first, then
// the peers (n/a with the reason where one cannot run). `notes` receives how the inputs were made.
Expected<std::vector<PeerRow>> measure_peers(const std::filesystem::path& capture_dir,
                                             const CalfReference& calf,
                                             const PeerSettings& settings, std::string* notes);

// One more calf clip of the same capture (e.g. the AV1 colour mode at a CRF) to set against x265.
struct ColourClip {
  std::string label;           // e.g. "AV1 CRF 32, cell 128, K 4"
  std::filesystem::path clip;  // decoded here
  uint64_t colour_bytes = 0;   // its colour stream's stored bytes
  double encode_s = 0;         // its whole encode
};

// A clip's colour against x265 at the PSNR it reaches: both judged as the peer set's 8-bit sRGB
// frames against the capture's (peak 255, mean per frame). Seek figures time
// LightfieldDecoder::advance on a fresh decoder (no culling) jumping to `seek_frames` frames.
struct ColourMatch {
  ColourClip calf;
  double psnr_db = 0;           // calf's decoded colour against the capture
  double decode_ms = 0;         // median advance() ms per frame in playback order, frames 2..n
  double upload_bytes = 0;      // mean texture-update payload bytes per frame (every view)
  double seek_ms = 0;           // mean advance() ms of a jump to a frame, fresh decoder
  uint32_t seek_max_units = 0;  // the most AV1 pictures one cell decoded for one jump (0: BC)
  PeerResult x265;
};

// Each clip of `clips` (of the capture at `capture_dir`) decoded and matched by x265 (settings'
// preset, parameters and tolerance), in order.
Expected<std::vector<ColourMatch>> match_colour_to_x265(const std::filesystem::path& capture_dir,
                                                        std::span<const ColourClip> clips,
                                                        const PeerSettings& settings);

}  // namespace calf::bench
