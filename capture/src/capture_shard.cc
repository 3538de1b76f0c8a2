// Capture shards: index lists, shard markers and the join (calf/capture/capture_shard.h).
#include "calf/capture/capture_shard.h"

#include <algorithm>
#include <system_error>

namespace calf::capture {

namespace {
constexpr const char* kMarkerPrefix = "capture-shard.";
constexpr const char* kMarkerSuffix = ".json";
}  // namespace

Expected<std::vector<uint32_t>> parse_index_list(const std::string& text, uint32_t count,
                                                 const std::string& what) {
  auto bad = [&](const std::string& why) {
    return Status(ErrorId::kShardRange, what + " '" + text + "': " + why + " (the set has " +
                                            std::to_string(count) + " " + what + ")");
  };
  std::vector<uint32_t> out;
  size_t i = 0;
  auto number = [&](uint32_t* value) -> bool {
    const size_t start = i;
    uint64_t v = 0;
    while (i < text.size() && text[i] >= '0' && text[i] <= '9' && i - start < 10) {
      v = v * 10 + static_cast<uint64_t>(text[i] - '0');
      ++i;
    }
    if (i == start || v > UINT32_MAX) return false;
    *value = static_cast<uint32_t>(v);
    return true;
  };
  if (text.empty()) return bad("empty list");
  while (i < text.size()) {
    uint32_t a = 0, b = 0;
    if (!number(&a)) return bad("expected a number at character " + std::to_string(i + 1));
    b = a;
    if (i < text.size() && text[i] == '-') {
      ++i;
      if (!number(&b)) return bad("expected a number after '-'");
    }
    if (b < a) return bad("range " + std::to_string(a) + "-" + std::to_string(b) + " is reversed");
    if (b >= count) return bad(std::to_string(b) + " is outside the set");
    if (!out.empty() && a <= out.back()) return bad("indices must ascend without repeats");
    for (uint64_t v = a; v <= b; ++v) out.push_back(static_cast<uint32_t>(v));
    if (i < text.size()) {
      if (text[i] != ',' || i + 1 == text.size()) {
        return bad("expected ',' at character " + std::to_string(i + 1));
      }
      ++i;
    }
  }
  return out;
}

std::string index_list_text(std::span<const uint32_t> indices) {
  std::string s;
  for (size_t i = 0; i < indices.size();) {
    size_t j = i;
    while (j + 1 < indices.size() && indices[j + 1] == indices[j] + 1) ++j;
    if (!s.empty()) s += ",";
    s += std::to_string(indices[i]);
    if (j > i) {
      s += '-';
      s += std::to_string(indices[j]);
    }
    i = j + 1;
  }
  return s;
}

std::string capture_shard_marker_name(std::span<const uint32_t> views, uint32_t first_frame,
                                      uint32_t last_frame) {
  return std::string(kMarkerPrefix) + "v" + index_list_text(views) + ".f" +
         std::to_string(first_frame) + "-" + std::to_string(last_frame) + kMarkerSuffix;
}

Status write_capture_shard_marker(const std::filesystem::path& directory,
                                  const CaptureManifest& manifest, std::span<const uint32_t> views,
                                  uint32_t first_frame, uint32_t last_frame) {
  return write_file_atomically(
      directory / capture_shard_marker_name(views, first_frame, last_frame),
      serialize_manifest(manifest));
}

Expected<uint32_t> join_capture_shards(const std::filesystem::path& directory) {
  std::vector<std::filesystem::path> markers;
  std::error_code ec;
  for (std::filesystem::directory_iterator it(directory, ec), end; !ec && it != end;
       it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.rfind(kMarkerPrefix, 0) == 0 && name.size() > std::string(kMarkerSuffix).size() &&
        name.compare(name.size() - 5, 5, kMarkerSuffix) == 0) {
      markers.push_back(it->path());
    }
  }
  if (ec) return Status(ErrorId::kFileOpen, directory.string() + ": " + ec.message());
  if (markers.empty()) {
    return Status(ErrorId::kShardMissing,
                  directory.string() + ": no capture shard (capture-shard.*.json) to join");
  }
  std::sort(markers.begin(), markers.end());
  CALF_ASSIGN_OR_RETURN(const std::string first, read_small_file(markers[0]));
  for (size_t i = 1; i < markers.size(); ++i) {
    CALF_ASSIGN_OR_RETURN(const std::string text, read_small_file(markers[i]));
    if (text != first) {
      return Status(ErrorId::kShardMismatch, markers[i].string() + " and " + markers[0].string() +
                                                 " are shards of different capture sets");
    }
  }
  CALF_ASSIGN_OR_RETURN(const CaptureManifest m, parse_manifest(first, markers[0].string()));
  for (uint32_t v = 0; v < m.viewpoints.size(); ++v) {
    for (uint32_t f = 0; f < m.frame_count; ++f) {
      const std::filesystem::path image = directory / capture_file_name(m, v, f);
      if (!std::filesystem::is_regular_file(image, ec)) {
        return Status(ErrorId::kShardMissing,
                      image.string() + ": view " + std::to_string(v) + ", frame " +
                          std::to_string(f) + " is in none of the " +
                          std::to_string(markers.size()) + " capture shards");
      }
    }
  }
  CALF_RETURN_IF_ERROR(write_file_atomically(directory / kManifestFileName, first));
  for (const auto& p : markers) std::filesystem::remove(p, ec);
  return static_cast<uint32_t>(markers.size());
}

}  // namespace calf::capture
