// Reading a tiles track (format/SPEC.md §11.2); the rules are in tiles_track.h and
// tiles_layout.h.
#include "calf/decoder/tiles_track.h"

#include <string>
#include <utility>
#include <variant>

#include "calf/format/bc.h"

namespace calf::decoder {

using container::cat;
using container::TilesStream;

struct TilesTrack::Index {
  tiles::IndexChunk chunk;
  uint32_t quads = 0;           // chunk id of the quads chunk
  std::vector<uint32_t> bands;  // chunk id of every atlas band
};

namespace {

constexpr uint32_t kNone = UINT32_MAX;

Status corrupt(const std::string& message) {
  return Status(ErrorId::kTilesChunk, "tiles track: " + message);
}

}  // namespace

const tiles::IndexChunk& TilesTrack::index() const {
  static const tiles::IndexChunk kEmpty;
  return index_ ? index_->chunk : kEmpty;
}

Box3 TilesTrack::view_volume() const {
  const tiles::IndexChunk& x = index();
  return Box3{{x.view_min[0], x.view_min[1], x.view_min[2]},
              {x.view_max[0], x.view_max[1], x.view_max[2]}};
}

Expected<TilesTrack> TilesTrack::open(const container::Reader& reader, uint16_t track) {
  if (track >= reader.tracks().size() ||
      !std::holds_alternative<container::TilesTrackHeader>(reader.tracks()[track].header)) {
    return Status(ErrorId::kInvalidArgument, cat("track ", track, " is not a tiles track"));
  }
  TilesTrack t;
  t.reader_ = &reader;
  t.track_ = track;
  t.header_ = std::get<container::TilesTrackHeader>(reader.tracks()[track].header);
  CALF_RETURN_IF_ERROR(tiles::check_header(t.header_));

  // One pass over the chunk index: the keys of every chunk of streams 0 - 2 (§11.2.1).
  std::vector<uint32_t> index_ids, quads_ids, band_ids;
  const auto& chunks = reader.chunks();
  for (uint32_t id = 0; id < chunks.size(); ++id) {
    const auto& k = chunks[id].keys;
    if (k.track != track || k.stream > static_cast<uint16_t>(TilesStream::kQuads)) continue;
    const char* name =
        container::stream_name(static_cast<uint16_t>(container::TrackKind::kTiles), k.stream);
    const bool atlas = k.stream == static_cast<uint16_t>(TilesStream::kAtlas);
    if (k.view || k.face || k.layer || k.first_frame || k.frame_count || (!atlas && k.region))
      return corrupt(cat("chunk ", id, " (", name, "): keys other than stream",
                         atlas ? " and region" : "", " must be 0"));
    (k.stream == 0 ? index_ids : atlas ? band_ids : quads_ids).push_back(id);
  }
  if (index_ids.size() != 1) return corrupt(cat(index_ids.size(), " index chunks, expected 1"));
  if (quads_ids.size() != 1) return corrupt(cat(quads_ids.size(), " quads chunks, expected 1"));
  Expected<std::vector<uint8_t>> raw = reader.read_chunk(index_ids[0]);
  if (!raw.ok()) return std::move(raw).status().with_context("tiles index");
  CALF_ASSIGN_OR_RETURN(tiles::IndexChunk x, tiles::parse_index(*raw, "tiles index"));

  auto index = std::make_shared<Index>();
  const uint32_t w = t.header_.atlas_width, h = t.header_.atlas_height;
  const uint32_t bands = tiles::band_count(h, x.band_rows);
  index->bands.assign(bands, kNone);
  for (uint32_t id : band_ids) {
    const uint32_t b = chunks[id].keys.region;
    if (b >= bands) return corrupt(cat("chunk ", id, " (atlas) band ", b, " of ", bands, " bands"));
    if (index->bands[b] != kNone)
      return corrupt(cat("chunks ", index->bands[b], " and ", id, " are both atlas band ", b));
    index->bands[b] = id;
  }
  // Every chunk present with its exact size (this bounds every count by real bytes).
  index->quads = quads_ids[0];
  if (chunks[index->quads].raw_size != tiles::quads_chunk_size(t.header_.tile_count))
    return corrupt(cat("quads chunk ", index->quads, " holds ", chunks[index->quads].raw_size,
                       " bytes, the header's ", t.header_.tile_count, " tiles need ",
                       tiles::quads_chunk_size(t.header_.tile_count)));
  for (uint32_t b = 0; b < bands; ++b) {
    const uint32_t id = index->bands[b];
    if (id == kNone) return corrupt(cat("no atlas band ", b, " chunk"));
    const uint64_t want = tiles::band_chunk_size(t.header_.atlas_format, w, h, x.band_rows, b);
    if (chunks[id].raw_size != want)
      return corrupt(cat("atlas band ", b, " chunk ", id, " holds ", chunks[id].raw_size,
                         " bytes, expected ", want));
  }
  index->chunk = x;
  t.index_ = std::move(index);
  return t;
}

Status TilesTrack::quads(std::vector<Tile>* out) const {
  const std::string what = cat("tiles quads chunk ", index_->quads);
  Expected<std::vector<uint8_t>> raw = reader_->read_chunk(index_->quads);
  if (!raw.ok()) return std::move(raw).status().with_context(what);
  return tiles::decode_quads(*raw, header_.tile_count, out, what);
}

Status TilesTrack::atlas_payload(std::vector<uint8_t>* out) const {
  out->clear();
  for (uint32_t b = 0; b < index_->bands.size(); ++b) {
    const uint32_t id = index_->bands[b];
    Expected<std::vector<uint8_t>> raw = reader_->read_chunk(id);
    if (!raw.ok())
      return std::move(raw).status().with_context(cat("tiles atlas band ", b, " chunk ", id));
    out->insert(out->end(), raw->begin(), raw->end());
  }
  return Status::Ok();
}

Status TilesTrack::atlas(std::vector<uint8_t>* out) const {
  std::vector<uint8_t> payload;
  CALF_RETURN_IF_ERROR(atlas_payload(&payload));
  const uint32_t w = header_.atlas_width, h = header_.atlas_height;
  if (header_.atlas_format == tiles::kAtlasRgba8) {
    *out = std::move(payload);
    return Status::Ok();
  }
  // BC7: the sizes were checked at open, so the blocks cover the atlas exactly.
  std::vector<uint8_t> texels(size_t{4} * w * h);
  CALF_RETURN_IF_ERROR(bc::decode_image(bc::Format::kBc7, payload.data(), payload.size(), w, h,
                                        texels.data(), texels.size(), size_t{4} * w));
  *out = std::move(texels);
  return Status::Ok();
}

Status TilesTrack::decode(TileSet* out) const {
  TileSet s;
  s.view_volume = view_volume();
  s.atlas_width = header_.atlas_width;
  s.atlas_height = header_.atlas_height;
  CALF_RETURN_IF_ERROR(quads(&s.tiles));
  CALF_RETURN_IF_ERROR(atlas(&s.atlas_rgba));
  *out = std::move(s);
  return Status::Ok();
}

Expected<TileSet> decode_tiles_track(const container::Reader& reader, uint16_t track) {
  CALF_ASSIGN_OR_RETURN(const TilesTrack t, TilesTrack::open(reader, track));
  TileSet s;
  CALF_RETURN_IF_ERROR(t.decode(&s));
  return s;
}

}  // namespace calf::decoder
