// Surfel-candidate files (calf/capture/surfel_candidates.h, format/SURFEL_CANDIDATES.md): the byte
// layout against sizes and offsets worked out by hand from the document, exact round trips in
// memory and on disk, one test per damaged file (each with its id), the writer's refusals and
// the check that a file belongs to a scene.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "calf/capture/surfel_candidates.h"
#include "calf/format/container_codec.h"

namespace calf::capture {
namespace {

namespace fs = std::filesystem;

// Two records: mesh 0 with 3 candidates in two colour sets (materials 0 and 2), from views 0
// (2 candidates) and 1 (1 candidate); mesh 1 with none.
SurfelCandidateFile sample_file() {
  SurfelCandidateFile f;
  f.header.scene = "t";
  f.header.resolution = 4;
  f.header.direction_count = 8;
  f.header.corners = SurfelCorners::kBox;
  f.header.prototype_count = 2;
  SurfelCandidates a;
  a.mesh = 0;
  a.mesh_hash = 0x0123456789abcdefull;
  a.box_min = {0, 0, 0};
  a.box_max = {1, 2, 1};
  const float k = 1 / std::sqrt(3.0f);
  for (int v = 0; v < 8; ++v) {
    SurfelCandidateView view;
    view.direction = {v & 1 ? -k : k, v & 2 ? -k : k, v & 4 ? -k : k};
    view.pixel_size = 0.5f + 0.125f * static_cast<float>(v);
    view.candidate_count = v == 0 ? 2 : v == 1 ? 1 : 0;
    a.views.push_back(view);
  }
  a.positions = {0, 0, 0, 1, 2, 1, 0.5f, 1.25f, 0.75f};
  a.normals = {0, 1, 0, 0.6f, 0, 0.8f, -1, 0, 0};
  a.colour_sets = {{0, {255, 0, 0, 1, 2, 3, 9, 8, 7}}, {2, {0, 0, 0, 128, 128, 128, 5, 6, 7}}};
  SurfelCandidates b = a;
  b.mesh = 1;
  b.mesh_hash = 42;
  b.positions.clear();
  b.normals.clear();
  b.colour_sets.clear();
  for (SurfelCandidateView& view : b.views) view.candidate_count = 0;
  f.prototypes = {a, b};
  return f;
}

std::vector<uint8_t> encoded(const SurfelCandidateFile& f) {
  auto bytes = encode_surfel_candidates(f);
  EXPECT_TRUE(bytes.ok()) << bytes.status().to_string();
  return bytes.ok() ? *bytes : std::vector<uint8_t>{};
}

uint64_t le(const std::vector<uint8_t>& b, size_t at, size_t n) {
  uint64_t v = 0;
  for (size_t i = 0; i < n; ++i) v |= uint64_t{b[at + i]} << (8 * i);
  return v;
}
void put(std::vector<uint8_t>* b, size_t at, uint64_t v, size_t n) {
  for (size_t i = 0; i < n; ++i) (*b)[at + i] = static_cast<uint8_t>(v >> (8 * i));
}

// Offsets worked out by hand from SURFEL_CANDIDATES.md: the header is 32 fixed bytes, a u32
// name length, the name ("t") and an 8-byte hash; a record is 52 head bytes, 20 per view, 4 per
// colour set, 24 per candidate, 3 per candidate and colour set and an 8-byte hash.
constexpr size_t kHeader = 32 + 4 + 1 + 8;
constexpr size_t kRecord0 = 52 + 8 * 20 + 2 * 4 + 3 * 24 + 2 * 3 * 3 + 8;  // 318
constexpr size_t kRecord1 = 52 + 8 * 20 + 8;                               // 220

void rehash_header(std::vector<uint8_t>* b) {
  put(b, kHeader - 8, container::hash64(std::span(*b).first(kHeader - 8)), 8);
}
void rehash_record(std::vector<uint8_t>* b, size_t offset, size_t size) {
  put(b, offset + size - 8, container::hash64(std::span(*b).subspan(offset, size - 8)), 8);
}

Status parse_status(const std::vector<uint8_t>& b) {
  auto f = parse_surfel_candidates(b, "damaged.cand");
  return f.ok() ? Status::Ok() : f.status();
}

TEST(SurfelCandidates, LayoutIsTheDocumentedOne) {
  const std::vector<uint8_t> b = encoded(sample_file());
  ASSERT_EQ(b.size(), kHeader + kRecord0 + kRecord1);
  EXPECT_EQ(std::string(b.begin(), b.begin() + 8), "calfcand");
  EXPECT_EQ(le(b, 8, 4), 1u);   // version
  EXPECT_EQ(le(b, 12, 4), 0u);  // flags
  EXPECT_EQ(le(b, 16, 4), 4u);  // resolution
  EXPECT_EQ(le(b, 20, 4), 8u);  // direction_count
  EXPECT_EQ(le(b, 24, 4), 1u);  // corners: box
  EXPECT_EQ(le(b, 28, 4), 2u);  // prototype_count
  EXPECT_EQ(le(b, 32, 4), 1u);  // scene name length
  EXPECT_EQ(b[36], 't');
  EXPECT_EQ(le(b, kHeader, 8), kRecord0);                    // record_size
  EXPECT_EQ(le(b, kHeader + 8, 4), 0u);                      // mesh
  EXPECT_EQ(le(b, kHeader + 12, 8), 0x0123456789abcdefull);  // mesh_hash
  EXPECT_EQ(le(b, kHeader + 20, 4), 3u);                     // candidate_count
  EXPECT_EQ(le(b, kHeader + 24, 4), 2u);                     // colour_set_count
  float pixel = 0;
  const uint32_t pixel_bits = static_cast<uint32_t>(le(b, kHeader + 52 + 20 + 12, 4));
  std::memcpy(&pixel, &pixel_bits, 4);
  EXPECT_EQ(pixel, 0.625f);                         // views[1].pixel_size
  EXPECT_EQ(le(b, kHeader + 52 + 20 + 16, 4), 1u);  // views[1].candidate_count
  EXPECT_EQ(le(b, kHeader + 52 + 160 + 4, 4), 2u);  // the second set's material
  const size_t colours = kHeader + 52 + 160 + 8 + 72;
  EXPECT_EQ(b[colours], 255);
  EXPECT_EQ(b[colours + 9 + 3], 128);  // set 1, candidate 1, red
  EXPECT_EQ(le(b, kHeader + kRecord0, 8), kRecord1);
  // Deterministic.
  EXPECT_TRUE(encoded(sample_file()) == b);
}

TEST(SurfelCandidates, RoundTripInMemory) {
  const SurfelCandidateFile f = sample_file();
  auto back = parse_surfel_candidates(encoded(f), "memory");
  ASSERT_TRUE(back.ok()) << back.status().to_string();
  EXPECT_TRUE(*back == f);
  const auto entries = surfel_candidate_entries(f);
  ASSERT_EQ(entries.size(), 2u);
  EXPECT_EQ(entries[0].offset, kHeader);
  EXPECT_EQ(entries[0].size, kRecord0);
  EXPECT_EQ(entries[1].offset, kHeader + kRecord0);
  EXPECT_EQ(entries[1].candidate_count, 0u);
}

TEST(SurfelCandidates, RoundTripOnDiskRecordByRecord) {
  const fs::path dir = fs::temp_directory_path() / ("calf_surfel_cand_" + std::to_string(getpid()));
  fs::create_directories(dir);
  const std::string path = (dir / "c.cand").string();
  const SurfelCandidateFile f = sample_file();
  ASSERT_TRUE(write_surfel_candidates(path, f).ok());
  EXPECT_EQ(fs::file_size(path), kHeader + kRecord0 + kRecord1);
  auto reader = SurfelCandidateReader::open(path);
  ASSERT_TRUE(reader.ok()) << reader.status().to_string();
  EXPECT_TRUE(reader->header() == f.header);
  ASSERT_EQ(reader->entries().size(), 2u);
  EXPECT_EQ(reader->entries()[0].mesh_hash, 0x0123456789abcdefull);
  EXPECT_EQ(reader->entries()[0].candidate_count, 3u);
  EXPECT_EQ(reader->entries()[0].colour_set_count, 2u);
  EXPECT_EQ(reader->entries()[0].last_material, 2u);  // the second set's, as laid out above
  EXPECT_EQ(reader->entries()[1].last_material, 0u);  // no colour sets
  EXPECT_EQ(reader->entries()[1].offset, kHeader + kRecord0);
  auto one = reader->read(1);
  ASSERT_TRUE(one.ok());
  EXPECT_TRUE(*one == f.prototypes[1]);
  EXPECT_FALSE(reader->read(2).ok());
  auto all = read_surfel_candidates(path);
  ASSERT_TRUE(all.ok());
  EXPECT_TRUE(*all == f);
  // A directory is not a file to read.
  auto dir_read = read_surfel_candidates(dir.string());
  ASSERT_FALSE(dir_read.ok());
  fs::remove_all(dir);
}

TEST(SurfelCandidates, WriterIsWholeOrNothing) {
  const fs::path dir = fs::temp_directory_path() / ("calf_surfel_wr_" + std::to_string(getpid()));
  fs::create_directories(dir);
  const std::string path = (dir / "c.cand").string();
  const SurfelCandidateFile f = sample_file();
  {
    auto w = SurfelCandidateWriter::create(path, f.header);
    ASSERT_TRUE(w.ok());
    ASSERT_TRUE(w->add(f.prototypes[0]).ok());
    Status early = w->commit();  // one record of two
    EXPECT_EQ(early.id(), ErrorId::kSurfelWriterMisuse) << early.to_string();
  }
  EXPECT_FALSE(fs::exists(path));
  EXPECT_TRUE(fs::is_empty(dir)) << "no temporary file left";
  {
    auto w = SurfelCandidateWriter::create(path, f.header);
    ASSERT_TRUE(w.ok());
    Status order = w->add(f.prototypes[1]);  // mesh 1 first
    EXPECT_EQ(order.id(), ErrorId::kSurfelWriterMisuse) << order.to_string();
  }
  EXPECT_FALSE(fs::exists(path));
  fs::remove_all(dir);
}

TEST(SurfelCandidates, WriterRefusesWhatTheReaderWould) {
  auto id_of = [](const SurfelCandidateFile& f) {
    auto b = encode_surfel_candidates(f);
    return b.ok() ? ErrorId::kOk : b.status().id();
  };
  SurfelCandidateFile f = sample_file();
  f.prototypes[0].normals.pop_back();
  EXPECT_EQ(id_of(f), ErrorId::kSurfelWriterMisuse);
  f = sample_file();
  f.prototypes[0].colour_sets[1].colours.push_back(0);
  EXPECT_EQ(id_of(f), ErrorId::kSurfelWriterMisuse);
  f = sample_file();
  f.prototypes[0].views.pop_back();
  EXPECT_EQ(id_of(f), ErrorId::kSurfelWriterMisuse);
  f = sample_file();
  f.header.prototype_count = 3;
  EXPECT_EQ(id_of(f), ErrorId::kSurfelWriterMisuse);
  f = sample_file();
  f.header.direction_count = 16;
  EXPECT_EQ(id_of(f), ErrorId::kSurfelWriterMisuse);
  f = sample_file();
  f.prototypes[0].normals[0] = 2;  // not unit
  EXPECT_EQ(id_of(f), ErrorId::kSurfelFileValue);
  f = sample_file();
  f.prototypes[0].positions[4] = 2.5f;  // outside the box (y <= 2)
  EXPECT_EQ(id_of(f), ErrorId::kSurfelFileValue);
  f = sample_file();
  f.prototypes[0].views[0].candidate_count = 1;  // 1 + 1 != 3
  EXPECT_EQ(id_of(f), ErrorId::kSurfelFileField);
  f = sample_file();
  f.prototypes[0].colour_sets[1].material = 0;  // not increasing
  EXPECT_EQ(id_of(f), ErrorId::kSurfelFileField);
  f = sample_file();
  f.prototypes[0].views[2].pixel_size = 0;
  EXPECT_EQ(id_of(f), ErrorId::kSurfelFileValue);
}

// Each damage, in the bytes, gives its own id; the message names the file.
TEST(SurfelCandidates, DamagedFilesGiveTheirIds) {
  const std::vector<uint8_t> good = encoded(sample_file());
  ASSERT_TRUE(parse_status(good).ok());
  struct Case {
    const char* what;
    ErrorId id;
    std::vector<uint8_t> bytes;
  };
  std::vector<Case> cases;
  auto with = [&](const char* what, ErrorId id, auto&& damage) {
    std::vector<uint8_t> b = good;
    damage(&b);
    cases.push_back({what, id, std::move(b)});
  };
  with("magic", ErrorId::kSurfelFileIdentifier, [](auto* b) { (*b)[0] = 'C'; });
  with("empty", ErrorId::kSurfelFileIdentifier, [](auto* b) { b->clear(); });
  with("version 2", ErrorId::kSurfelFileVersion, [](auto* b) { put(b, 8, 2, 4); });
  with("flags", ErrorId::kSurfelFileVersion, [](auto* b) {
    put(b, 12, 1, 4);
    rehash_header(b);
  });
  with("header hash", ErrorId::kSurfelFileHash, [](auto* b) { put(b, 16, 8, 4); });
  with("resolution 0", ErrorId::kSurfelFileField, [](auto* b) {
    put(b, 16, 0, 4);
    rehash_header(b);
  });
  with("resolution 5000", ErrorId::kSurfelFileLimit, [](auto* b) {
    put(b, 16, 5000, 4);
    rehash_header(b);
  });
  with("9 directions", ErrorId::kSurfelFileField, [](auto* b) {
    put(b, 20, 9, 4);
    rehash_header(b);
  });
  with("corners 2", ErrorId::kSurfelFileField, [](auto* b) {
    put(b, 24, 2, 4);
    rehash_header(b);
  });
  with("2^21 prototypes", ErrorId::kSurfelFileLimit, [](auto* b) {
    put(b, 28, 1u << 21, 4);
    rehash_header(b);
  });
  with("more prototypes than bytes", ErrorId::kSurfelFileTruncated, [](auto* b) {
    put(b, 28, 9, 4);
    rehash_header(b);
  });
  with("name longer than the file", ErrorId::kSurfelFileTruncated,
       [](auto* b) { put(b, 32, 1000, 4); });
  with("name over the limit", ErrorId::kSurfelFileLimit, [](auto* b) { put(b, 32, 100000, 4); });
  with("cut in the header", ErrorId::kSurfelFileTruncated, [](auto* b) { b->resize(30); });
  with("cut in a record", ErrorId::kSurfelFileTruncated, [](auto* b) { b->pop_back(); });
  with("trailing byte", ErrorId::kSurfelFileField, [](auto* b) { b->push_back(0); });
  with("record hash", ErrorId::kSurfelFileHash, [](auto* b) { (*b)[kHeader + 60] ^= 1; });
  with("record_size too small", ErrorId::kSurfelFileField, [](auto* b) { put(b, kHeader, 20, 8); });
  with("mesh index", ErrorId::kSurfelFileField, [](auto* b) {
    put(b, kHeader + 8, 1, 4);
    rehash_record(b, kHeader, kRecord0);
  });
  with("candidate limit", ErrorId::kSurfelFileLimit, [](auto* b) {
    put(b, kHeader + 20, 8 * 16 + 1, 4);  // > directions x R^2
    rehash_record(b, kHeader, kRecord0);
  });
  with("colour set limit", ErrorId::kSurfelFileLimit, [](auto* b) {
    put(b, kHeader + 24, 65537, 4);
    rehash_record(b, kHeader, kRecord0);
  });
  with("counts against record_size", ErrorId::kSurfelFileField, [](auto* b) {
    put(b, kHeader + 24, 1, 4);  // one colour set: the record would be 9 + 4 bytes shorter
    rehash_record(b, kHeader, kRecord0);
  });
  with("NaN position", ErrorId::kSurfelFileValue, [](auto* b) {
    const float nan = std::numeric_limits<float>::quiet_NaN();
    uint32_t bits;
    std::memcpy(&bits, &nan, 4);
    put(b, kHeader + 52 + 160 + 8, bits, 4);
    rehash_record(b, kHeader, kRecord0);
  });
  with("normal not unit", ErrorId::kSurfelFileValue, [](auto* b) {
    put(b, kHeader + 52 + 160 + 8 + 36 + 4, 0x40000000u, 4);  // normal 0's y = 2
    rehash_record(b, kHeader, kRecord0);
  });
  with("view direction not unit", ErrorId::kSurfelFileValue, [](auto* b) {
    put(b, kHeader + 52, 0, 4);
    rehash_record(b, kHeader, kRecord0);
  });
  with("view counts", ErrorId::kSurfelFileField, [](auto* b) {
    put(b, kHeader + 52 + 16, 1, 4);
    rehash_record(b, kHeader, kRecord0);
  });
  with("materials order", ErrorId::kSurfelFileField, [](auto* b) {
    put(b, kHeader + 52 + 160 + 4, 0, 4);
    rehash_record(b, kHeader, kRecord0);
  });
  with("box not ordered", ErrorId::kSurfelFileValue, [](auto* b) {
    put(b, kHeader + 28, 0x40400000u, 4);  // box_min.x = 3 > box_max.x
    rehash_record(b, kHeader, kRecord0);
  });
  for (const Case& c : cases) {
    const Status s = parse_status(c.bytes);
    EXPECT_EQ(s.id(), c.id) << c.what << ": " << s.to_string();
    EXPECT_NE(s.message().find("damaged.cand"), std::string::npos)
        << c.what << ": " << s.to_string();
  }
}

TEST(SurfelCandidates, MatchTheSceneTheyWereMadeFrom) {
  SceneFile scene;
  SceneMesh m;
  m.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  m.indices = {0, 1, 2};
  scene.meshes = {m, m};
  scene.meshes[1].positions[0] = 0.5f;
  scene.materials.resize(3);  // the sample's colour sets are of materials 0 and 2
  SurfelCandidateFile f = sample_file();
  f.prototypes[0].mesh_hash = surfel_mesh_hash(scene.meshes[0]);
  f.prototypes[1].mesh_hash = surfel_mesh_hash(scene.meshes[1]);
  EXPECT_NE(f.prototypes[0].mesh_hash, f.prototypes[1].mesh_hash);
  EXPECT_EQ(surfel_mesh_hash(scene.meshes[0]), surfel_mesh_hash(m));
  const auto entries = surfel_candidate_entries(f);
  EXPECT_TRUE(check_surfel_candidates_match(entries, scene, "c").ok());
  SceneFile moved = scene;
  moved.meshes[1].positions[4] = 0.25f;
  Status s = check_surfel_candidates_match(entries, moved, "c");
  EXPECT_EQ(s.id(), ErrorId::kSurfelSceneMismatch);
  EXPECT_NE(s.message().find("record 1"), std::string::npos) << s.to_string();
  SceneFile coloured = scene;
  coloured.meshes[0].colors = {1, 1, 1, 1, 1, 1, 0, 0, 0};
  EXPECT_EQ(check_surfel_candidates_match(entries, coloured, "c").id(),
            ErrorId::kSurfelSceneMismatch);
  // A colour set of a material the scene lacks (a builder would index past its materials).
  SceneFile fewer = scene;
  fewer.materials.resize(2);
  s = check_surfel_candidates_match(entries, fewer, "c");
  EXPECT_EQ(s.id(), ErrorId::kSurfelSceneMismatch);
  EXPECT_NE(s.message().find("record 0 has a colour set of material 2"), std::string::npos)
      << s.to_string();
  scene.meshes.pop_back();
  EXPECT_EQ(check_surfel_candidates_match(entries, scene, "c").id(), ErrorId::kSurfelSceneMismatch);
}

// The same refusal on a file read from disk: the reader's entries carry each record's last
// material, whatever it is (60000000 would have crashed the surfel builder, 5 read past the
// scene's materials without a word).
TEST(SurfelCandidates, MaterialsPastTheSceneAreRefusedFromDisk) {
  const fs::path dir =
      fs::temp_directory_path() / ("calf_surfel_cand_mat_" + std::to_string(getpid()));
  fs::create_directories(dir);
  SceneFile scene;
  SceneMesh m;
  m.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  m.indices = {0, 1, 2};
  scene.meshes = {m, m};
  scene.materials.resize(3);
  for (const uint32_t material : {3u, 5u, 60000000u, 0xfffffffeu}) {
    SurfelCandidateFile f = sample_file();
    f.prototypes[0].mesh_hash = surfel_mesh_hash(scene.meshes[0]);
    f.prototypes[1].mesh_hash = surfel_mesh_hash(scene.meshes[1]);
    f.prototypes[0].colour_sets[1].material = material;
    const std::string path = (dir / "c.cand").string();
    ASSERT_TRUE(write_surfel_candidates(path, f).ok());
    auto reader = SurfelCandidateReader::open(path);
    ASSERT_TRUE(reader.ok()) << reader.status().to_string();
    const Status s = check_surfel_candidates_match(reader->entries(), scene, path);
    EXPECT_EQ(s.id(), ErrorId::kSurfelSceneMismatch) << material;
    EXPECT_NE(s.message().find("material " + std::to_string(material)), std::string::npos)
        << s.to_string();
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace calf::capture
