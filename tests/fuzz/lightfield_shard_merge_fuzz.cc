// Fuzz target for the merge of a sharded encode (calf/encoder/lightfield_shard.h): the input is
// an analysis file and a shard file, the first 4 bytes (little-endian) the analysis's length. Any
// bytes must give a clip or a one-line error (the analysis reader's, the container reader's,
// CALF-E162..E165), never a crash, a sanitizer report or an exception; a failed merge leaves no
// output, and a clip it writes opens as a container with the analysis's one track.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "../scratch_dir.h"
#include "calf/encoder/lightfield_shard.h"
#include "calf/format/container.h"

namespace {

void write(const std::filesystem::path& path, const uint8_t* data, size_t size) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 4) return 0;
  const size_t split = static_cast<size_t>(data[0]) | static_cast<size_t>(data[1]) << 8 |
                       static_cast<size_t>(data[2]) << 16 | static_cast<size_t>(data[3]) << 24;
  if (split > size - 4) return 0;
  const std::filesystem::path dir = calf::test::scratch_dir("calf_lightfield_shard_merge_fuzz");
  const std::filesystem::path analysis_path = dir / "analysis.calf", shard = dir / "shard.calf",
                              out = dir / "clip.calf";
  write(analysis_path, data + 4, split);
  write(shard, data + 4 + split, size - 4 - split);
  std::filesystem::remove(out);
  auto analysis = calf::encoder::read_lightfield_analysis(analysis_path.string());
  if (!analysis.ok()) {
    if (analysis.status().id() == calf::ErrorId::kOk) std::abort();
    return 0;
  }
  const std::vector<std::string> shards = {shard.string()};
  const calf::Status s = calf::encoder::merge_lightfield_shards(*analysis, shards, out.string());
  if (!s.ok()) {
    if (s.id() == calf::ErrorId::kOk || s.to_string().find('\n') != std::string::npos) std::abort();
    if (std::filesystem::exists(out)) std::abort();
    return 0;
  }
  auto clip = calf::container::Reader::open(out.string());
  if (!clip.ok() || clip->tracks().size() != 1) std::abort();
  return 0;
}
