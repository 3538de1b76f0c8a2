// calf-encode --mode lightfield (the default): a capture set (format/CAPTURE.md) into a .calf
// lightfield track (paper 002, Sec. 5; format/SPEC.md §11.1), in one run or sharded (analysis.h).
#pragma once

#include <string>

#include <CLI/CLI.hpp>

#include "calf/encoder/colour_denoise.h"
#include "calf/encoder/lightfield_encode.h"
#include "calf/encoder/noise_estimate.h"
#include "calf_encode/analysis.h"
#include "calf_encode/common.h"

namespace calf::tools {

enum class ColourCodec { kBc, kAv1 };

struct LightfieldOptions {
  // Cell, --color-format, depth coding and windows, BC1 fit, AV1 settings; threads, the image
  // budget, supercompression and the directory come from CommonOptions.
  encoder::LightfieldEncodeOptions encode;
  std::string psnr = "auto";  // Q in dB, or "auto" (from the capture's render noise)
  double psnr_noise_margin = encoder::kDefaultPsnrNoiseMargin;
  // The pre-filter's window, or "auto" (encoder::kDefaultDenoiseWindow where --psnr auto turns
  // the noise-aware test on with BC colour, else off).
  std::string denoise_window = "auto";
  std::string colour_rdo = "auto";  // lambda, or "auto" (each colour format's measured default)
  ColourCodec colour_codec = ColourCodec::kBc;
  bool no_coverage = false;
  double coverage_unmix = -1;       // the minimum own share, < 0: off
  double coverage_unmix_jump = -1;  // the minimum depth step, < 0: not given (0)
  bool fixed_groups = false;
  ShardOptions shard;  // a sharded encode's steps
};

inline constexpr const char* kLightfieldGroup = "Lightfield options (--mode lightfield)";
inline constexpr const char* kAv1Group =
    "AV1 colour options (--mode lightfield --colour-codec av1)";

// The lightfield mode's options (groups kLightfieldGroup, kAv1Group and kShardGroup).
void add_options(CLI::App& app, LightfieldOptions& options);

// Checks the lightfield options given on `app` against each other (contradictions are usage
// errors, exit 2) and completes options->encode from them and `common`. Returns -1 to go on, else
// the exit status of the error it printed.
int resolve(const CLI::App& app, const CommonOptions& common, LightfieldOptions* options);

// Encodes (or, with the shard options, writes the analysis file or a shard) after resolve();
// prints progress and the summary lines. Returns the command's exit status.
int run(const CommonOptions& common, const LightfieldOptions& options);

}  // namespace calf::tools
