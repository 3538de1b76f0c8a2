// Private to the scene-file code (format/SCENE.md): what its validation (scene_file_validate.cc),
// decoder (scene_file_decode.cc), writer (scene_file_write.cc) and texture images
// (scene_texture_io.cc) share.
#pragma once

#include <bit>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

#include "calf/capture/scene_file.h"
#include "calf/format/status.h"

namespace calf::capture::scene_internal {

// Buffers are little-endian and are copied byte for byte into and out of the arrays.
static_assert(std::endian::native == std::endian::little,
              "scene buffers assume a little-endian host");

inline constexpr uint64_t kMaxByteLength = uint64_t{1} << 50;
inline constexpr uint64_t kMaxViewCount = uint64_t{1} << 40;
inline constexpr size_t kMaxNameLength = 1000;

// A number as printf's %g writes it, for messages.
std::string num(double v);

// A relative path confined to the scene folder: '/'-separated components of A-Z a-z 0-9 _ - .,
// none empty, "." or "..", none starting with '.', not "scene.json". Returns "" when valid.
std::string path_problem(std::string_view path);

// Validates the whole scene; `size_id` is the id of a size error (the decoder's and the writer's
// differ).
Status validate_impl(const SceneFile& s, ErrorId size_id);

// Writes texture `t` (RGBA pixels) as a PNG file.
Status write_png(const std::filesystem::path& path, const SceneTexture& t);

}  // namespace calf::capture::scene_internal
