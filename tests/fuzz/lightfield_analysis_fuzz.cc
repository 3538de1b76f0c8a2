// Fuzz target for the sharded encode's inputs (calf/encoder/lightfield_shard.h,
// calf/capture/capture_shard.h): any bytes read as an analysis file must give the analysis or a
// container / CALF-E162 error, never a crash, a sanitizer report or an exception; an accepted
// analysis must have one fact per view of its header. The same bytes as text go through the
// view-list parser (CALF-E166 or an ascending list below the count).
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "../scratch_dir.h"
#include "calf/capture/capture_shard.h"
#include "calf/encoder/lightfield_shard.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::filesystem::path file =
      calf::test::scratch_dir("calf_lightfield_analysis_fuzz") / "analysis.calf";
  {
    std::ofstream out(file, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  }
  calf::Expected<calf::encoder::LightfieldAnalysisFile> a =
      calf::encoder::read_lightfield_analysis(file.string());
  if (a.ok()) {
    if (a->analysis.views.size() != a->analysis.header.view_count) std::abort();
  } else if (a.status().id() == calf::ErrorId::kOk) {
    std::abort();
  }
  const std::string text(reinterpret_cast<const char*>(data), std::min<size_t>(size, 256));
  calf::Expected<std::vector<uint32_t>> list = calf::capture::parse_index_list(text, 1000, "views");
  if (list.ok()) {
    for (size_t i = 0; i < list->size(); ++i) {
      if ((*list)[i] >= 1000 || (i > 0 && (*list)[i] <= (*list)[i - 1])) std::abort();
    }
  } else if (list.status().id() != calf::ErrorId::kShardRange) {
    std::abort();
  }
  return 0;
}
