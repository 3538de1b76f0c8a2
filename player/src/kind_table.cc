// The player layer's table of track kinds; the entries are in <kind>_kind.cc.
#include "kind_table.h"

namespace calf::player {
namespace {

constexpr const PlayerKind* kKinds[] = {
    &kLightfieldPlayerKind,
    &kTilesPlayerKind,
    &kSurfelsPlayerKind,
    &kMeshPlayerKind,
};

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
