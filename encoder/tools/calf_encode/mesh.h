// calf-encode --mode mesh: a scene file (format/SCENE.md) into a mesh track of the whole scene
// (format/SPEC.md §11.4), or with --visible-set of the triangles visible from its view region
// (paper 004; docs/VISIBILITY.md).
#pragma once

#include <cstdint>
#include <optional>

#include <CLI/CLI.hpp>

#include "calf/encoder/visible_set.h"
#include "calf_encode/common.h"

namespace calf::tools {

struct MeshOptions {
  bool visible_set = false;          // keep only the visible triangles
  std::optional<double> eye_height;  // none: the middle of the view region's y range
  uint32_t segments_per_edge = 1;
  encoder::VisibleSetOptions visibility;  // face size, granularity, motion (threads: --threads)
};

inline constexpr const char* kMeshGroup = "Mesh options (--mode mesh)";

// The mesh mode's options, in the group kMeshGroup; the visible-set knobs need --visible-set.
void add_options(CLI::App& app, MeshOptions& options);

// Encodes the scene file common.input into the clip common.output; prints the summary lines.
// Returns the command's exit status.
int run(const CommonOptions& common, const MeshOptions& options);

}  // namespace calf::tools
