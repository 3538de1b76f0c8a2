// Base-colour textures of assimp-imported models: lookup, resolution, decoding, sharing.
#include "model_textures.h"

#include <cstring>
#include <map>
#include <span>
#include <string>
#include <system_error>
#include <utility>

#include <assimp/material.h>
#include <assimp/scene.h>
#include <assimp/texture.h>

#include "calf/capture/image_budget.h"
#include "calf/capture/scene_file.h"
#include "model_prescan.h"

namespace calf::samples::detail {

namespace {

// The texture a material names for its base colour: glTF's baseColorTexture (assimp files it as
// BASE_COLOR and DIFFUSE), OBJ's map_Kd and FBX's DiffuseColor (DIFFUSE). Empty when none.
std::string base_colour_path(const aiMaterial& m) {
  for (aiTextureType type : {aiTextureType_BASE_COLOR, aiTextureType_DIFFUSE}) {
    aiString path;
    if (m.GetTextureCount(type) > 0 && m.GetTexture(type, 0, &path) == AI_SUCCESS &&
        path.length > 0) {
      return path.C_Str();
    }
  }
  return {};
}

bool is_file(const std::filesystem::path& p) {
  std::error_code ec;
  return std::filesystem::is_regular_file(p, ec);
}

// Where the file a model names lies: the path relative to the model's folder (as written, then
// percent-decoded), else the file's name alone in that folder (FBX and OBJ files often carry the
// author's absolute or Windows paths). Backslashes are separators. Empty when none exists.
std::filesystem::path resolve(const std::filesystem::path& folder, std::string named) {
  if (named.rfind("file://", 0) == 0) named.erase(0, 7);
  for (char& c : named) c = c == '\\' ? '/' : c;
  for (const std::string& candidate : {named, percent_decode(named)}) {
    const std::filesystem::path p = folder / std::filesystem::path(candidate);
    if (is_file(p)) return p;
  }
  const std::filesystem::path alone = folder / std::filesystem::path(named).filename();
  if (std::filesystem::path(named).has_filename() && is_file(alone)) return alone;
  return {};
}

// An embedded image: compressed bytes (mHeight 0: mWidth bytes in a format such as PNG or JPEG)
// or raw BGRA texels (mWidth x mHeight, row 0 at the top).
Status decode_embedded(const aiTexture& t, const std::string& name, uint64_t max_image_pixels,
                       capture::SceneTexture* out) {
  if (!t.pcData || t.mWidth == 0) {
    return Status(ErrorId::kModelTexture, name + ": the embedded image holds no data");
  }
  if (t.mHeight == 0) {
    const std::span<const uint8_t> bytes(reinterpret_cast<const uint8_t*>(t.pcData), t.mWidth);
    // achFormatHint is a NUL-terminated extension of at most 8 characters.
    std::string hint(t.achFormatHint, strnlen(t.achFormatHint, sizeof t.achFormatHint));
    return capture::decode_texture_image(bytes, hint, name, out, max_image_pixels);
  }
  if (t.mWidth > capture::kSceneMaxTextureSize || t.mHeight > capture::kSceneMaxTextureSize) {
    return Status(ErrorId::kModelTexture, name + ": " + std::to_string(t.mWidth) + " x " +
                                              std::to_string(t.mHeight) +
                                              " is larger than 16384 x 16384");
  }
  CALF_RETURN_IF_ERROR(capture::check_image_budget(name, t.mWidth, t.mHeight, max_image_pixels));
  out->width = t.mWidth;
  out->height = t.mHeight;
  out->rgba.resize(size_t{t.mWidth} * t.mHeight * 4);
  for (size_t i = 0; i < size_t{t.mWidth} * t.mHeight; ++i) {
    const aiTexel& p = t.pcData[i];
    out->rgba[4 * i] = p.r, out->rgba[4 * i + 1] = p.g, out->rgba[4 * i + 2] = p.b;
    out->rgba[4 * i + 3] = p.a;
  }
  return Status::Ok();
}

}  // namespace

Status load_model_textures(const aiScene& ai, const std::filesystem::path& model,
                           bool replaces_colour, uint64_t max_image_pixels, Scene* scene) {
  const std::filesystem::path folder = model.parent_path();
  // One decoded texture per file or embedded image, however many materials name it.
  std::map<std::string, uint32_t> index_of;
  for (unsigned i = 0; i < ai.mNumMaterials && i < scene->materials.size(); ++i) {
    if (!ai.mMaterials[i]) continue;
    const aiMaterial& m = *ai.mMaterials[i];
    const std::string named = base_colour_path(m);
    if (named.empty()) continue;
    const std::string where = model.string() + ": material " + std::to_string(i) + " '" +
                              m.GetName().C_Str() + "' base-colour texture '" + named + "'";
    const auto [embedded, embedded_index] = ai.GetEmbeddedTextureAndIndex(named.c_str());
    std::string key;
    std::filesystem::path file;
    if (embedded) {
      // Appends, not operator+ on a temporary: GCC 12 -O3 misfires -Wrestrict on that.
      key = "*";
      key.append(std::to_string(embedded_index));
    } else if (named[0] == '*') {
      return Status(ErrorId::kModelTexture,
                    where + ": the model embeds " + std::to_string(ai.mNumTextures) + " images");
    } else {
      file = resolve(folder, named);
      if (file.empty()) {
        return Status(ErrorId::kModelTextureMissing,
                      where + ": no such file (looked for " + (folder / named).string() +
                          " and its name alone in " + folder.string() + ")");
      }
      key = file.lexically_normal().string();
    }
    auto found = index_of.find(key);
    if (found == index_of.end()) {
      capture::SceneTexture image;
      Status s = embedded ? decode_embedded(*embedded, where, max_image_pixels, &image)
                          : capture::read_texture_image(file, &image, max_image_pixels);
      if (s.id() == ErrorId::kImageBudget) {
        return Status(s.id(), (embedded ? "" : where + ": ") + s.message());
      }
      if (!s.ok()) {
        return Status(ErrorId::kModelTexture, (embedded ? "" : where + ": ") + s.message());
      }
      // The scene-file name the export gives it (SCENE.md: a relative path ending in .png).
      image.path = "textures/texture" + std::to_string(scene->textures.size()) + ".png";
      found = index_of.emplace(key, static_cast<uint32_t>(scene->textures.size())).first;
      scene->textures.push_back(make_texture(std::move(image)));
    }
    Material& mat = scene->materials[i];
    mat.base_color_texture = found->second;
    if (replaces_colour) mat.albedo = glm::vec3(1);
  }
  return Status::Ok();
}

}  // namespace calf::samples::detail
