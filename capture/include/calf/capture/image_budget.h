// The budget of decoded images: the most pixels one decoded image, or the six cube faces of one
// viewpoint a command builds, may hold. Every image calf reads (capture-set and ingest images,
// scene-file textures, model textures) is measured against it from its header, before a pixel
// is decoded or a buffer is allocated, so that a small file that declares a huge image costs
// nothing; commands that load images take it as `--max-image-pixels` (docs/ERRORS.md, E012).
//
// Memory per budgeted pixel, by reader: an 8-bit texture 4 bytes (plus the original channels
// while it decodes); a Seurat or equirectangular image 4 bytes per channel read; one ingest
// viewpoint's faces 16 bytes (colour and depth as float); calf-capture's ray tracer keeps a
// texture as float RGB with its mip chain, about 16 bytes per texel. The default, 2^26 pixels
// (8192 x 8192), therefore bounds one image at 256 MB to 1 GB; a 16384 x 16384 texture (SCENE.md's
// largest) needs `--max-image-pixels 268435456`.
#pragma once

#include <cstdint>
#include <string_view>

#include "calf/format/status.h"

namespace calf::capture {

// The default budget: 8192 x 8192 pixels.
inline constexpr uint64_t kDefaultMaxImagePixels = uint64_t{1} << 26;
// The largest budget an option accepts (2^32 pixels: 64 GB of float RGBA).
inline constexpr uint64_t kMaxImagePixelsLimit = uint64_t{1} << 32;

// The help text of a command's --max-image-pixels option (CLI::Range(1, kMaxImagePixelsLimit)).
inline constexpr const char* kMaxImagePixelsHelp =
    "the image budget: the most pixels (width x height) of one decoded image, or of one "
    "viewpoint's six faces (6 x face size^2), checked from each image's header before it is "
    "decoded (CALF-E012 when exceeded); default 67108864 (8192 x 8192), at most 4294967296";
static_assert(kDefaultMaxImagePixels == 67108864 && kMaxImagePixelsLimit == 4294967296);

// Ok when `count` images of `width` x `height` pixels fit in `max_pixels`; else E012 naming
// `what`, the pixels it needs and the option that raises the budget.
Status check_image_budget(std::string_view what, uint64_t width, uint64_t height,
                          uint64_t max_pixels, uint64_t count = 1);

}  // namespace calf::capture
