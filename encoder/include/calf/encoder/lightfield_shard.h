// Sharded light-field encoding (docs/FARM.md): the two passes of lightfield_encode.h run as
// separate jobs, possibly on different machines, and joined into the very bytes one machine writes.
//
//   analysis   write_lightfield_analysis() runs pass 1 over the whole capture set and writes an
//              analysis file: a small .calf container holding the final track header, every
//              view's facts, the encode options and the clip's metadata (record below).
//   shards     encode_lightfield_shard() codes any subset of views with the options the analysis
//              file recorded, and writes their chunks, stored (compressed) exactly as the final
//              clip holds them, into a shard file (a .calf container with the same track header).
//   merge      merge_lightfield_shards() checks that the shards come from that analysis, that no
//              view is in two shards and that every view is in one, then copies the stored chunks
//              view by view into the clip. No chunk is recompressed, so the clip is byte-identical
//              to encode_lightfield_file() with the same options, for any split.
//
// Shard and analysis files are intermediate: calf-verify reads them as containers, but they are
// not playable clips (a shard lacks views; an analysis has no chunks).
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "calf/encoder/lightfield_encode.h"
#include "calf/format/status.h"

namespace calf::encoder {

// An analysis file read back: the analysis, the options it was planned with (every option that
// changes the bytes; threads and progress are the reader's own) and its identity.
struct LightfieldAnalysisFile {
  LightfieldAnalysis analysis;
  LightfieldEncodeOptions options;
  // A hash of the record and the track header; every shard names the analysis it was coded with.
  std::string id;
  // Metadata of the final clip ("encoder", "source_scene", "view_volume"), key-sorted.
  std::vector<std::pair<std::string, std::string>> clip_metadata;
  // Fingerprints of the capture set's images, per view one per segment of segment_frames frames
  // (one for the whole clip without segments): XXH3-64 of the image files' XXH3-64s in frame
  // order. A shard codes only images that match them (kShardMismatch otherwise), and they are in
  // the record the id hashes: captures of one manifest with other pixels have other ids.
  std::vector<std::vector<uint64_t>> pixels;
  // The file it was read from or written to: an input of every shard and merge made with it, so
  // that their output may not replace it (kOutputIsInput). Empty for an analysis held only in
  // memory.
  std::string path;
};

// Pass 1 as a job: analyses every view of the capture set at `capture_dir` (options.threads at a
// time) and writes the analysis file `out_path` whole. Errors: analyse_lightfield()'s;
// kOutputIsInput; file and container errors.
Expected<LightfieldAnalysisFile> write_lightfield_analysis(const std::filesystem::path& capture_dir,
                                                           const std::string& out_path,
                                                           const LightfieldEncodeOptions& options);

// Reads an analysis file. Errors: the container reader's; kShardFile (not an analysis file, or a
// malformed record).
Expected<LightfieldAnalysisFile> read_lightfield_analysis(const std::string& path);

// Codes `views` (ascending) x frames [first_frame, first_frame + frame_count) of the capture set
// at `capture_dir` with the analysis file's options (`threads` worker threads; the capture set
// read within the image budget `max_image_pixels`, CaptureSetReader::open) and writes the
// shard file `out_path` whole. A frame range short of the clip must be whole segments of the
// analysis's segment_frames (encode_lightfield_view_frames()). Errors: kShardRange;
// kShardMismatch (the capture set is not the one analysed: other view count, frames or face size,
// or an image whose bytes differ from the analysis's fingerprint of its segment);
// encode_lightfield_view()'s (kEncoderInput when an image changed since the analysis);
// kOutputIsInput (`out_path` is the analysis file, the manifest or an image of the set).
Expected<LightfieldEncodeStats> encode_lightfield_shard(
    const std::filesystem::path& capture_dir, const LightfieldAnalysisFile& analysis,
    std::span<const uint32_t> views, uint32_t first_frame, uint32_t frame_count, uint32_t threads,
    const std::string& out_path, uint64_t max_image_pixels = capture::kDefaultMaxImagePixels);

// Joins shard files (views x frame ranges) into the clip `out_path` (written whole or not at all);
// the partial t chunks of frame-range shards are joined and compressed as one encode does. Errors:
// the container reader's; kShardFile (not a shard file); kShardMismatch (a shard of another
// analysis, naming both files); kShardOverlap (a view-frame in two shards, naming both);
// kShardMissing (a view-frame in no shard); kOutputIsInput (`out_path` is a shard or the analysis
// file).
Status merge_lightfield_shards(const LightfieldAnalysisFile& analysis,
                               std::span<const std::string> shard_paths,
                               const std::string& out_path);

}  // namespace calf::encoder
