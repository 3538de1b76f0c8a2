// The player layer's table of track kinds; the entries are in <kind>_kind.cc.
#include "kind_table.h"

namespace calf::player {
namespace {

#define CALF_PLAYER_KIND_POINTER(Name, number, name, section) &k##Name##PlayerKind,
// One line per kind (clang-format would pack them).
// clang-format off
constexpr const PlayerKind* kKinds[] = {
    &kLightfieldPlayerKind,
    &kTilesPlayerKind,
    &kSurfelsPlayerKind,
    &kMeshPlayerKind,
    CALF_EXTRA_TRACK_KINDS(CALF_PLAYER_KIND_POINTER)  // a build's own kinds (track_kinds.h)
};
// clang-format on
#undef CALF_PLAYER_KIND_POINTER

}  // namespace

std::span<const PlayerKind* const> player_kinds() {
  return kKinds;
}

const PlayerKind* find_player_kind(uint16_t kind) {
  for (const PlayerKind* k : kKinds) {
    if (static_cast<uint16_t>(k->kind) == kind) return k;
  }
  return nullptr;
}

}  // namespace calf::player
