// Fuzz target: the reference lightfield decoder
// (decoder/include/calf/decoder/lightfield_reference.h) on arbitrary bytes. Opens them as a .calf
// file from memory, opens every lightfield track and decodes every view / face / frame it claims,
// plus every cell timeline and depth region's rectangle counts. Any crash, sanitizer report or hang
// is a bug; errors are expected. Seeded with tiny valid encoded files (face 8, 2-3 frames) and
// files whose chunks were rewritten with corrupt contents but valid hashes (so mutations reach the
// decoder's chunk parser, not just the container's checks).
#include <cstddef>
#include <cstdint>
#include <span>

#include "calf/decoder/lightfield_reference.h"
#include "calf/format/container.h"
#include "calf/format/grid.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace calf;
  auto r = container::Reader::open(container::memory_source(std::span<const uint8_t>(data, size)));
  if (!r.ok()) return 0;
  // A header may legally claim 16384^2 faces and thousands of frames; decoding that would only
  // measure allocation. Cap the work per input (the decoder's own checks are what is under test).
  constexpr uint64_t kMaxTexels = uint64_t{1} << 22;  // decoded face texels per input, all tracks
  uint64_t budget = kMaxTexels;
  for (uint16_t t = 0; t < r->tracks().size(); ++t) {
    auto d = decoder::LightfieldReference::open(*r, t);
    if (!d.ok()) continue;
    const auto& h = d->header();
    const uint64_t face_texels = uint64_t{h.face_size} * h.face_size;
    const uint64_t faces = uint64_t{h.view_count} * 6 * h.frame_count;
    if (face_texels == 0 || face_texels > budget || faces > budget / face_texels) continue;
    budget -= faces * face_texels;
    auto cells = FaceGrid::with_cell_size(h.face_size, h.cell_size);
    auto tiles = FaceGrid::with_cell_size(h.face_size, h.depth_region_size);
    decoder::LightfieldFace out;
    for (uint32_t v = 0; v < h.view_count; ++v) {
      for (uint32_t f = 0; f < 6; ++f) {
        if (cells.ok()) {
          for (uint32_t c = 0; c < cells->cell_count() && c < 4096; ++c) {
            (void)d->cell_timeline(v, f, c).ok();
          }
        }
        if (tiles.ok()) {
          for (uint32_t c = 0; c < tiles->cell_count() && c < 4096; ++c) {
            (void)d->depth_rect_counts(v, f, c).ok();
          }
        }
        for (uint32_t n = 0; n < h.frame_count; ++n) (void)d->decode_face(v, f, n, &out).ok();
      }
    }
    // Out of range requests are errors, not crashes.
    (void)d->decode_face(h.view_count, 0, 0, &out).ok();
    (void)d->decode_face(0, 6, 0, &out).ok();
    (void)d->decode_face(0, 0, h.frame_count, &out).ok();
  }
  return 0;
}
