// What every mode of calf-encode shares: the input and output, the mode itself, threads, the
// image budget, supercompression, the container's directory and --quiet; the mode table; the
// helpers each mode's run() reports with. Each mode lives in its own file (<mode>.h / <mode>.cc:
// an options struct whose members hold the defaults, add_options() and run()).
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>

#include <CLI/CLI.hpp>

#include "calf/capture/image_budget.h"
#include "calf/format/container_types.h"
#include "calf/format/status.h"
#include "enum_option.h"

namespace calf::tools {

enum class EncodeMode { kLightfield, kMesh, kSurfels, kTiles };

inline constexpr EnumTable<EncodeMode, 4> kEncodeModes = {{{"lightfield", EncodeMode::kLightfield},
                                                           {"mesh", EncodeMode::kMesh},
                                                           {"surfels", EncodeMode::kSurfels},
                                                           {"tiles", EncodeMode::kTiles}}};

inline constexpr EnumTable<container::Compression, 3> kSupercompressions = {
    {{"zstd", container::Compression::kZstd},
     {"lzma2", container::Compression::kLzma2},
     {"none", container::Compression::kNone}}};

struct CommonOptions {
  std::string input;   // a capture set or a scene file: its folder or its manifest
  std::string output;  // the .calf written
  EncodeMode mode = EncodeMode::kLightfield;
  uint32_t threads = 0;  // 0 = all cores
  uint64_t max_image_pixels = capture::kDefaultMaxImagePixels;
  container::Compression supercompression = container::Compression::kZstd;
  bool plain_directory = false;  // a container 1.0 file
  bool quiet = false;
};

void add_options(CLI::App& app, CommonOptions& options);

// The folder of `input`: `input` itself, or its parent when it names the file `manifest`.
std::filesystem::path input_folder(const std::string& input, const char* manifest);

// Prints `status` as calf-encode's one line; returns exit status 1.
int fail(const Status& status);

// The process's peak resident set in MiB.
double peak_rss_mib();

}  // namespace calf::tools
