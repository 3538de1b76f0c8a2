// The clip metadata the calf tools write and read (format/SPEC.md §5, "The calf tools write and
// read these keys"): each typed value is formatted and parsed here, once, so that the encoder's
// writers and the player agree on it.
//
//   writer.set_metadata(std::string(kViewVolumeKey), format_view_volume(box));
//   std::optional<Box3> box = parse_view_volume(reader.find_metadata(kViewVolumeKey));
#pragma once

#include <optional>
#include <string>
#include <string_view>

#include "calf/format/geometry.h"

namespace calf::container {

// The box, in scene units, the viewer may move in.
inline constexpr std::string_view kViewVolumeKey = "view_volume";

// "min_x min_y min_z max_x max_y max_z", each with %.17g (reads back as the same double).
std::string format_view_volume(const Box3& box);

// The box of a view_volume value: six numbers, each finite, min <= max on each axis; std::nullopt
// for a missing value (nullptr) or any other text (the value is advice, never an error).
std::optional<Box3> parse_view_volume(const std::string* text);

}  // namespace calf::container
