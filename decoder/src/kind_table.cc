// The decoder layer's table of track kinds; the entries are in <kind>_kind.cc.
#include "calf/decoder/kind_table.h"

namespace calf::decoder {
namespace {

// In the order calf-verify's "ok" line names what it decoded.
constexpr const DecoderKind* kKinds[] = {
    &kLightfieldDecoderKind,
    &kMeshDecoderKind,
    &kSurfelsDecoderKind,
    &kTilesDecoderKind,
};

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
