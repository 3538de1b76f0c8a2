// Whole-track verification of a tiles track; the rules are in the public header.
#include "calf/decoder/tiles_verify.h"

#include <bit>
#include <cstdio>

#include "calf/format/container_codec.h"

namespace calf::decoder {
namespace {

void put(std::vector<uint8_t>& out, uint64_t v, int bytes) {
  for (int i = 0; i < bytes; ++i) out.push_back(static_cast<uint8_t>(v >> (8 * i)));
}

}  // namespace

uint64_t tiles_quads_hash(const TileSet& s) {
  std::vector<uint8_t> b;
  b.reserve(52 + 96 * s.tiles.size());
  put(b, s.tiles.size(), 4);
  for (double d : {s.view_volume.min.x, s.view_volume.min.y, s.view_volume.min.z,
                   s.view_volume.max.x, s.view_volume.max.y, s.view_volume.max.z})
    put(b, std::bit_cast<uint64_t>(d), 8);
  for (const Tile& t : s.tiles) {
    for (const TileCorner& c : t.corners) {
      for (float f : c.position) put(b, std::bit_cast<uint32_t>(f), 4);
      for (float f : c.uvw) put(b, std::bit_cast<uint32_t>(f), 4);
    }
  }
  return container::hash64(b);
}

uint64_t tiles_atlas_hash(const TileSet& s) {
  std::vector<uint8_t> b;
  b.reserve(8 + s.atlas_rgba.size());
  put(b, s.atlas_width, 4);
  put(b, s.atlas_height, 4);
  b.insert(b.end(), s.atlas_rgba.begin(), s.atlas_rgba.end());
  return container::hash64(b);
}

TilesVerifyResult verify_tiles_track(const container::Reader& reader, uint16_t track,
                                     bool with_hashes, size_t max_problems) {
  (void)max_problems;  // a tiles track has one set of chunks: at most one problem
  TilesVerifyResult result;
  const std::string name = "track " + std::to_string(track);
  container::ChunkQuery q;
  q.track = track;
  q.stream = static_cast<uint16_t>(container::TilesStream::kIndex);
  if (reader.find_chunks(q).empty()) {
    result.skipped = true;
    return result;
  }
  Expected<TilesTrack> t = TilesTrack::open(reader, track);
  if (!t.ok()) {
    result.problems.push_back(t.status().with_context(name));
    return result;
  }
  TileSet s;
  if (Status st = t->decode(&s); !st.ok()) {
    result.problems.push_back(st.with_context(name));
    return result;
  }
  result.tiles_decoded = s.tiles.size();
  result.texels_decoded = uint64_t{s.atlas_width} * s.atlas_height;
  if (with_hashes) {
    char line[96];
    std::snprintf(line, sizeof line, "track %u tiles quads %016llx", unsigned{track},
                  static_cast<unsigned long long>(tiles_quads_hash(s)));
    result.hash_lines.push_back(line);
    std::snprintf(line, sizeof line, "track %u tiles atlas %016llx", unsigned{track},
                  static_cast<unsigned long long>(tiles_atlas_hash(s)));
    result.hash_lines.push_back(line);
  }
  return result;
}

}  // namespace calf::decoder
