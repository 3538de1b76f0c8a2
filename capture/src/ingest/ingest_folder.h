// The output folder of an ingest (internal): which folders writing it creates, so that a failed
// ingest removes them again and leaves nothing behind.
#pragma once

#include <filesystem>
#include <system_error>
#include <vector>

#include "calf/capture/capture_set.h"

namespace calf::capture::detail {

// `dir` and those of its parents that do not exist yet, deepest first: what creating `dir` makes.
inline std::vector<std::filesystem::path> missing_folders(const std::filesystem::path& dir) {
  std::vector<std::filesystem::path> out;
  std::error_code ec;
  for (std::filesystem::path p = dir; !p.empty(); p = p.parent_path()) {
    if (std::filesystem::symlink_status(p, ec).type() != std::filesystem::file_type::not_found) {
      break;
    }
    out.push_back(p);
    if (p == p.parent_path()) break;
  }
  return out;
}

// Removes `folders` (deepest first) while they are empty; stops at the first that is not.
inline void remove_empty_folders(const std::vector<std::filesystem::path>& folders) {
  for (const std::filesystem::path& dir : folders) {
    std::error_code ec;
    if (!std::filesystem::is_directory(dir, ec)) continue;
    if (!std::filesystem::is_empty(dir, ec) || ec) break;
    std::filesystem::remove(dir, ec);
  }
}

// Creates an ingest's capture-set writer in `out_dir`, recording in `created` the folders that
// makes (for remove_empty_folders when the ingest fails later); when creating the writer fails,
// those folders are removed at once.
inline Expected<CaptureSetWriter> create_ingest_writer(
    const std::filesystem::path& out_dir, const CaptureManifest& manifest,
    std::vector<std::filesystem::path>* created) {
  *created = missing_folders(out_dir);
  Expected<CaptureSetWriter> writer = CaptureSetWriter::create(out_dir, manifest);
  if (!writer.ok()) remove_empty_folders(*created);
  return writer;
}

}  // namespace calf::capture::detail
