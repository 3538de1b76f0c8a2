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
#include <string>
#include <vector>

#include "calf/format/status.h"
#include "sweep.h"

namespace calf::bench {

struct PeerSettings {
  bool ffmpeg = true;  // false: the ffmpeg rows say "skipped (--no-ffmpeg)"
  std::string x265_preset = "medium";
  std::string x265_params;           // further x265 parameters of the colour peer, e.g. "keyint=1"
  double colour_tolerance_db = 0.5;  // how close x265's PSNR must come to calf's (dB)
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

}  // namespace calf::bench
