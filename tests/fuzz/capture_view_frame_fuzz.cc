// Fuzz target for view-frame images through the capture-set reader (calf/capture/capture_set.h,
// CaptureSetReader::read): any bytes as the one image of a one-view, one-frame set must give a
// view-frame or one of the image errors (E135 - E139), never a crash, a sanitizer report, an
// exception or a stray allocation; an accepted view-frame passes validate_view_frame.
// Input: the first byte picks the set (bits 0-1: face size 1 + value, bit 2: material), the rest
// is the OpenEXR file.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <system_error>

#include "../scratch_dir.h"
#include "calf/capture/capture_set.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  const std::filesystem::path& dir = calf::test::scratch_dir("calf_view_frame_fuzz");
  calf::capture::CaptureManifest m;
  m.frame_count = 1;
  m.face_size = 1 + (data[0] & 3);
  m.material = (data[0] & 4) != 0;
  m.view_volume = {{0, 0, 0}, {0, 0, 0}};
  m.viewpoints = {{"view0", {0, 0, 0}}};
  {
    std::ofstream out(dir / calf::capture::kManifestFileName, std::ios::binary | std::ios::trunc);
    out << calf::capture::serialize_manifest(m);
    std::ofstream image(dir / calf::capture::capture_file_name(m, 0, 0),
                        std::ios::binary | std::ios::trunc);
    image.write(reinterpret_cast<const char*>(data + 1), static_cast<std::streamsize>(size - 1));
  }
  calf::Expected<calf::capture::CaptureSetReader> reader =
      calf::capture::CaptureSetReader::open(dir);
  if (!reader.ok()) std::abort();
  calf::capture::ViewFrame frame;
  calf::Status st = reader->read(0, 0, &frame);
  if (!st.ok()) {
    switch (st.id()) {
      case calf::ErrorId::kCaptureFileMissing:
      case calf::ErrorId::kCaptureImageFormat:
      case calf::ErrorId::kCaptureDepthPixel:
      case calf::ErrorId::kCaptureColourPixel:
      case calf::ErrorId::kCaptureMaterialPixel:
        return 0;
      default:
        std::abort();
    }
  }
  if (!calf::capture::validate_view_frame(frame, "fuzz").ok()) std::abort();
  if (frame.face_size != m.face_size || frame.has_material != m.material) std::abort();
  return 0;
}
