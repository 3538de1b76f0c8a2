// Fuzz target: the view-dependent decoder (decoder/include/calf/decoder/lightfield_decoder.h) and
// the CPU texture state its updates are applied to (cpu_textures.h), on arbitrary bytes opened as a
// .calf file from memory. Every lightfield track is played frame by frame with everything
// visible, then seeked backwards and to random frames with a viewer, so the chunk parsers, the
// per-cell / per-tile state and the P-frame window stepping all see corrupt input. Corrupt chunks
// must show up as frame statistics, never as a crash. Seeded like lightfield_decode_fuzz.
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "calf/decoder/cpu_textures.h"
#include "calf/decoder/lightfield_decoder.h"
#include "calf/format/container.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace calf;
  auto r = container::Reader::open(container::memory_source(std::span<const uint8_t>(data, size)));
  if (!r.ok()) return 0;
  constexpr uint64_t kMaxTexels = uint64_t{1} << 22;  // face texels x frames, all tracks
  uint64_t budget = kMaxTexels;
  for (uint16_t t = 0; t < r->tracks().size(); ++t) {
    decoder::LightfieldDecoderOptions o;
    o.background_thread = (size % 2) == 0;  // both paths, deterministic per input
    o.coverage = (size % 3) != 0;           // decode a coverage stream where the input has one
    o.view_dependent = false;
    auto d = decoder::LightfieldDecoder::open(*r, t, o);
    if (!d.ok()) continue;
    const auto& h = d->header();
    const uint64_t work = uint64_t{h.face_size} * h.face_size * 6 * h.view_count * h.frame_count;
    if (work == 0 || work > budget) continue;
    budget -= work;
    std::vector<decoder::LightfieldViewInfo> views;
    for (uint32_t v = 0; v < h.view_count; ++v) views.push_back(d->view(v));
    decoder::CpuTextures tex(h, views);
    decoder::LightfieldFrameUpdates fu;
    for (uint32_t n = 0; n < h.frame_count; ++n) {
      if (d->advance(n, {}, {}, &fu).ok()) (void)tex.apply(fu).ok();
    }
    // Backwards and with a viewer: culling on, seeks into earlier groups.
    auto culled = decoder::LightfieldDecoder::open(*r, t);
    if (!culled.ok()) continue;
    EyeView eye;
    eye.forward = {1, 0.2, -0.1};
    const EyeView eyes[] = {eye};
    for (uint32_t n = h.frame_count; n-- > 0;) (void)culled->advance(n, eyes, {}, &fu).ok();
    (void)culled->advance(h.frame_count, eyes, {}, &fu).ok();
  }
  return 0;
}
