// calf-encode --mode surfels: a scene file and its surfel candidates (format/SURFEL_CANDIDATES.md)
// into the scene's mesh track (track 0) and the surfels track paired with it (track 1; paper 001,
// format/SPEC.md §11.3, calf/encoder/surfels_build.h).
#pragma once

#include <string>

#include <CLI/CLI.hpp>

#include "calf/encoder/surfels_build.h"
#include "calf_encode/common.h"

namespace calf::tools {

struct SurfelsOptions {
  std::string candidates;  // the candidate file (calf-capture --surfel-candidates)
  encoder::SurfelBuildOptions build;
};

inline constexpr const char* kSurfelsGroup = "Surfels options (--mode surfels)";

void add_options(CLI::App& app, SurfelsOptions& options);

// Encodes the scene file common.input with options.candidates into common.output; prints the
// summary lines. Returns the command's exit status.
int run(const CommonOptions& common, const SurfelsOptions& options);

}  // namespace calf::tools
