// Fuzz target for the capture-set manifest and eye-path parsers (calf/capture/*.h): any bytes
// must give a value or an error, never a crash, a sanitizer report or an exception; and a parsed
// manifest or path must serialize to JSON that parses back to the same value (round trip).
// The first byte picks the parser so that one corpus covers both.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "calf/capture/capture_set.h"
#include "calf/capture/eye_path.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  std::string_view text(reinterpret_cast<const char*>(data + 1), size - 1);
  if (data[0] % 2 == 0) {
    auto m = calf::capture::parse_manifest(text, "fuzz");
    if (!m.ok()) return 0;
    if (!calf::capture::validate_manifest(*m).ok()) std::abort();
    auto again = calf::capture::parse_manifest(calf::capture::serialize_manifest(*m), "again");
    if (!again.ok() || !(*again == *m)) std::abort();
  } else {
    auto p = calf::capture::parse_eye_path(text, "fuzz");
    if (!p.ok()) return 0;
    auto again = calf::capture::parse_eye_path(calf::capture::serialize_eye_path(*p), "again");
    if (!again.ok() || !(*again == *p)) std::abort();
  }
  return 0;
}
