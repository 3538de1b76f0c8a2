// Fuzz target for calf-capture's --rig auto / hammersley parser (calf/samples/rig_placement.h,
// parse_placement): any text gives options or a one-line CALF-E195 error, never a crash, a
// sanitizer report or an exception; accepted options are within their documented ranges.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "calf/format/errors.h"
#include "calf/samples/rig_placement.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::string_view text(reinterpret_cast<const char*>(data), size);
  calf::Expected<calf::samples::PlacementOptions> o = calf::samples::parse_placement(text);
  if (!o.ok()) {
    if (o.status().id() != calf::ErrorId::kPlacementSyntax) std::abort();
    if (o.status().message().find('\n') != std::string::npos) std::abort();
    return 0;
  }
  if (!calf::samples::is_placement_rig(text)) std::abort();
  if (o->max_cameras < 1 || o->max_cameras > 256 || o->candidates < 1 || o->candidates > 65536 ||
      o->samples < 16 || o->frames < 1 || o->frames > 256 || !(o->k >= 0) ||
      !(o->stop >= 0 && o->stop <= 1) || !(o->theta_degrees > 0 && o->theta_degrees <= 180)) {
    std::abort();
  }
  if (o->has_volume && !(o->volume.min.x <= o->volume.max.x && o->volume.min.y <= o->volume.max.y &&
                         o->volume.min.z <= o->volume.max.z)) {
    std::abort();
  }
  return 0;
}
