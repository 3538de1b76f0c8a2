// The mesh track encoder (kind 4, format/SPEC.md §11.4): a scene file (format/SCENE.md) in, a
// mesh track of a .calf container out, holding the whole scene or only a visible set (paper 004,
// computed by compute_visible_set in calf/encoder/visible_set.h).
//
// What the track holds of a scene:
//   materials   every scene material's base colour, emission and base-colour texture (reflect,
//               refract and ior are not part of the track);
//   textures    every scene texture, in scene order, its pixels losslessly (SPEC §11.4.6);
//   prototypes  the scene meshes that some kept object uses, in mesh order: positions, normals,
//               vertex colours, UVs, triangles, per-triangle materials and vertex states as the
//               scene has them, with each analytic sphere appended as a fixed icosphere
//               (calf/encoder/sphere_mesh.h: sphere s of a mesh of T triangles is prototype
//               triangles [T + s * kSphereTriangles, ...), its vertices held in every state);
//               see prototype_arrays();
//   objects     the scene objects, in scene order, with their prototype, material and transforms
//               (none -> one identity; frame_count equal ones -> one; else one per frame) and,
//               with a visible set, their sorted triangle subset. An object whose subset is empty
//               is left out (it draws nothing); one whose subset is every triangle is stored as
//               "all triangles". ObjectRecord::source_object keeps its scene index.
//
// The index is written in layout 1 (the 1.0 bytes) when nothing needs layout 2: no texture, no
// material naming one and no mesh with UVs; else in layout 2.
//
// Passes (DESIGN.md): the plan (every count, the index chunk and the track header) is made
// first from the scene alone; then every prototype's vertices and triangles chunks, every
// object's visibility chunk and every texture's chunk are coded independently (options.threads at
// a time); then they are added in a fixed order: index, per prototype (vertices, triangles), per
// object (visibility), per texture (textures).
// The bytes depend on the scene, the visible set and the options only, never on `threads`.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "calf/capture/scene_file.h"
#include "calf/format/container.h"
#include "calf/format/mesh_layout.h"
#include "calf/format/status.h"

namespace calf::encoder {

struct MeshEncodeOptions {
  // Supercompression of every chunk of the track (zstd decodes fast; LZMA2 is smallest).
  container::Compression supercompression = container::Compression::kZstd;
  container::CompressionOptions levels;  // zstd level / LZMA preset (fixed per clip)
  uint32_t threads = 1;                  // 0 = all cores; never changes the output
  // Written to the header (informative): the view-region perimeter segments the visible set was
  // computed from; 0 for a full-scene track.
  uint32_t segment_count = 0;
  // The image budget of the scene file's textures (calf/capture/image_budget.h): the files
  // read by encode_mesh_file / encode_surfel_file from a folder are refused with E012 above it.
  uint64_t max_image_pixels = capture::kDefaultMaxImagePixels;
};

// Bytes of one stream of the track.
struct MeshStreamBytes {
  uint64_t raw = 0;     // chunks' raw bytes (after the §11.4 coding, before supercompression)
  uint64_t stored = 0;  // chunks' stored bytes
  uint64_t chunks = 0;
};

struct MeshEncodeStats {
  uint32_t materials = 0, prototypes = 0, objects = 0;
  uint64_t vertices = 0;         // over prototypes (the header's vertex_count)
  uint64_t triangles = 0;        // drawn by the objects (the header's triangle_count)
  uint64_t scene_triangles = 0;  // the scene's, spheres tessellated, instances counted each time
  uint64_t plain_bytes = 0;      // the arrays as plain little-endian f32 / u32 (the baseline)
  MeshStreamBytes index, vertices_stream, triangles_stream, visibility, textures;
};

// A scene mesh as the track stores it (spheres appended, see above), and its record's flags:
// normals are kept when the mesh has them, or when it has no triangles of its own (a sphere-only
// mesh, smooth-shaded); a mesh of both triangles without normals and spheres has none (face
// normals). Colours: a sphere's vertices get (1, 1, 1); UVs (when the mesh has them): (0, 0).
// Triangle materials: a sphere's triangles get mesh::kObjectMaterial. Errors: kEncoderInput (a mesh
// too large for u32 counts).
struct MeshPrototypeArrays {
  mesh::PrototypeRecord record;  // counts and flags
  mesh::VertexArrays vertices;
  mesh::TriangleArrays triangles;
};
Expected<MeshPrototypeArrays> prototype_arrays(const capture::SceneMesh& mesh);

// The values encode_mesh_track refuses in the meshes objects place (a position or sphere beyond
// the coordinate bound, counts too large), checked without encoding anything: a caller that
// computes something from the scene first (calf-encode --visible-set) refuses the scene the mesh
// track would, before that work. Errors: kEncoderInput and kMeshLimit naming the scene mesh.
Status check_mesh_scene(const capture::SceneFile& scene);

// Encodes `scene` into a new mesh track of `writer` (does not finish the writer). `visible`:
// nullptr for every triangle of every object, else one sorted list of mesh-triangle indices per
// scene object (compute_visible_set's VisibleSet::triangles; sphere triangles numbered as
// above). `stats` (optional) receives the figures. Errors: the scene validator's (E152-E161);
// kEncoderOption (threads above 256, an unknown supercompression); kEncoderInput (a visible set
// of the wrong size, a list not strictly increasing or beyond its mesh's triangles, a position
// beyond the coordinate bound, a texture without its pixels); kMeshLimit (a chunk above the
// container's 1 GiB, a count above §11.4's limits); container errors passed through.
//
// The lead's --visible-set flags of calf-encode call this with the builder's lists and
// options.segment_count set.
Status encode_mesh_track(const capture::SceneFile& scene,
                         const std::vector<std::vector<uint32_t>>* visible,
                         const MeshEncodeOptions& options, container::Writer* writer,
                         MeshEncodeStats* stats = nullptr);

// Reads the scene folder `scene_dir` (capture::read_scene_file), encodes it with every triangle
// into `out_path` (written whole or not at all) with metadata "encoder", "source_scene" (the
// scene's name, when it has one) and "view_volume" (the view region). An output that is the
// folder, its scene.json, scene.bin or a texture is refused first (kOutputIsInput).
Expected<MeshEncodeStats> encode_mesh_file(const std::filesystem::path& scene_dir,
                                           const std::string& out_path,
                                           const MeshEncodeOptions& options);

// As above for a scene already read from `scene_dir` (calf-encode --visible-set reads it once to
// compute the set): `visible` as for encode_mesh_track (nullptr: every triangle), and
// `extra_metadata` (key, value) pairs written after the ones above (e.g. how the set was made).
// `more_inputs` are other files the output must not be; `more_tracks` (optional) adds tracks after
// the mesh track (track 0), e.g. the surfels track paired with it.
Expected<MeshEncodeStats> encode_mesh_file(
    const capture::SceneFile& scene, const std::filesystem::path& scene_dir,
    const std::string& out_path, const std::vector<std::vector<uint32_t>>* visible,
    const MeshEncodeOptions& options,
    const std::vector<std::pair<std::string, std::string>>& extra_metadata = {},
    const std::vector<std::string>& more_inputs = {},
    const std::function<Status(container::Writer*)>& more_tracks = nullptr);

// The scene's fps as the header's fraction: n/1 for a whole number, n/1001 for the NTSC rates
// (23.976 = 24000/1001), else round(fps * 10^6) / 10^6 reduced. Exposed for the decoder tests.
void mesh_fps_fraction(double fps, uint32_t* numerator, uint32_t* denominator);

}  // namespace calf::encoder
