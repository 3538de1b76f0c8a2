// Fuzz target for scene models through the sample scene loader (calf/samples/scene.h,
// load_scene_file): the calf-side checks before assimp (the PLY header and glTF JSON pre-scans)
// and after it (every vertex, transform and key finite and within the coordinate bound). Any
// bytes must give a scene or one of the loader's errors, never a crash, a sanitizer report, an
// exception or an allocation far beyond the input's size; an accepted scene must validate and
// hold only vertices within the bound. Textures: a glTF image URI names a file that is not
// there (E190) or an embedded image does not decode (E191).
// Input: the first byte picks the extension (.obj, .ply, .gltf, .glb), the rest is the file,
// written to a temporary folder of its own.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <system_error>

#include "../scratch_dir.h"
#include "calf/format/coordinates.h"
#include "calf/samples/scene.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  static const char* const kExtensions[] = {".obj", ".ply", ".gltf", ".glb"};
  const std::filesystem::path& dir = calf::test::scratch_dir("calf_assimp_fuzz");
  const std::filesystem::path file = dir / (std::string("model") + kExtensions[data[0] % 4]);
  {
    std::ofstream out(file, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data + 1), static_cast<std::streamsize>(size - 1));
  }
  calf::Expected<calf::samples::Scene> scene = calf::samples::load_scene_file(file);
  std::error_code ignored;
  std::filesystem::remove(file, ignored);
  if (!scene.ok()) {
    switch (scene.status().id()) {
      case calf::ErrorId::kSceneLoad:
      case calf::ErrorId::kSceneEmpty:
      case calf::ErrorId::kSceneGeometry:
      case calf::ErrorId::kFileOpen:
      case calf::ErrorId::kFileRead:
      case calf::ErrorId::kModelTextureMissing:  // an image URI naming no file
      case calf::ErrorId::kModelTexture:         // an embedded image that does not decode
        return 0;
      default:
        std::abort();
    }
  }
  if (!calf::samples::validate_scene(*scene).ok()) std::abort();
  for (const calf::samples::Object& o : scene->objects) {
    for (const auto& p : o.mesh.positions) {
      if (!calf::coordinates_ok({p.x, p.y, p.z})) std::abort();
    }
  }
  return 0;
}
