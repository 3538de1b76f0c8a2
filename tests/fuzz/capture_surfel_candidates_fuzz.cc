// Fuzz target for the surfel-candidate reader (calf/capture/surfel_candidates.h): any bytes must
// give a file or an error, never a crash, a sanitizer report, an exception or an allocation beyond
// the input's size; a decoded file must encode to the same bytes (a round trip: every field is
// stored once, nothing is normalised away), and the file reader on disk must agree with the
// in-memory parser.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <span>

#include "../scratch_dir.h"
#include "calf/capture/surfel_candidates.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::span<const uint8_t> bytes(data, size);
  auto file = calf::capture::parse_surfel_candidates(bytes, "fuzz");
  // Every 8th input also goes through the reader on disk, which walks the same records through
  // pread (writing a file per input would make the run I/O bound).
  static uint64_t count = 0;
  if (count++ % 8 != 0) {
    if (!file.ok()) return 0;
    auto again = calf::capture::encode_surfel_candidates(*file);
    if (!again.ok() || again->size() != size || !std::equal(again->begin(), again->end(), data)) {
      std::abort();
    }
    return 0;
  }
  const std::string path = (calf::test::scratch_dir("surfel_candidates_fuzz") / "in.cand").string();
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  }
  auto from_disk = calf::capture::read_surfel_candidates(path);
  if (from_disk.ok() != file.ok()) std::abort();
  if (!file.ok()) {
    if (from_disk.status().id() != file.status().id()) std::abort();
    return 0;
  }
  if (!(*from_disk == *file)) std::abort();
  auto encoded = calf::capture::encode_surfel_candidates(*file);
  if (!encoded.ok()) std::abort();
  if (encoded->size() != size || !std::equal(encoded->begin(), encoded->end(), data)) std::abort();
  return 0;
}
