// The decoder layer's table of track kinds; the entries are in <kind>_kind.cc.
#include "calf/decoder/kind_table.h"

namespace calf::decoder {
namespace {

// In the order calf-verify's "ok" line names what it decoded.
#define CALF_DECODER_KIND_POINTER(Name, number, name, section) &k##Name##DecoderKind,
// One line per kind (clang-format would pack them).
// clang-format off
constexpr const DecoderKind* kKinds[] = {
    &kLightfieldDecoderKind,
    &kMeshDecoderKind,
    &kSurfelsDecoderKind,
    &kTilesDecoderKind,
    CALF_EXTRA_TRACK_KINDS(CALF_DECODER_KIND_POINTER)  // a build's own kinds (track_kinds.h)
};
// clang-format on
#undef CALF_DECODER_KIND_POINTER

}  // namespace

std::span<const DecoderKind* const> decoder_kinds() {
  return kKinds;
}

const DecoderKind* find_decoder_kind(uint16_t kind) {
  for (const DecoderKind* k : kKinds) {
    if (static_cast<uint16_t>(k->kind) == kind) return k;
  }
  return nullptr;
}

}  // namespace calf::decoder
