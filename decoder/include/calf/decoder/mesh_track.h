// Reading a mesh track (kind 4, format/SPEC.md §11.4): objects placing prototype meshes with a
// material and a rigid transform per frame, optionally reduced to a visible set (paper 004). The
// track is readable per object: open() reads the index chunk only, object() decodes one object's
// prototype and triangle subset on demand, texture() one base-colour texture (layout 2).
//
// The player's MeshRepresentation (player/mesh_representation.h) renders what this returns; the
// encoder side is encoder/mesh_encode.h.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "calf/format/container.h"
#include "calf/format/geometry.h"
#include "calf/format/mesh_layout.h"
#include "calf/format/status.h"

namespace calf::decoder {

// A row-major 3 x 4 object-to-world matrix: world = M * (x, y, z, 1) (as SCENE.md).
using MeshTransform = std::array<float, 12>;

// A surface (SCENE.md "Material"; reflect, refract and ior are not part of the track).
struct MeshMaterial {
  std::array<float, 3> base_colour{0.7f, 0.7f, 0.7f};  // linear diffuse reflectance, [0, 1]
  std::array<float, 3> emission{0, 0, 0};              // emitted radiance, >= 0
  // Its base-colour texture (< MeshTrack::texture_count()) or mesh::kNoTexture. The reflectance
  // is base_colour x the texture's linear colour at the vertex UVs x the vertex colour.
  uint32_t base_colour_texture = mesh::kNoTexture;
};

// A prototype mesh in object space, as it lies in the track (SCENE.md "Mesh").
struct MeshPrototype {
  std::vector<float> positions;   // 3 per vertex (the rest pose when there are states)
  std::vector<float> normals;     // empty (use face normals) or 3 per vertex
  std::vector<float> colours;     // empty or 3 per vertex, linear, multiplies the material
  std::vector<float> uvs;         // empty or 2 per vertex (u, v), v = 0 at the texture's top row
  std::vector<uint32_t> indices;  // 3 per triangle
  std::vector<uint32_t> triangle_materials;  // empty or 1 per triangle (material index)
  // Piecewise-linear vertex states (SCENE.md "Vertex states"): times in seconds, strictly
  // increasing, and state_times.size() * vertex_count * 3 floats, state-major. Empty: static.
  std::vector<float> state_times;
  std::vector<float> state_positions;

  size_t vertex_count() const { return positions.size() / 3; }
  size_t triangle_count() const { return indices.size() / 3; }
};

// One object of the track, decoded.
struct MeshObject {
  uint32_t prototype = 0;  // index of its prototype (objects may share one)
  uint32_t material = 0;   // index into MeshTrack::materials()
  // 1 (static) or frame_count transforms; transform_at() picks one.
  std::vector<MeshTransform> transforms;
  // The triangles of the prototype this object draws, as sorted prototype triangle indices;
  // `all_triangles` true means every triangle (a full-scene track), and `triangles` is empty.
  bool all_triangles = true;
  std::vector<uint32_t> triangles;
};

class MeshTrack {
 public:
  // Reads track `track`'s header and index chunk (stream 0). `reader` must outlive the result.
  // Errors: kInvalidArgument (no such track, not a mesh track) and the track's chunk errors
  // (format/SPEC.md §11.4).
  static Expected<MeshTrack> open(const container::Reader& reader, uint16_t track);

  const container::MeshTrackHeader& header() const { return header_; }
  uint32_t frame_count() const { return header_.frame_count; }
  double fps() const;
  // The box the eye may move in (the scene's view region).
  const Box3& view_volume() const { return view_volume_; }

  uint32_t object_count() const;
  uint32_t prototype_count() const;
  uint32_t texture_count() const;
  const std::vector<MeshMaterial>& materials() const { return materials_; }
  // The index chunk as read (format/mesh_layout.h): the prototype and object records with their
  // counts and flags, e.g. for figures without decoding (calf-verify, tests).
  const mesh::IndexChunk& index() const;
  uint16_t track() const { return track_; }

  // Decodes object `index` (its transforms and triangle subset); errors name the chunk.
  Status object(uint32_t index, MeshObject* out) const;
  // Decodes prototype `index`; errors name the chunk.
  Status prototype(uint32_t index, MeshPrototype* out) const;
  // Decodes texture `index` (level 0, sRGB RGBA8, row 0 at the top; calf/format/mesh_texture.h
  // makes its mip chain); errors name the chunk.
  Status texture(uint32_t index, mesh::TextureTexels* out) const;

 private:
  MeshTrack() = default;
  const container::Reader* reader_ = nullptr;
  uint16_t track_ = 0;
  container::MeshTrackHeader header_;
  Box3 view_volume_;
  std::vector<MeshMaterial> materials_;
  // The index chunk's tables (owned by the implementation).
  struct Index;
  std::shared_ptr<const Index> index_;
};

// The object-to-world transform of `object` at frame f (the one transform when static, else
// transforms[min(f, last)]).
const MeshTransform& transform_at(const MeshObject& object, uint32_t frame);

// The prototype's object-space vertex positions at `time` seconds into `out` (3 floats per
// vertex): `positions` without states, else linear between the two states around `time`, held
// before the first and after the last (paper 004 Eqs. 3-4, SCENE.md "Vertex states").
void positions_at(const MeshPrototype& prototype, double time, std::vector<float>* out);

}  // namespace calf::decoder
