// The exporters' shared writing (rules in assimp_files.h).
#include "assimp_files.h"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <string_view>

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>
#include <assimp/texture.h>
#include <assimp/Exporter.hpp>

#include "gltf_files.h"

namespace calf::exporter {
namespace {

// assimp's exporters name the side files of a blob export after "$blobfile" (OBJ's
// "mtllib $blobfile.mtl", glTF's buffer uri "$blobfile.bin"); the files are written as
// `<stem>.mtl` / `<stem>.bin`, so the main file's references say so.
void rename_side_files(std::vector<uint8_t>* bytes, const std::string& stem) {
  static constexpr std::string_view kBlobName = "$blobfile";
  std::string text(bytes->begin(), bytes->end());
  for (size_t at = text.find(kBlobName); at != std::string::npos;
       at = text.find(kBlobName, at + stem.size())) {
    text.replace(at, kBlobName.size(), stem);
  }
  bytes->assign(text.begin(), text.end());
}

}  // namespace

Expected<std::vector<uint8_t>> png_bytes(const uint8_t* rgba, uint32_t width, uint32_t height,
                                         const std::string& what) {
  std::vector<unsigned char> bytes;
  OIIO::Filesystem::IOVecOutput proxy(bytes);
  auto out = OIIO::ImageOutput::create("texture.png");
  OIIO::ImageSpec spec(static_cast<int>(width), static_cast<int>(height), 4, OIIO::TypeDesc::UINT8);
  spec.attribute("oiio:UnassociatedAlpha", 1);
  spec.attribute("oiio:ColorSpace", "sRGB");
  if (!out || !out->set_ioproxy(&proxy) || !out->open("texture.png", spec) ||
      !out->write_image(OIIO::TypeDesc::UINT8, rgba) || !out->close()) {
    return Status(ErrorId::kExportWrite,
                  what + ": PNG encoding failed" + (out ? ": " + out->geterror() : std::string()));
  }
  return std::vector<uint8_t>(bytes.begin(), bytes.end());
}

std::string embed_png(aiScene* scene, const std::vector<uint8_t>& png) {
  auto* tex = new aiTexture();
  tex->mWidth = static_cast<unsigned>(png.size());  // mHeight 0: compressed, mWidth bytes
  tex->mHeight = 0;
  std::snprintf(tex->achFormatHint, sizeof tex->achFormatHint, "png");
  tex->pcData = reinterpret_cast<aiTexel*>(new uint8_t[png.size()]);
  std::copy(png.begin(), png.end(), reinterpret_cast<uint8_t*>(tex->pcData));
  auto** textures = new aiTexture*[scene->mNumTextures + 1];
  std::copy(scene->mTextures, scene->mTextures + scene->mNumTextures, textures);
  textures[scene->mNumTextures] = tex;
  delete[] scene->mTextures;
  scene->mTextures = textures;
  // (Appended rather than "*" + to_string: GCC 12 warns about that temporary, -Wrestrict.)
  std::string path = "*";
  path += std::to_string(scene->mNumTextures++);
  return path;
}

Expected<std::vector<ExportedFile>> write_scene(const aiScene& scene, MeshExportFormat format,
                                                const std::string& stem, const GltfOptions& gltf) {
  if (format != MeshExportFormat::kObj) return write_gltf(scene, format, stem, gltf);
  if (gltf.meshopt) {
    return Status(ErrorId::kExportInput, "meshopt compression applies to .glb / .gltf");
  }
  Assimp::Exporter exporter;
  const aiExportDataBlob* blob = exporter.ExportToBlob(&scene, "obj", 0);
  if (blob == nullptr) {
    return Status(ErrorId::kExportWrite,
                  std::string("assimp's exporter failed: ") + exporter.GetErrorString());
  }
  std::vector<ExportedFile> files;
  for (const aiExportDataBlob* b = blob; b != nullptr; b = b->next) {
    ExportedFile file;
    if (b != blob) {  // appends, not operator+: GCC 12 -O3 misfires -Wrestrict on it
      file.suffix = ".";
      file.suffix += b->name.C_Str();
    }
    const auto* data = static_cast<const uint8_t*>(b->data);
    file.bytes.assign(data, data + b->size);
    files.push_back(std::move(file));
  }
  if (files.size() > 1) rename_side_files(&files[0].bytes, stem);
  return files;
}

Status check_stem(const std::string& stem, MeshExportFormat format) {
  if (format == MeshExportFormat::kGlb) return Status::Ok();
  const bool plain = !stem.empty() && std::all_of(stem.begin(), stem.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.';
  });
  if (plain) return Status::Ok();
  return Status(ErrorId::kExportInput,
                "output name '" + stem +
                    "': a .gltf or .obj names its side file after it, so it may hold only "
                    "A-Z a-z 0-9 _ - .");
}

}  // namespace calf::exporter
