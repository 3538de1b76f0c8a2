// Fuzz target for the image readers where images enter calf (calf/capture/image_budget.h): PNG
// and OpenEXR headers and data through the texture readers (in memory and from a file) and
// through calf-ingest's Seurat reader with its manifest. The first byte picks the path:
//   0  decode_texture_image on the rest (PNG by libpng, other formats by OpenImageIO)
//   1  the rest as a file, read_texture_image
//   2  the rest as the one image of a Seurat manifest of 16 x 16 cameras (colour and depth)
//   3  the rest split at the first NUL: a Seurat manifest, then the image it may name as "img"
// Any bytes must give a value or an error (never a crash, a sanitizer report, an exception or
// output on stderr), and what is accepted must hold the budget: a small one here, so that a
// header alone never makes the fuzzer allocate more than a few MB.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <span>
#include <string>

#include "../capture/hostile_images.h"
#include "../scratch_dir.h"
#include "calf/capture/ingest.h"
#include "calf/capture/scene_file.h"

namespace {

constexpr uint64_t kBudget = uint64_t{1} << 20;

void write(const std::filesystem::path& p, const uint8_t* data, size_t size) {
  std::ofstream(p, std::ios::binary | std::ios::trunc)
      .write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
}

void check_texture(const calf::Status& s, const calf::capture::SceneTexture& t) {
  if (!s.ok()) return;
  const uint64_t pixels = uint64_t{t.width} * t.height;
  if (pixels == 0 || pixels > kBudget || t.rgba.size() != pixels * 4) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  const uint8_t mode = data[0] % 4;
  ++data;
  --size;
  const std::filesystem::path& dir = calf::test::scratch_dir("capture_image_fuzz");
  calf::capture::SceneTexture t;
  if (mode == 0) {
    check_texture(calf::capture::decode_texture_image({data, size}, "exr", "fuzz", &t, kBudget), t);
    return 0;
  }
  if (mode == 1) {
    write(dir / "in.img", data, size);
    check_texture(calf::capture::read_texture_image(dir / "in.img", &t, kBudget), t);
    return 0;
  }
  std::string manifest;
  const uint8_t* image = data;
  size_t image_size = size;
  if (mode == 2) {
    manifest = calf::test::seurat_manifest(16, "img", "img");
  } else {
    size_t nul = 0;
    while (nul < size && data[nul] != 0) ++nul;
    manifest.assign(reinterpret_cast<const char*>(data), nul);
    image = data + std::min(size, nul + 1);
    image_size = size - std::min(size, nul + 1);
  }
  std::filesystem::remove_all(dir / "out");
  std::ofstream(dir / "manifest.json", std::ios::trunc) << manifest;
  write(dir / "img", image, image_size);
  calf::capture::IngestOptions options;
  options.max_image_pixels = kBudget;
  options.face_size = 4;  // small faces: the readers, not the resampling, are under test
  const calf::Status s = calf::capture::ingest_seurat(dir / "manifest.json", dir / "out", options);
  if (s.ok() && !std::filesystem::exists(dir / "out" / "manifest.json")) std::abort();
  return 0;
}
