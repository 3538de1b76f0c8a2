// The page decoder's hot path as WebAssembly, for web/tools/wasm_bench.mjs only (not shipped):
// calf's own C++ decoding of a colour keyframe payload and of a depth region chunk, the work
// lightfield.js's decodeColour and parseRegion + applyRegionFrame do after decompression. Built
// with Debian's emcc (see wasm_bench.mjs); no OS calls. Each function returns 0, or the CALF error
// number of the Status the C++ code gave.
#include <cstdint>
#include <cstring>
#include <span>
#include <string>
#include <vector>

#include "calf/decoder/cpu_textures.h"
#include "calf/format/container_types.h"
#include "calf/format/lightfield_layout.h"

namespace {

int code(const calf::Status& s) {
  return s.ok() ? 0 : static_cast<int>(s.id());
}

}  // namespace

extern "C" {

// A w x h colour keyframe payload (§11.1.5) of `format` -> 3 w h linear floats in `rgb`.
int calf_wasm_colour(uint32_t format, const uint8_t* raw, uint32_t size, uint32_t w, uint32_t h,
                     float* rgb) {
  static std::vector<uint8_t> gpu;
  const std::string what = "colour";
  if (auto s = calf::lf::colour_payload_gpu_bytes(static_cast<uint16_t>(format), {raw, size}, w, h,
                                                  gpu, what);
      !s.ok()) {
    return code(s);
  }
  const auto gpu_format = static_cast<calf::container::PixelFormat>(format);
  return code(calf::decoder::decode_gpu_colour(gpu_format, gpu, w, h, {rgb, size_t{w} * h * 3}));
}

// Every frame of a depth region chunk (§11.1.6 – §11.1.9) of `frames` frames, applied in order to
// the tw x th tile state `codes` (log-16 codes, row-major), as the native decoder applies them.
int calf_wasm_depth(uint32_t depth_format, const uint8_t* raw, uint32_t size, uint32_t frames,
                    uint32_t tw, uint32_t th, uint16_t* codes) {
  auto coding = calf::lf::depth_coding(static_cast<uint16_t>(depth_format));
  if (!coding.ok()) return code(coding.status());
  auto chunk = calf::lf::parse_region_chunk({raw, size}, frames, tw, th, *coding, "depth");
  if (!chunk.ok()) return code(chunk.status());
  const calf::container::PixelFormat format = calf::lf::region_gpu_format(*coding);
  static std::vector<uint8_t> gpu;
  static std::vector<uint16_t> decoded;
  for (size_t k = 0; k < chunk->rects.size(); ++k) {
    const calf::lf::RegionRect& r = chunk->rects[k];
    if (calf::lf::region_rect_reads_state(*chunk, k)) {
      gpu.resize(size_t{r.w} * r.h * 2);
      for (uint32_t y = 0; y < r.h; ++y) {
        std::memcpy(gpu.data() + size_t{y} * r.w * 2, codes + size_t{r.y + y} * tw + r.x,
                    size_t{r.w} * 2);
      }
    }
    calf::lf::region_rect_gpu_bytes(*chunk, k, gpu);
    decoded.resize(size_t{r.w} * r.h);
    if (auto s = calf::decoder::decode_gpu_depth(format, gpu, r.w, r.h, decoded); !s.ok()) {
      return code(s);
    }
    for (uint32_t y = 0; y < r.h; ++y) {
      std::memcpy(codes + size_t{r.y + y} * tw + r.x, decoded.data() + size_t{y} * r.w,
                  size_t{r.w} * 2);
    }
  }
  return 0;
}

}  // extern "C"
