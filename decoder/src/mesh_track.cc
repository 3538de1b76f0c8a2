// Reading a mesh track (format/SPEC.md §11.4); the rules are in mesh_track.h and mesh_layout.h.
#include "calf/decoder/mesh_track.h"

#include <algorithm>
#include <string>
#include <utility>
#include "calf/format/vertex_states.h"

namespace calf::decoder {

using container::cat;
using container::MeshStream;

// The index chunk and where each prototype's and object's chunks are.
struct MeshTrack::Index {
  mesh::IndexChunk chunk;
  std::vector<uint32_t> vertices, triangles;  // chunk id per prototype
  std::vector<uint32_t> visibility;           // chunk id per object
  std::vector<uint32_t> textures;             // chunk id per texture
};

namespace {

constexpr uint32_t kNone = UINT32_MAX;

Status corrupt(const std::string& message) {
  return Status(ErrorId::kMeshChunk, message);
}

std::string stream_text(uint16_t stream) {
  return container::MeshTrackHeader::kStreamNames[stream];
}

}  // namespace

double MeshTrack::fps() const {
  return static_cast<double>(header_.fps_numerator) / header_.fps_denominator;
}

uint32_t MeshTrack::object_count() const {
  return index_ ? static_cast<uint32_t>(index_->chunk.objects.size()) : 0;
}

uint32_t MeshTrack::prototype_count() const {
  return index_ ? static_cast<uint32_t>(index_->chunk.prototypes.size()) : 0;
}

uint32_t MeshTrack::texture_count() const {
  return index_ ? static_cast<uint32_t>(index_->chunk.textures.size()) : 0;
}

const mesh::IndexChunk& MeshTrack::index() const {
  static const mesh::IndexChunk kEmpty;
  return index_ ? index_->chunk : kEmpty;
}

Expected<MeshTrack> MeshTrack::open(const container::Reader& reader, uint16_t track) {
  if (track >= reader.tracks().size() ||
      !std::holds_alternative<container::MeshTrackHeader>(reader.tracks()[track].header)) {
    return Status(ErrorId::kInvalidArgument, cat("track ", track, " is not a mesh track"));
  }
  MeshTrack t;
  t.reader_ = &reader;
  t.track_ = track;
  t.header_ = std::get<container::MeshTrackHeader>(reader.tracks()[track].header);
  if (t.header_.flags & ~mesh::kHeaderVisibleSet)
    return Status(ErrorId::kMeshUnsupported,
                  cat("mesh track header: reserved flags in ", t.header_.flags));

  // One pass over the chunk index: the keys of every chunk of streams 0-4 (§11.4.1).
  std::vector<uint32_t> index_ids;
  struct Keyed {
    uint32_t id;
    uint16_t stream;
    uint32_t region;
  };
  std::vector<Keyed> keyed;
  const auto& chunks = reader.chunks();
  for (uint32_t id = 0; id < chunks.size(); ++id) {
    const auto& k = chunks[id].keys;
    if (k.track != track || k.stream > static_cast<uint16_t>(MeshStream::kTextures)) continue;
    if (k.view || k.face || k.layer || k.first_frame || k.frame_count ||
        (k.stream == 0 && k.region)) {
      return corrupt(cat("chunk ", id, " (", stream_text(k.stream),
                         "): keys other than stream and region must be 0",
                         k.stream == 0 ? ", region too" : ""));
    }
    if (k.stream == 0)
      index_ids.push_back(id);
    else
      keyed.push_back({id, k.stream, k.region});
  }
  if (index_ids.size() != 1) return corrupt(cat(index_ids.size(), " index chunks, expected 1"));
  Expected<std::vector<uint8_t>> raw = reader.read_chunk(index_ids[0]);
  if (!raw.ok()) return std::move(raw).status().with_context("mesh index");
  CALF_ASSIGN_OR_RETURN(mesh::IndexChunk x,
                        mesh::parse_index(*raw, t.header_.frame_count, "mesh index"));

  auto index = std::make_shared<Index>();
  const size_t np = x.prototypes.size(), no = x.objects.size(), nt = x.textures.size();
  index->vertices.assign(np, kNone);
  index->triangles.assign(np, kNone);
  index->visibility.assign(no, kNone);
  index->textures.assign(nt, kNone);
  for (const Keyed& c : keyed) {
    const bool object = c.stream == static_cast<uint16_t>(MeshStream::kVisibility);
    const bool texture = c.stream == static_cast<uint16_t>(MeshStream::kTextures);
    // A layout-1 track has no texture: its stream-4 chunks are a later version's, ignored.
    if (texture && x.layout_version < 2) continue;
    const size_t count = object ? no : texture ? nt : np;
    const char* unit = object ? "object" : texture ? "texture" : "prototype";
    if (c.region >= count) {
      return corrupt(cat("chunk ", c.id, " (", stream_text(c.stream), ") region ", c.region, " of ",
                         count, " ", unit, "s"));
    }
    std::vector<uint32_t>& slot = c.stream == static_cast<uint16_t>(MeshStream::kVertices)
                                      ? index->vertices
                                  : object  ? index->visibility
                                  : texture ? index->textures
                                            : index->triangles;
    if (slot[c.region] != kNone) {
      return corrupt(cat("chunks ", slot[c.region], " and ", c.id, " are both the ",
                         stream_text(c.stream), " chunk of ", unit, " ", c.region));
    }
    slot[c.region] = c.id;
  }
  // Every chunk exists and has the size the index gives (this bounds every count by real bytes).
  uint64_t vertices = 0, triangles = 0;
  for (size_t p = 0; p < np; ++p) {
    const auto& r = x.prototypes[p];
    const uint64_t want[2] = {mesh::vertices_chunk_size(r), mesh::triangles_chunk_size(r)};
    const uint32_t ids[2] = {index->vertices[p], index->triangles[p]};
    for (int s = 0; s < 2; ++s) {
      const char* name = s ? "triangles" : "vertices";
      if (s == 1 && r.triangles_of != p) {
        // It draws an earlier prototype's triangles and has no chunk of its own.
        if (ids[s] != kNone) {
          return corrupt(cat("prototype ", p, " has triangles chunk ", ids[s],
                             " but uses prototype ", r.triangles_of, "'s"));
        }
        continue;
      }
      if (ids[s] == kNone) return corrupt(cat("prototype ", p, " has no ", name, " chunk"));
      if (chunks[ids[s]].raw_size != want[s]) {
        return corrupt(cat("prototype ", p, " ", name, " chunk ", ids[s], " holds ",
                           chunks[ids[s]].raw_size, " bytes, the index gives ", want[s]));
      }
    }
    vertices += r.vertex_count;
  }
  for (size_t o = 0; o < no; ++o) {
    const uint32_t id = index->visibility[o];
    if (id == kNone) return corrupt(cat("object ", o, " has no visibility chunk"));
    if (chunks[id].raw_size < mesh::visibility_chunk_min_size(x.objects[o])) {
      return corrupt(cat("object ", o, " visibility chunk ", id, " holds ", chunks[id].raw_size,
                         " bytes, fewer than its ", x.objects[o].transform_count,
                         " transforms need"));
    }
    triangles += x.objects[o].triangle_count;
  }
  for (size_t i = 0; i < nt; ++i) {
    const uint32_t id = index->textures[i];
    if (id == kNone) return corrupt(cat("texture ", i, " has no textures chunk"));
    if (chunks[id].raw_size != mesh::texture_chunk_size(x.textures[i])) {
      return corrupt(cat("texture ", i, " chunk ", id, " holds ", chunks[id].raw_size,
                         " bytes, the index gives ", mesh::texture_chunk_size(x.textures[i])));
    }
  }
  if (vertices != t.header_.vertex_count || triangles != t.header_.triangle_count) {
    return corrupt(cat("the header gives ", t.header_.vertex_count, " vertices and ",
                       t.header_.triangle_count, " triangles, the index ", vertices, " and ",
                       triangles));
  }
  t.view_volume_ = Box3{{x.view_min[0], x.view_min[1], x.view_min[2]},
                        {x.view_max[0], x.view_max[1], x.view_max[2]}};
  for (size_t i = 0; i < x.materials.size(); ++i) {
    const auto& m = x.materials[i];
    MeshMaterial mm;
    for (int c = 0; c < 3; ++c) {
      mm.base_colour[c] = m.base_colour[c];
      mm.emission[c] = m.emission[c];
    }
    mm.base_colour_texture = x.material_texture(i);
    t.materials_.push_back(mm);
  }
  index->chunk = std::move(x);
  t.index_ = std::move(index);
  return t;
}

Status MeshTrack::object(uint32_t i, MeshObject* out) const {
  if (i >= object_count())
    return Status(ErrorId::kInvalidArgument, cat("object ", i, " of ", object_count()));
  const auto& r = index_->chunk.objects[i];
  const std::string what = cat("object ", i, " visibility chunk ", index_->visibility[i]);
  Expected<std::vector<uint8_t>> raw = reader_->read_chunk(index_->visibility[i]);
  if (!raw.ok()) return std::move(raw).status().with_context(what);
  mesh::Visibility v;
  CALF_RETURN_IF_ERROR(
      mesh::decode_visibility(*raw, r, index_->chunk.prototypes[r.prototype], &v, what));
  out->prototype = r.prototype;
  out->material = r.material;
  out->transforms = std::move(v.transforms);
  out->all_triangles = (r.flags & mesh::kAllTriangles) != 0;
  out->triangles = std::move(v.triangles);
  return Status::Ok();
}

Status MeshTrack::prototype(uint32_t i, MeshPrototype* out) const {
  if (i >= prototype_count())
    return Status(ErrorId::kInvalidArgument, cat("prototype ", i, " of ", prototype_count()));
  const auto& r = index_->chunk.prototypes[i];
  const std::string vwhat = cat("prototype ", i, " vertices chunk ", index_->vertices[i]);
  Expected<std::vector<uint8_t>> vraw = reader_->read_chunk(index_->vertices[i]);
  if (!vraw.ok()) return std::move(vraw).status().with_context(vwhat);
  mesh::VertexArrays v;
  CALF_RETURN_IF_ERROR(mesh::decode_vertices(*vraw, r, &v, vwhat));
  vraw->clear();
  vraw->shrink_to_fit();
  // A prototype sharing an earlier one's triangles reads that chunk; its indices are checked
  // against its own vertex count.
  const uint32_t tid = index_->triangles[r.triangles_of];
  const std::string twhat = cat("prototype ", i, " triangles chunk ", tid);
  Expected<std::vector<uint8_t>> traw = reader_->read_chunk(tid);
  if (!traw.ok()) return std::move(traw).status().with_context(twhat);
  mesh::TriangleArrays tri;
  CALF_RETURN_IF_ERROR(mesh::decode_triangles(
      *traw, r, static_cast<uint32_t>(index_->chunk.materials.size()), &tri, twhat));
  out->positions = std::move(v.positions);
  out->normals = std::move(v.normals);
  out->colours = std::move(v.colours);
  out->uvs = std::move(v.uvs);
  out->state_times = std::move(v.state_times);
  out->state_positions = std::move(v.state_positions);
  out->indices = std::move(tri.indices);
  out->triangle_materials = std::move(tri.triangle_materials);
  return Status::Ok();
}

Status MeshTrack::texture(uint32_t i, mesh::TextureTexels* out) const {
  if (i >= texture_count())
    return Status(ErrorId::kInvalidArgument, cat("texture ", i, " of ", texture_count()));
  const std::string what = cat("texture ", i, " textures chunk ", index_->textures[i]);
  Expected<std::vector<uint8_t>> raw = reader_->read_chunk(index_->textures[i]);
  if (!raw.ok()) return std::move(raw).status().with_context(what);
  return mesh::decode_texture(*raw, index_->chunk.textures[i], out, what);
}

const MeshTransform& transform_at(const MeshObject& object, uint32_t frame) {
  static const MeshTransform kIdentity = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
  if (object.transforms.empty()) return kIdentity;
  return object.transforms[std::min<size_t>(frame, object.transforms.size() - 1)];
}

// The same arithmetic as capture::positions_at (SCENE.md "Vertex states"), so that the track
// and the scene it came from give the same floats at every time.
void positions_at(const MeshPrototype& prototype, double time, std::vector<float>* out) {
  out->resize(prototype.positions.size());
  vertex_states_at(prototype.positions, prototype.state_times, prototype.state_positions, time,
                   *out);
}

}  // namespace calf::decoder
