// Test support: a lightfield clip written again with one chunk's payload edited, for the tests
// that check a decoder refuses damaged streams with their own error ids.
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <functional>
#include <variant>
#include <vector>

#include "calf/format/container.h"

namespace calf::testing_support {

// The clip `r` reads (its first track a lightfield track) written to memory with every chunk
// stored raw, the payload of the first chunk whose keys satisfy `which` rewritten by `edit`.
// A failure of the writer, or no chunk matching, fails the calling test.
inline std::vector<uint8_t> with_chunk_edited(
    const container::Reader& r, const std::function<bool(const container::ChunkKeys&)>& which,
    const std::function<void(std::vector<uint8_t>&)>& edit) {
  std::vector<uint8_t> out;
  auto w = container::Writer::create(container::memory_sink(&out));
  EXPECT_TRUE(w.ok());
  EXPECT_TRUE(w->add_track(std::get<container::LightfieldTrackHeader>(r.tracks()[0].header)).ok());
  w->require_minor_version(r.header().version_minor);
  bool edited = false;
  for (uint32_t id = 0; id < r.chunks().size(); ++id) {
    const container::ChunkKeys& k = r.chunks()[id].keys;
    auto raw = r.read_chunk(id);
    EXPECT_TRUE(raw.ok());
    if (!edited && which(k)) {
      edit(*raw);
      edited = true;
    }
    EXPECT_TRUE(w->add_chunk(k, *raw, container::Compression::kNone).ok());
  }
  EXPECT_TRUE(edited);
  EXPECT_TRUE(w->finish().ok());
  return out;
}

}  // namespace calf::testing_support
