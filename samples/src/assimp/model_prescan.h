// Cheap checks of a model file before assimp reads it (internal to calf_samples).
//
// assimp trusts what a file declares: a 79-byte PLY declaring 99,999,999 vertices makes it
// allocate gigabytes before it finds the data missing, and a glTF buffer URI
// "../../../../etc/passwd" is read as geometry. These scans read only the PLY header or the glTF
// JSON, compare every declared count and length with the bytes that exist, and refuse URIs that
// leave the model's folder, so that such files fail in milliseconds with bounded memory.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

#include "calf/format/status.h"

namespace calf::samples::detail {

// Scans `path` by its extension (lower case, with the dot: ".ply", ".gltf", ".glb"); other
// extensions pass. E171 (kSceneLoad, the file cannot be imported) for a declared count or length
// beyond the bytes that hold it, a buffer / image / shader URI outside the folder, or a header
// too malformed to scan (assimp would refuse it too); the message names the element or field.
Status prescan_model_file(const std::filesystem::path& path, std::string_view extension);

// The same checks on bytes already in memory (`folder` resolves external glTF buffers;
// `glb_bin_bytes` is the size of a GLB's binary chunk when `has_glb_bin`).
// `head` is the start of the file (at least its header, up to 1 MiB), `file_size` its size.
Status prescan_ply(std::string_view head, uint64_t file_size, std::string_view name);
Status prescan_gltf_json(std::string_view json, std::string_view name,
                         const std::filesystem::path& folder, uint64_t glb_bin_bytes,
                         bool has_glb_bin);
Status prescan_glb(std::string_view bytes, std::string_view name,
                   const std::filesystem::path& folder);

// Decodes %XX escapes (assimp and the glTF spec treat URIs as percent-encoded, e.g. "my%20tex.png"
// names "my tex.png"); a malformed escape is kept as it is.
std::string percent_decode(std::string_view s);

}  // namespace calf::samples::detail
