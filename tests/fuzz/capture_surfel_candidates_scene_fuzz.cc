// Fuzz target for surfel-candidate files read against their scene (calf/capture/
// surfel_candidates.h, check_surfel_candidates_match): the first byte picks the scene's material
// count (0 to 3; two fixed meshes), the rest is a candidate file whose header and record hashes,
// and the records' mesh hashes, are recomputed before it is read, so that mutations reach the
// fields behind them (materials, counts) as a hostile file with self-consistent hashes does.
// Whatever the bytes: no crash, no sanitizer report; when the file and the scene match, every
// colour set names one of the scene's materials (what the surfel builder indexes), and the reader
// on disk (its entries walked without decoding) agrees with the in-memory parser.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <span>
#include <string>
#include <vector>

#include "../scratch_dir.h"
#include "calf/capture/surfel_candidates.h"
#include "calf/format/container_codec.h"
#include "calf/format/container_fields.h"

namespace {

using calf::capture::SceneFile;

const SceneFile& scene_with(uint32_t materials) {
  static SceneFile scenes[4];
  SceneFile& s = scenes[materials];
  if (s.meshes.empty()) {
    calf::capture::SceneMesh m;
    m.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    m.indices = {0, 1, 2};
    s.meshes = {m, m};
    s.meshes[1].positions[2] = 0.5f;
    s.materials.resize(materials);
  }
  return s;
}

// The file's hashes as SURFEL_CANDIDATES.md lays them out, recomputed in place where the bytes
// hold them: the header's after the scene name, each record's last 8 bytes, and record i's
// mesh_hash (at 12) set to scene mesh i's.
void fix_hashes(std::vector<uint8_t>& b, const SceneFile& scene) {
  if (b.size() < 36) return;
  const uint64_t name = calf::container::load_le(b.data() + 32, 4);
  if (name > 1000 || b.size() < 36 + name + 8) return;
  const size_t head = 36 + static_cast<size_t>(name);
  calf::container::store_le(b.data() + head,
                            calf::container::hash64(std::span<const uint8_t>(b.data(), head)), 8);
  size_t at = head + 8;
  for (size_t i = 0; at + 60 <= b.size(); ++i) {
    const uint64_t record = calf::container::load_le(b.data() + at, 8);
    if (record < 60 || record > b.size() - at) return;
    if (i < scene.meshes.size()) {
      calf::container::store_le(b.data() + at + 12,
                                calf::capture::surfel_mesh_hash(scene.meshes[i]), 8);
    }
    const size_t end = at + static_cast<size_t>(record) - 8;
    calf::container::store_le(
        b.data() + end, calf::container::hash64(std::span<const uint8_t>(b.data() + at, end - at)),
        8);
    at += static_cast<size_t>(record);
  }
}

// A matching file must only name the scene's materials.
void check_materials(const calf::capture::SurfelCandidateFile& file, const SceneFile& scene) {
  for (const auto& p : file.prototypes) {
    for (const auto& set : p.colour_sets) {
      if (set.material >= scene.materials.size()) std::abort();
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  const SceneFile& scene = scene_with(data[0] % 4);
  std::vector<uint8_t> bytes(data + 1, data + size);
  fix_hashes(bytes, scene);
  auto file = calf::capture::parse_surfel_candidates(bytes, "fuzz");
  calf::Status match = calf::Status::Ok();
  if (file.ok()) {
    match = calf::capture::check_surfel_candidates_match(
        calf::capture::surfel_candidate_entries(*file), scene, "fuzz");
    if (match.ok()) check_materials(*file, scene);
  }
  // Every 8th input also goes through the reader on disk: its entries, walked without decoding,
  // must give the same verdict before any record is read.
  static uint64_t count = 0;
  if (count++ % 8 != 0) return 0;
  const std::string path =
      (calf::test::scratch_dir("surfel_candidates_scene_fuzz") / "in.cand").string();
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(bytes.data()),
              static_cast<std::streamsize>(bytes.size()));
  }
  auto reader = calf::capture::SurfelCandidateReader::open(path);
  if (!reader.ok()) {
    if (file.ok()) std::abort();  // the parser accepted what the walk refuses
    return 0;
  }
  const calf::Status disk_match =
      calf::capture::check_surfel_candidates_match(reader->entries(), scene, "fuzz");
  if (file.ok() && disk_match.ok() != match.ok()) std::abort();
  if (!disk_match.ok()) return 0;
  for (uint32_t i = 0; i < reader->entries().size(); ++i) {
    auto record = reader->read(i);
    if (!record.ok()) continue;
    for (const auto& set : record->colour_sets) {
      if (set.material >= scene.materials.size()) std::abort();
    }
  }
  return 0;
}
