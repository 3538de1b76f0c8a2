// Fuzz target for calf-capture's --rig parser (calf/samples/scene.h, parse_rig): any text must give
// a rig or a CALF-E175 error, never a crash, a sanitizer report or an exception; and a rig it
// accepts must make a valid capture manifest (parse_rig asks validate_manifest itself; this
// guards that every rig form keeps going through it), and its description must parse back to the
// same rig, position for position (the independent check: numbers printed exactly).
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "calf/capture/capture_set.h"
#include "calf/format/errors.h"
#include "calf/samples/scene.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::string_view text(reinterpret_cast<const char*>(data), size);
  calf::Expected<calf::samples::Rig> rig = calf::samples::parse_rig(text);
  if (!rig.ok()) {
    if (rig.status().id() != calf::ErrorId::kRigSyntax) std::abort();
    return 0;
  }
  calf::capture::CaptureManifest m;
  m.frame_count = 1;
  m.face_size = 4;
  m.viewpoints = rig->viewpoints;
  m.view_volume = rig->view_volume;
  if (!calf::capture::validate_manifest(m).ok()) std::abort();
  calf::Expected<calf::samples::Rig> again = calf::samples::parse_rig(rig->description);
  if (!again.ok() || again->viewpoints != rig->viewpoints ||
      !(again->view_volume == rig->view_volume) || again->description != rig->description) {
    std::abort();
  }
  return 0;
}
