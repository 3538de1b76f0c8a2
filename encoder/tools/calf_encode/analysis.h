// calf-encode's sharded lightfield encode (docs/FARM.md): --analysis-only writes the analysis file
// of a capture set, --analysis with --views (and --frame-range) codes one shard with the options
// that file records; calf-merge joins the shards (calf/encoder/lightfield_shard.h).
#pragma once

#include <filesystem>
#include <string>

#include <CLI/CLI.hpp>

#include "calf/encoder/lightfield_encode.h"
#include "calf_encode/common.h"

namespace calf::tools {

struct ShardOptions {
  bool analysis_only = false;  // step 1: write the analysis file
  std::string analysis;        // step 2: the analysis file a shard codes with
  std::string views;           // the shard's views, e.g. 0-2,5
  std::string frame_range;     // the shard's frames FIRST-LAST; empty: every frame
};

inline constexpr const char* kShardGroup =
    "Sharded lightfield encode options (--mode lightfield, docs/FARM.md)";

void add_options(CLI::App& app, ShardOptions& options);

// Step 1: the analysis pass over the capture set at `dir` with `encode`'s options, written to
// common.output. Returns the command's exit status.
int run_analysis(const CommonOptions& common, const std::filesystem::path& dir,
                 const encoder::LightfieldEncodeOptions& encode);

// Step 2: the shard of options.views (and options.frame_range) of the capture set at `dir`, coded
// with the options of the analysis file options.analysis, written to common.output. Returns the
// command's exit status.
int run_shard(const CommonOptions& common, const std::filesystem::path& dir,
              const ShardOptions& options);

}  // namespace calf::tools
