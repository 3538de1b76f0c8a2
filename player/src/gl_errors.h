// Private to the player: the error ids of the GL renderer, named once so that its sources agree.
#pragma once

#include "calf/format/errors.h"

namespace calf::player::internal {

// No context, a GL version / extension / entry point missing, a shader that does not compile.
inline constexpr ErrorId kGlMissing = ErrorId::kPlayerGl;
// A texture layout the GL state cannot hold (CALF-E410).
inline constexpr ErrorId kGlLayout = ErrorId::kPlayerGlLayout;
// A texture update that does not fit the GL texture state (CALF-E411).
inline constexpr ErrorId kGlUpdate = ErrorId::kPlayerGlUpdate;
// A GL call reported an error (CALF-E412).
inline constexpr ErrorId kGlCall = ErrorId::kPlayerGlCall;

}  // namespace calf::player::internal
