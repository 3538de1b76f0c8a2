// Fuzz target for the scene-file decoder (calf/capture/scene_file.h): any bytes must give a scene
// or an error, never a crash, a sanitizer report, an exception or an allocation beyond the input's
// size; and a decoded scene must encode and decode back to the same scene (round trip).
// Input: the manifest's JSON text, a NUL byte, then the bytes of the one buffer (no NUL: no
// buffer), so that mutations reach both the manifest and the buffer.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <string_view>

#include "calf/capture/scene_file.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const char* text = reinterpret_cast<const char*>(data);
  const void* nul = std::memchr(data, 0, size);
  const size_t json_size =
      nul ? static_cast<size_t>(static_cast<const uint8_t*>(nul) - data) : size;
  std::string_view manifest(text, json_size);
  std::string_view buffers[1];
  size_t buffer_count = 0;
  if (nul) buffers[buffer_count++] = std::string_view(text + json_size + 1, size - json_size - 1);
  auto scene = calf::capture::parse_scene_file(
      manifest, std::span<const std::string_view>(buffers, buffer_count), "fuzz");
  if (!scene.ok()) return 0;
  if (!calf::capture::validate_scene_file(*scene).ok()) std::abort();
  auto encoded = calf::capture::encode_scene_file(*scene);
  if (!encoded.ok()) std::abort();
  std::string_view again_buffers[1] = {encoded->buffer};
  auto again = calf::capture::parse_scene_file(encoded->manifest, again_buffers, "again");
  if (!again.ok() || !(*again == *scene)) std::abort();
  return 0;
}
