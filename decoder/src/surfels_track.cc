// Reading a surfels track (format/SPEC.md §11.3); the rules are in surfels_track.h and
// surfels_layout.h.
#include "calf/decoder/surfels_track.h"

#include <string>
#include <utility>
#include <variant>

#include "calf/decoder/mesh_track.h"

namespace calf::decoder {

using container::cat;
using container::SurfelsStream;

// The index chunk and where each prototype's level chunks are.
struct SurfelsTrack::Index {
  surfels::IndexChunk chunk;
  std::vector<std::vector<uint32_t>> levels;  // chunk id per prototype per level
};

namespace {

constexpr uint32_t kNone = UINT32_MAX;

Status corrupt(const std::string& message) {
  return Status(ErrorId::kSurfelsChunk, "surfels track: " + message);
}

}  // namespace

uint16_t SurfelsTrack::mesh_track() const {
  return index_ ? static_cast<uint16_t>(index_->chunk.mesh_track) : 0;
}

uint32_t SurfelsTrack::prototype_count() const {
  return index_ ? static_cast<uint32_t>(index_->chunk.prototypes.size()) : 0;
}

const surfels::PrototypeRecord& SurfelsTrack::record(uint32_t p) const {
  return index_->chunk.prototypes[p];
}

const surfels::IndexChunk& SurfelsTrack::index() const {
  static const surfels::IndexChunk kEmpty;
  return index_ ? index_->chunk : kEmpty;
}

Expected<SurfelsTrack> SurfelsTrack::open(const container::Reader& reader, uint16_t track) {
  if (track >= reader.tracks().size() ||
      !std::holds_alternative<container::SurfelsTrackHeader>(reader.tracks()[track].header)) {
    return Status(ErrorId::kInvalidArgument, cat("track ", track, " is not a surfels track"));
  }
  SurfelsTrack t;
  t.reader_ = &reader;
  t.track_ = track;
  t.header_ = std::get<container::SurfelsTrackHeader>(reader.tracks()[track].header);
  if (t.header_.flags != 0)
    return Status(ErrorId::kSurfelsUnsupported,
                  cat("surfels track header: reserved flags in ", t.header_.flags));

  // One pass over the chunk index: the keys of every chunk of streams 0 and 1 (§11.3.1).
  std::vector<uint32_t> index_ids, level_ids;
  const auto& chunks = reader.chunks();
  for (uint32_t id = 0; id < chunks.size(); ++id) {
    const auto& k = chunks[id].keys;
    if (k.track != track || k.stream > static_cast<uint16_t>(SurfelsStream::kSurfels)) continue;
    if (k.view || k.face || k.first_frame || k.frame_count ||
        (k.stream == 0 && (k.region || k.layer)))
      return corrupt(cat("chunk ", id, " (", k.stream == 0 ? "index" : "surfels",
                         "): keys other than stream, region and layer must be 0",
                         k.stream == 0 ? ", region and layer too" : ""));
    (k.stream == 0 ? index_ids : level_ids).push_back(id);
  }
  if (index_ids.size() != 1) return corrupt(cat(index_ids.size(), " index chunks, expected 1"));
  Expected<std::vector<uint8_t>> raw = reader.read_chunk(index_ids[0]);
  if (!raw.ok()) return std::move(raw).status().with_context("surfels index");
  CALF_ASSIGN_OR_RETURN(surfels::IndexChunk x, surfels::parse_index(*raw, "surfels index"));

  // The paired mesh track: a track of this file, of the mesh kind (its contents are checked by
  // check_pairing, which reads its index chunk).
  if (x.mesh_track >= reader.tracks().size() ||
      !std::holds_alternative<container::MeshTrackHeader>(reader.tracks()[x.mesh_track].header)) {
    return Status(ErrorId::kSurfelsPairing,
                  cat("surfels index: mesh_track ", x.mesh_track, " is not a mesh track of the ",
                      reader.tracks().size(), " tracks"));
  }

  auto index = std::make_shared<Index>();
  const size_t np = x.prototypes.size();
  index->levels.resize(np);
  uint64_t surfels = 0;
  for (size_t p = 0; p < np; ++p) {
    index->levels[p].assign(surfels::level_count(x.prototypes[p].surfel_count), kNone);
    surfels += x.prototypes[p].surfel_count;
  }
  for (uint32_t id : level_ids) {
    const auto& k = chunks[id].keys;
    if (k.region >= np)
      return corrupt(cat("chunk ", id, " (surfels) region ", k.region, " of ", np, " prototypes"));
    auto& slots = index->levels[k.region];
    if (k.layer >= slots.size())
      return corrupt(cat("chunk ", id, " (surfels) level ", k.layer, " of prototype ", k.region,
                         ", which has ", slots.size(), " levels"));
    if (slots[k.layer] != kNone)
      return corrupt(cat("chunks ", slots[k.layer], " and ", id, " are both level ", k.layer,
                         " of prototype ", k.region));
    slots[k.layer] = id;
  }
  // Every level exists with its exact size (this bounds every count by real bytes).
  for (size_t p = 0; p < np; ++p) {
    const uint64_t n = x.prototypes[p].surfel_count;
    for (uint32_t k = 0; k < index->levels[p].size(); ++k) {
      const uint32_t id = index->levels[p][k];
      if (id == kNone) return corrupt(cat("prototype ", p, " has no level ", k, " chunk"));
      if (chunks[id].raw_size != surfels::level_chunk_size(k, n))
        return corrupt(cat("prototype ", p, " level ", k, " chunk ", id, " holds ",
                           chunks[id].raw_size, " bytes, the index gives ",
                           surfels::level_chunk_size(k, n)));
    }
  }
  if (np != t.header_.object_count || surfels != t.header_.surfel_count)
    return corrupt(cat("the header gives ", t.header_.object_count, " prototypes and ",
                       t.header_.surfel_count, " surfels, the index ", np, " and ", surfels));
  index->chunk = std::move(x);
  t.index_ = std::move(index);
  return t;
}

Status SurfelsTrack::check_pairing(const MeshTrack& mesh) const {
  if (mesh.track() != mesh_track())
    return Status(ErrorId::kSurfelsPairing, cat("surfels track ", track_, " pairs with track ",
                                                mesh_track(), ", not mesh track ", mesh.track()));
  if (mesh.prototype_count() != prototype_count())
    return Status(ErrorId::kSurfelsPairing,
                  cat("surfels track ", track_, " has ", prototype_count(),
                      " prototypes, its mesh track ", mesh.track(), " ", mesh.prototype_count()));
  return Status::Ok();
}

Status SurfelsTrack::prototype(uint32_t p, SurfelBuffer* out) const {
  if (p >= prototype_count())
    return Status(ErrorId::kInvalidArgument, cat("prototype ", p, " of ", prototype_count()));
  return prefix(p, record(p).surfel_count, out);
}

Status SurfelsTrack::prefix(uint32_t p, uint32_t count, SurfelBuffer* out) const {
  if (p >= prototype_count())
    return Status(ErrorId::kInvalidArgument, cat("prototype ", p, " of ", prototype_count()));
  const surfels::PrototypeRecord& r = record(p);
  if (count > r.surfel_count)
    return Status(ErrorId::kInvalidArgument, cat("prefix of ", count, " surfels of prototype ", p,
                                                 ", which has ", r.surfel_count));
  *out = SurfelBuffer{};
  const uint32_t levels = surfels::level_count(count);
  for (uint32_t k = 0; k < levels; ++k) {
    const uint32_t id = index_->levels[p][k];
    const std::string what = cat("prototype ", p, " level ", k, " chunk ", id);
    Expected<std::vector<uint8_t>> raw = reader_->read_chunk(id);
    if (!raw.ok()) return std::move(raw).status().with_context(what);
    CALF_RETURN_IF_ERROR(surfels::decode_level(*raw, r, k, out, what));
  }
  out->positions.resize(3 * size_t{count});
  out->normals.resize(3 * size_t{count});
  out->colours.resize(3 * size_t{count});
  return Status::Ok();
}

}  // namespace calf::decoder
