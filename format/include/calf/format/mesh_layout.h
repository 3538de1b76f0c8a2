// The mesh track (kind 4, format/SPEC.md §11.4): a visible-set mesh (paper 004). This header
// holds what the frozen 1.0 file (tests/conformance/container/valid/v1_frozen.calf) fixed for
// the kind: its track header and stream tags. Below them (§11.4) the byte layout of its chunks,
// both directions: the versioned index chunk (stream 0) declared once with the fields visitor
// (container_fields.h), and the coded arrays of the vertices, triangles, visibility and (layout 2)
// textures chunks.
// The encoder (encoder/mesh_encode.h) writes chunks with the serialize_* / encode_* functions,
// every decoder (decoder/mesh_track.h) reads them with parse_index / decode_*. This is the one
// place that knows the predictions and byte planes of §11.4.
//
// Parsers check every count and size against the chunk before use and every value before
// returning it: a chunk of the wrong size or a missing array is CALF-E220 (kMeshChunk), an
// unknown layout version or reserved flag bit E221, an index out of range E222, a bad value
// E223, a count above a limit E224. Messages start with the caller's `what` ("prototype 3
// vertices").
#pragma once

#include <array>
#include <cstdint>
#include <iterator>
#include <span>
#include <string>
#include <vector>

#include "calf/format/container_fields.h"
#include "calf/format/container_types.h"
#include "calf/format/status.h"

namespace calf::container {

// Stream tags (SPEC.md §11.4).
#define CALF_MESH_STREAMS(X)  \
  X(kIndex, 0, "index")       \
  X(kVertices, 1, "vertices") \
  X(kTriangles, 2, "triangles") X(kVisibility, 3, "visibility") X(kTextures, 4, "textures")
enum class MeshStream : uint16_t { CALF_MESH_STREAMS(CALF_STREAM_ENUM) };

// Track header (34 bytes), frozen in 1.0; later fields are appended.
struct MeshTrackHeader {
  static constexpr TrackKind kKind = TrackKind::kMesh;
  static constexpr const char* kStreamNames[] = {CALF_MESH_STREAMS(CALF_STREAM_NAME)};
  uint32_t frame_count = 1;
  uint32_t fps_numerator = 24;
  uint32_t fps_denominator = 1;
  uint64_t vertex_count = 0;
  uint64_t triangle_count = 0;
  // SPEC §11.4: vertex_count is the sum of the prototypes' vertex counts (what the
  // track stores), triangle_count the triangles its objects draw (instances counted each time,
  // a subset by its size); both equal the index chunk's sums. segment_count: the perimeter
  // segments the visible set was computed from (0 for a full-scene track). flags bit 0
  // (kMeshHeaderVisibleSet): the objects were reduced to a visible set; other bits 0.
  uint32_t segment_count = 0;  // view-region perimeter segments
  uint16_t flags = 0;
  template <class Self, class V>
  static constexpr void fields(Self& s, V& v) {
    CALF_TRACK_TIMING_FIELDS(s, v);
    v(s.vertex_count, "vertex_count");
    v(s.triangle_count, "triangle_count");
    v(s.segment_count, "segment_count");
    v(s.flags, "flags");
  }
};
static_assert(fixed_size<MeshTrackHeader>() == 34);
static_assert(std::size(MeshTrackHeader::kStreamNames) ==
              static_cast<size_t>(MeshStream::kTextures) + 1);

}  // namespace calf::container

namespace calf::mesh {

// ---- Constants (SPEC.md §11.4) ----

// Layout 2 (textures and UVs) adds the index chunk's textures, the UV array of the vertices chunk
// and the textures stream; layout 1 is layout 2 without them. Readers accept both; calf's encoder
// writes 1 when a track has no UVs and no textures, so such tracks keep their 1.0 bytes.
inline constexpr uint32_t kLayoutVersion = 2;
inline constexpr uint32_t kLayoutVersionUntextured = 1;
inline constexpr uint16_t kHeaderVisibleSet = 1;  // MeshTrackHeader::flags bit 0
// Limits (a larger count is CALF-E224); the scene file's (SCENE.md "Limits").
inline constexpr uint32_t kMaxMaterials = 1u << 16;
inline constexpr uint32_t kMaxPrototypes = 1u << 20;
inline constexpr uint32_t kMaxObjects = 1u << 24;
inline constexpr uint32_t kMaxStates = 4096;  // vertex states per prototype
inline constexpr uint32_t kMaxTextures = 1u << 12;
inline constexpr uint32_t kMaxTextureSize = 16384;  // texels per side
// A material's texture of this value: the material has none.
inline constexpr uint32_t kNoTexture = 0xffffffffu;
// A triangle material of this value means "the object's material" (an analytic sphere's
// triangles in a mesh with per-triangle materials).
inline constexpr uint32_t kObjectMaterial = 0xffffffffu;

// PrototypeRecord::flags: which optional arrays its vertices / triangles chunks hold.
inline constexpr uint32_t kHasNormals = 1;
inline constexpr uint32_t kHasColours = 2;
inline constexpr uint32_t kHasTriangleMaterials = 4;
inline constexpr uint32_t kHasUvs = 8;  // layout 2 only
inline constexpr uint32_t kPrototypeFlagsV1 = 7;
inline constexpr uint32_t kPrototypeFlags = 15;
// ObjectRecord::flags bit 0: the object draws every triangle of its prototype (no subset).
inline constexpr uint32_t kAllTriangles = 1;

// ---- The index chunk (stream 0, §11.4.2) ----

// A surface: linear base colour in [0, 1] and emission >= 0 (finite). 24 bytes.
struct MaterialRecord {
  float base_colour[3] = {0.7f, 0.7f, 0.7f};
  float emission[3] = {0, 0, 0};
  template <class Self, class V>
  static constexpr void fields(Self& s, V& v) {
    v(s.base_colour, "base_colour", container::FloatRule::kFinite);
    v(s.emission, "emission", container::FloatRule::kFinite);
  }
};
static_assert(container::fixed_size<MaterialRecord>() == 24);

// A prototype mesh: its counts, which optional arrays exist, and whose triangles chunk it uses.
// 20 bytes.
struct PrototypeRecord {
  uint32_t vertex_count = 0;
  uint32_t triangle_count = 0;
  uint32_t flags = 0;        // kHasNormals | kHasColours | kHasTriangleMaterials
  uint32_t state_count = 0;  // piecewise-linear vertex states, 0 (static) .. kMaxStates
  // Its own index p: the prototype has its triangles chunk. An earlier prototype q < p: it has
  // none and draws q's triangles (identical indices and triangle materials, e.g. two meshes that
  // are each one analytic sphere); q has its own chunk, the same triangle count and flag bit 2.
  uint32_t triangles_of = 0;
  template <class Self, class V>
  static constexpr void fields(Self& s, V& v) {
    v(s.vertex_count, "vertex_count");
    v(s.triangle_count, "triangle_count");
    v(s.flags, "flags");
    v(s.state_count, "state_count", container::Range{0, kMaxStates});
    v(s.triangles_of, "triangles_of");
  }
};
static_assert(container::fixed_size<PrototypeRecord>() == 20);

// An object: a prototype placed with a material and one transform (static) or one per frame,
// drawing all of the prototype's triangles or a subset of triangle_count of them. 24 bytes.
struct ObjectRecord {
  uint32_t source_object = 0;  // its index in the scene it was made from (informative)
  uint32_t prototype = 0;
  uint32_t material = 0;
  uint32_t transform_count = 1;  // 1 or the track's frame_count
  uint32_t flags = kAllTriangles;
  uint32_t triangle_count = 0;  // drawn: the prototype's with kAllTriangles, else the subset's
  template <class Self, class V>
  static constexpr void fields(Self& s, V& v) {
    v(s.source_object, "source_object");
    v(s.prototype, "prototype");
    v(s.material, "material");
    v(s.transform_count, "transform_count");
    v(s.flags, "flags");
    v(s.triangle_count, "triangle_count");
  }
};
static_assert(container::fixed_size<ObjectRecord>() == 24);

// A base-colour texture (layout 2): its size and coding; its texels are the textures chunk of the
// same index (§11.4.6). 16 bytes.
// Codings of the texels (sRGB RGBA8, lossless): MED residuals in channel planes, or the texels
// as they are, interleaved (flat graphics, whose runs of equal texels supercompress better so).
inline constexpr uint32_t kTextureSrgba8Med = 0;
inline constexpr uint32_t kTextureSrgba8Plain = 1;
struct TextureRecord {
  uint32_t width = 0, height = 0;       // 1 .. kMaxTextureSize
  uint32_t coding = kTextureSrgba8Med;  // kTextureSrgba8Med or kTextureSrgba8Plain
  uint32_t flags = 0;                   // reserved, 0
  template <class Self, class V>
  static constexpr void fields(Self& s, V& v) {
    v(s.width, "width", container::Range{1, kMaxTextureSize});
    v(s.height, "height", container::Range{1, kMaxTextureSize});
    v(s.coding, "coding");
    v(s.flags, "flags");
  }
};
static_assert(container::fixed_size<TextureRecord>() == 16);

// The whole index chunk: u32 layout version, u32 flags (0), the view region, then three counted
// arrays; layout 2 adds the textures and one base-colour texture per material. Nothing may follow.
struct IndexChunk {
  // 1 by default (what an untextured track writes); set kLayoutVersion for textures or UVs.
  uint32_t layout_version = kLayoutVersionUntextured;
  uint32_t flags = 0;              // reserved, 0
  double view_min[3] = {0, 0, 0};  // the box the eye may move in, min <= max
  double view_max[3] = {0, 0, 0};
  std::vector<MaterialRecord> materials;
  std::vector<PrototypeRecord> prototypes;
  std::vector<ObjectRecord> objects;
  // Layout 2 only (empty in layout 1): the textures, and per material its base-colour texture
  // (< textures.size() or kNoTexture), one per material, no count on disk.
  std::vector<TextureRecord> textures;
  std::vector<uint32_t> material_textures;
  template <class Self, class V>
  static constexpr void fields(Self& s, V& v) {
    v(s.layout_version, "layout_version");
    v(s.flags, "flags");
    v(s.view_min, "view_min", container::FloatRule::kFinite);
    v(s.view_max, "view_max", container::FloatRule::kFinite);
    v(s.materials, "materials", container::Range{0, kMaxMaterials});
    v(s.prototypes, "prototypes", container::Range{0, kMaxPrototypes});
    v(s.objects, "objects", container::Range{0, kMaxObjects});
    if (s.layout_version >= 2) {
      v(s.textures, "textures", container::Range{0, kMaxTextures});
      v(s.material_textures, "material_textures", container::Length{s.materials.size()});
    }
  }
  // The texture of material m (kNoTexture in layout 1).
  uint32_t material_texture(size_t m) const {
    return m < material_textures.size() ? material_textures[m] : kNoTexture;
  }
};

// Writes the index chunk. Errors: kContainerWriterMisuse for anything parse_index refuses.
Expected<std::vector<uint8_t>> serialize_index(const IndexChunk& index, uint32_t frame_count);
// Reads and checks the index chunk in §11.4.2's order: the layout version first (1 or 2, else
// E221), every count and size (E220, E224), flags (E221; prototype flag bit 3 and texture flags
// need layout 2, texture coding 0), values (E223), then references: object prototype, material,
// transform count and drawn triangle count, material texture (E222). serialize_index writes
// index.layout_version as given (a layout-1 index must have no textures).
Expected<IndexChunk> parse_index(std::span<const uint8_t> raw, uint32_t frame_count,
                                 const std::string& what);

// ---- Vertices chunk (stream 1, §11.4.3) ----

// A prototype's vertex arrays as they are in memory: 3 floats per vertex (positions, normals,
// colours; state positions 3 per vertex per state, state-major), 2 per vertex for UVs and one
// time per state.
struct VertexArrays {
  std::vector<float> positions;
  std::vector<float> normals;  // empty unless kHasNormals
  std::vector<float> colours;  // empty unless kHasColours
  std::vector<float> uvs;      // empty unless kHasUvs: (u, v), v = 0 at the image's top row
  std::vector<float> state_times;
  std::vector<float> state_positions;
};
// The exact raw size of the vertices chunk of `p` (u64: no overflow for any u32 counts).
uint64_t vertices_chunk_size(const PrototypeRecord& p);
// Codes `a` as `p` describes it (kContainerWriterMisuse when the array sizes do not match `p`).
Expected<std::vector<uint8_t>> encode_vertices(const PrototypeRecord& p, const VertexArrays& a);
// Decodes and checks (size E220, values E223). Replaces `out`.
Status decode_vertices(std::span<const uint8_t> raw, const PrototypeRecord& p, VertexArrays* out,
                       const std::string& what);

// ---- Triangles chunk (stream 2, §11.4.4) ----

struct TriangleArrays {
  std::vector<uint32_t> indices;             // 3 per triangle
  std::vector<uint32_t> triangle_materials;  // empty unless kHasTriangleMaterials
};
uint64_t triangles_chunk_size(const PrototypeRecord& p);
Expected<std::vector<uint8_t>> encode_triangles(const PrototypeRecord& p, const TriangleArrays& a);
// Decodes and checks (size E220; a vertex index >= vertex_count, a triangle material neither
// < material_count nor kObjectMaterial: E222). Replaces `out`.
Status decode_triangles(std::span<const uint8_t> raw, const PrototypeRecord& p,
                        uint32_t material_count, TriangleArrays* out, const std::string& what);

// ---- Visibility chunk (stream 3, §11.4.5) ----

using Transform = std::array<float, 12>;  // row-major 3 x 4, world = M * (x, y, z, 1)
struct Visibility {
  std::vector<Transform> transforms;  // transform_count
  std::vector<uint32_t> triangles;    // sorted subset; empty with kAllTriangles
};
// Codes an object's visibility chunk (kContainerWriterMisuse when it contradicts `o` / `p`).
Expected<std::vector<uint8_t>> encode_visibility(const ObjectRecord& o, const PrototypeRecord& p,
                                                 const Visibility& v);
// Decodes and checks (size, run count E220; non-finite transforms E223; a subset that is not
// strictly increasing, leaves the prototype or has another size than o.triangle_count E222).
Status decode_visibility(std::span<const uint8_t> raw, const ObjectRecord& o,
                         const PrototypeRecord& p, Visibility* out, const std::string& what);
// The smallest raw size of a visibility chunk of `o` (transforms, plus the run count of a subset).
uint64_t visibility_chunk_min_size(const ObjectRecord& o);

// ---- Textures chunk (stream 4, layout 2, §11.4.6) ----

// A texture's texels: 8-bit RGBA, sRGB-encoded colour and linear alpha (as glTF), row 0 at the
// top, width * height * 4 bytes.
struct TextureTexels {
  uint32_t width = 0, height = 0;
  std::vector<uint8_t> rgba;
};
// The exact raw size of a textures chunk of `t` (4 * width * height).
uint64_t texture_chunk_size(const TextureRecord& t);
// Codes `texels` (its size must be t's: kContainerWriterMisuse otherwise) as t.coding says: MED
// residuals in channel planes, or the texels as they are (both lossless).
Expected<std::vector<uint8_t>> encode_texture(const TextureRecord& t, const TextureTexels& texels);
// Decodes (size E220; every byte value is valid). Replaces `out`.
Status decode_texture(std::span<const uint8_t> raw, const TextureRecord& t, TextureTexels* out,
                      const std::string& what);

}  // namespace calf::mesh
