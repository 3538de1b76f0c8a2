// Base-colour textures of a model imported by assimp (internal to calf_samples): which texture
// each material names, where its pixels are (a file beside the model or an image embedded in it),
// decoding, and sharing one decoded texture among the materials that name it.
#pragma once

#include <filesystem>
#include <vector>

#include "calf/format/status.h"
#include "calf/samples/scene.h"

struct aiScene;

namespace calf::samples::detail {

// Loads the base-colour texture of every material of `ai` into scene->textures (one entry per
// distinct file or embedded image, in order of first use) and sets
// scene->materials[i].base_color_texture; scene->materials must hold one material per aiMaterial.
// `model` is the model file: external paths resolve against its folder. A material's texture is
// aiTextureType_BASE_COLOR's first, else aiTextureType_DIFFUSE's first. With `replaces_colour`
// (FBX) a textured material's albedo becomes 1: the texture replaces the colour rather than
// multiplying it. E190 for a file found nowhere, E191 for an image that cannot be decoded, is too
// large or is an embedded index the model does not hold; both name the texture and the material.
// E012 for an image with more pixels than `max_image_pixels`, found from its header (an embedded
// one's too) before it is decoded (calf/capture/image_budget.h).
Status load_model_textures(const aiScene& ai, const std::filesystem::path& model,
                           bool replaces_colour, uint64_t max_image_pixels, Scene* scene);

}  // namespace calf::samples::detail
