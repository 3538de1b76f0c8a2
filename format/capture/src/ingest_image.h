// Reading the images of foreign captures by channel name (internal to ingest): OpenEXR through
// exr_io.h, 8-bit PNG through OpenImageIO's PNG reader (its signature checked first, so that no
// other format plugin ever sees the bytes).
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "calf/format/status.h"

namespace calf::capture::detail {

// The reserved channel names of Seurat's manifests: a plane filled with 0 or 1.
inline constexpr const char* kConstantZero = "CONSTANT_ZERO";
inline constexpr const char* kConstantOne = "CONSTANT_ONE";

// How PNG samples become floats: colour channels are sRGB-decoded, others read as value / 255.
enum class PngSamples : uint8_t { kSrgbColour, kLinear };

struct NamedPlanes {
  uint32_t width = 0, height = 0;
  std::vector<std::vector<float>> planes;  // one per requested name, row-major from the top row
};

// Reads `names` from the image at `path`. `png[i]` says how a PNG's channel i is decoded (ignored
// for EXR, whose channels must be HALF or FLOAT). Errors: E135 missing file, E136 undecodable or
// unsupported image, `missing_channel` (naming the channel and listing those the image has).
Status read_named_planes(const std::filesystem::path& path, const std::vector<std::string>& names,
                         const std::vector<PngSamples>& png, ErrorId missing_channel,
                         NamedPlanes* out);

}  // namespace calf::capture::detail
