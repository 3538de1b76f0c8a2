// Capture shards (docs/FARM.md): a capture set rendered as pieces — any subset of views x a frame
// range each — into one directory (a farm's shared file system), then joined into a complete set.
//
// A shard writes its images and a marker DIR/capture-shard.v<views>.f<first>-<last>.json holding
// the manifest of the whole set; it never writes manifest.json, so a set is never complete before
// the join. join_capture_shards() checks that every marker holds the same manifest and that every
// image the manifest names is there, writes manifest.json (whole) and removes the markers.
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "calf/capture/capture_set.h"
#include "calf/format/status.h"

namespace calf::capture {

// Parses an index list such as "0-2,5,7-8" (inclusive ranges, ascending, no repeats) of indices
// below `count`; `what` ("views", "frames") names them in errors. Errors: kShardRange.
Expected<std::vector<uint32_t>> parse_index_list(const std::string& text, uint32_t count,
                                                 const std::string& what);
// The canonical text of an ascending index list ("0-2,5").
std::string index_list_text(std::span<const uint32_t> indices);

// The marker file name of a shard of `views` (ascending) x frames [first, last].
std::string capture_shard_marker_name(std::span<const uint32_t> views, uint32_t first_frame,
                                      uint32_t last_frame);

// Writes the marker of a finished shard (whole; the manifest as serialize_manifest() writes it).
Status write_capture_shard_marker(const std::filesystem::path& directory,
                                  const CaptureManifest& manifest, std::span<const uint32_t> views,
                                  uint32_t first_frame, uint32_t last_frame);

// Joins the shards in `directory`: kShardMissing (no marker, or an image of the manifest that no
// shard wrote, named), kShardMismatch (two markers with different manifests, both named), the
// manifest parser's errors; then writes manifest.json and removes the markers. Returns the
// number of shards joined.
Expected<uint32_t> join_capture_shards(const std::filesystem::path& directory);

}  // namespace calf::capture
