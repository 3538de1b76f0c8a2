// Surfel-candidate files (format/SURFEL_CANDIDATES.md): the initial surfel candidates of paper 001
// Sec. 3.1, one set per mesh prototype of a scene file, so that the surfel builder in encoder/
// reads them without tracing a ray (samples/ renders them: calf-capture --surfel-candidates).
//
// For each mesh of a scene file (a prototype: its instances share its surfels) an orthographic
// G-buffer of R x R pixels is ray cast from each of 8 (or 16) directions, the view enclosing the
// mesh's bounding box; every pixel that hits the mesh is one candidate: its position and normal
// in the mesh's object space and its unshaded base colour, once per material that objects placing
// the mesh use (a "colour set"). Records are in mesh order, record i for mesh i, each hashed, so
// that a reader can check and decode one prototype at a time.
//
// Errors: CALF-E180-E189 (docs/ERRORS.md), each message naming the file, the record (prototype)
// and the field at fault. Nothing here throws; every count is checked against its limit and
// against the bytes present before anything is allocated.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "calf/capture/scene_file.h"
#include "calf/format/status.h"

namespace calf::capture {

inline constexpr uint32_t kSurfelCandidatesVersion = 1;
// The file's first 8 bytes.
inline constexpr std::array<uint8_t, 8> kSurfelCandidatesMagic = {'c', 'a', 'l', 'f',
                                                                  'c', 'a', 'n', 'd'};

// Limits (SURFEL_CANDIDATES.md "Limits"): refused with CALF-E185 before any allocation.
inline constexpr uint32_t kSurfelMaxResolution = 4096;                // G-buffer side, pixels
inline constexpr uint32_t kSurfelMaxPrototypes = kSceneMaxMeshes;     // records in a file
inline constexpr uint32_t kSurfelMaxColourSets = kSceneMaxMaterials;  // colour sets per record
inline constexpr uint32_t kSurfelMaxSceneName = 1000;                 // bytes of `scene`
// Tolerances of the reader's value checks (CALF-E184): a normal or view direction's length is
// within kSurfelUnitTolerance of 1; a position lies in the record's box grown on every side by
// kSurfelBoxTolerance times the box's largest extent (plus 1e-6 for a point-sized box).
inline constexpr float kSurfelUnitTolerance = 1e-3f;
inline constexpr float kSurfelBoxTolerance = 1e-4f;

// Where the 8 view directions come from. kCube (calf's default): from the corners of the box
// made cubical (its centre, its largest half extent on every axis) towards the centre, i.e. the
// diagonals (+-1, +-1, +-1) / sqrt(3), so that a flat or long part (a floor, a pipe) is never seen
// edge-on; kBox: from the corners of the bounding box itself towards its centre (the paper's
// words; the same for a cube-shaped box). With 16 directions the 8 are joined by the same 8
// turned 45 degrees about +Y.
enum class SurfelCorners : uint32_t { kCube = 0, kBox = 1 };

// What the whole file shares.
struct SurfelCandidateHeader {
  std::string scene;             // informative: the scene's name, <= 1000 bytes
  uint32_t resolution = 512;     // R: G-buffer side in pixels, 1..4096
  uint32_t direction_count = 8;  // 8 or 16
  SurfelCorners corners = SurfelCorners::kCube;
  uint32_t prototype_count = 0;  // records: one per mesh of the scene file, <= 2^20
  friend bool operator==(const SurfelCandidateHeader&, const SurfelCandidateHeader&) = default;
};

// One G-buffer: the candidates it gave are consecutive in the record, views in order.
struct SurfelCandidateView {
  std::array<float, 3> direction{0, 0, -1};  // unit: the way the view looks (corner -> centre)
  float pixel_size = 1;          // object-space side of one pixel (> 0): the candidates' spacing
  uint32_t candidate_count = 0;  // <= R * R
  friend bool operator==(const SurfelCandidateView&, const SurfelCandidateView&) = default;
};

// The base colour of every candidate as the objects with one material show it.
struct SurfelColourSet {
  uint32_t material = 0;         // index into the scene file's materials
  std::vector<uint8_t> colours;  // 3 per candidate: sRGB-encoded (colour.h) linear base colour
  friend bool operator==(const SurfelColourSet&, const SurfelColourSet&) = default;
};

// The candidates of one prototype (scene-file mesh), in object space.
struct SurfelCandidates {
  uint32_t mesh = 0;       // the mesh's index in the scene file (== the record's index)
  uint64_t mesh_hash = 0;  // surfel_mesh_hash of that mesh, to check a scene matches
  std::array<float, 3> box_min{0, 0, 0}, box_max{0, 0, 0};  // the box the views enclose
  std::vector<SurfelCandidateView> views;                   // direction_count of them
  std::vector<float> positions;              // 3 per candidate, finite, inside the box
  std::vector<float> normals;                // 3 per candidate, unit, facing the view that saw it
  std::vector<SurfelColourSet> colour_sets;  // materials strictly increasing

  size_t candidate_count() const { return positions.size() / 3; }
  friend bool operator==(const SurfelCandidates&, const SurfelCandidates&) = default;
};

struct SurfelCandidateFile {
  SurfelCandidateHeader header;
  std::vector<SurfelCandidates> prototypes;  // header.prototype_count of them, mesh i at i
  friend bool operator==(const SurfelCandidateFile&, const SurfelCandidateFile&) = default;
};

// What a reader learns of a record without decoding it (SurfelCandidateReader::open).
struct SurfelCandidateEntry {
  uint32_t mesh = 0;
  uint64_t mesh_hash = 0;
  uint32_t candidate_count = 0;
  uint32_t colour_set_count = 0;
  // The last (largest, materials being strictly increasing) colour set's material; 0 without
  // colour sets or when the record is too short to hold its materials (read() refuses it then).
  uint32_t last_material = 0;
  uint64_t offset = 0, size = 0;  // the record's bytes in the file
};

// XXH3-64 of the mesh's geometry and colour inputs, in this order, each as stored in a scene
// buffer (little-endian): positions, triangles, spheres, vertex colours, UVs, triangle
// materials. Whatever changes a candidate's position, normal or colour but the materials
// themselves changes the hash.
uint64_t surfel_mesh_hash(const SceneMesh& mesh);

// Every rule of SURFEL_CANDIDATES.md on one in-memory record, with the reader's ids: array sizes
// that do not match the header or each other CALF-E187 (only an in-memory record can have them),
// a mesh other than `index` (the record's place in the file), view counts that do not add up or
// materials not strictly increasing E183, values E184, counts above a limit E185.
Status validate_surfel_candidates(const SurfelCandidateHeader& header, uint32_t index,
                                  const SurfelCandidates& prototype);

// Ok when `entries` (a file's records) belong to `scene`: one record per mesh, each with that
// mesh's surfel_mesh_hash, every colour set's material below the scene's material count (the
// last one checked: materials strictly increase, which read() enforces). Else CALF-E189 naming
// the first record at fault. `source` names the candidate file in messages. A builder calls it
// before reading any record against the scene.
Status check_surfel_candidates_match(std::span<const SurfelCandidateEntry> entries,
                                     const SceneFile& scene, std::string_view source);
// The entries of an in-memory file (offsets and sizes as encode_surfel_candidates lays it out).
std::vector<SurfelCandidateEntry> surfel_candidate_entries(const SurfelCandidateFile& file);

// ---- whole files in memory (tests, fuzzing, small scenes) ---------------------------------------

// Validates and serialises (CALF-E187 for a file the reader would refuse). Deterministic.
Expected<std::vector<uint8_t>> encode_surfel_candidates(const SurfelCandidateFile& file);
// Decodes and checks a whole file held in memory; `source` names it in messages.
Expected<SurfelCandidateFile> parse_surfel_candidates(std::span<const uint8_t> bytes,
                                                      std::string_view source);

// ---- files on disk -----------------------------------------------------------------------------

// Writes a file record by record (the builder streams one prototype at a time): create() checks
// the output path (files.h: CALF-E004) and writes the header to a temporary file beside it;
// add() appends the next record (mesh 0, 1, ... in order; CALF-E187 out of order or invalid);
// commit() renames the file into place once all header.prototype_count records are in (else
// E187). Destroyed without commit(), it removes the temporary file: a file is whole or absent.
class SurfelCandidateWriter {
 public:
  static Expected<SurfelCandidateWriter> create(const std::string& path,
                                                const SurfelCandidateHeader& header);
  SurfelCandidateWriter(SurfelCandidateWriter&&) noexcept;
  SurfelCandidateWriter& operator=(SurfelCandidateWriter&&) noexcept;
  ~SurfelCandidateWriter();
  Status add(const SurfelCandidates& prototype);
  Status commit();
  uint64_t bytes_written() const;

 private:
  struct Impl;
  explicit SurfelCandidateWriter(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

// write_surfel_candidates: the writer over a whole in-memory file.
Status write_surfel_candidates(const std::string& path, const SurfelCandidateFile& file);

// Reads a file's header and walks its records (8 bytes each, not their contents) so that any
// record can be read alone: open() checks the header (E180, E181, E183, E185, E186) and that the
// records' sizes tile the file exactly (E182 short, E183 otherwise); read(i) reads record i,
// checks its hash (E186) and every rule (E183-E185). The file must be a regular file (E002).
class SurfelCandidateReader {
 public:
  static Expected<SurfelCandidateReader> open(const std::string& path);
  SurfelCandidateReader(SurfelCandidateReader&&) noexcept;
  SurfelCandidateReader& operator=(SurfelCandidateReader&&) noexcept;
  ~SurfelCandidateReader();
  const SurfelCandidateHeader& header() const;
  const std::vector<SurfelCandidateEntry>& entries() const;
  Expected<SurfelCandidates> read(uint32_t index) const;

 private:
  struct Impl;
  explicit SurfelCandidateReader(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

// Opens and reads every record.
Expected<SurfelCandidateFile> read_surfel_candidates(const std::string& path);

}  // namespace calf::capture
