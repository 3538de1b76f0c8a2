// Reading the images of foreign captures by channel name (internal to ingest): OpenEXR through
// exr_io.h, 8-bit PNG through image_input.h (its signature checked first, so that no other
// reader ever sees the bytes).
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "calf/format/status.h"
#include "image_input.h"

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
// for EXR, whose channels must be HALF or FLOAT). The header is checked against `expect` (size,
// budget) before any pixel is decoded; EXR rows are read in strips, so that memory is the planes
// asked for plus one strip. Errors: E135 missing file, E136 undecodable or unsupported image,
// `expect.wrong_size`, E012 over the budget, `missing_channel` (naming the channel and listing
// those the image has).
Status read_named_planes(const std::filesystem::path& path, const std::vector<std::string>& names,
                         const std::vector<PngSamples>& png, ErrorId missing_channel,
                         const ImageExpect& expect, NamedPlanes* out);

}  // namespace calf::capture::detail
