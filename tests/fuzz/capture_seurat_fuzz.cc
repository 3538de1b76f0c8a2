// Fuzz target for the Seurat manifest parser (calf/capture/ingest.h): any bytes must give a value
// or an error, never a crash, a sanitizer report or an exception; and what it accepts must hold
// what the converter relies on (perspective projections with 0 < near < far, affine poses,
// relative image paths, 4 colour channels and 1 depth channel per view).
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "calf/capture/ingest.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::string_view text(reinterpret_cast<const char*>(data), size);
  auto c = calf::capture::parse_seurat_manifest(text, "fuzz");
  if (!c.ok()) return 0;
  if (c->view_groups.empty()) std::abort();
  for (const auto& group : c->view_groups) {
    if (group.empty()) std::abort();
    for (const auto& v : group) {
      if (v.color.channels.size() != 4 || v.depth.channels.size() != 1) std::abort();
      if (v.color.path.empty() || v.color.path[0] == '/') std::abort();
      if (v.image_width == 0 || v.image_height == 0) std::abort();
      if (!(v.clip_from_eye[14] < 0) || v.world_from_eye[15] == 0) std::abort();
    }
  }
  return 0;
}
