// The container conformance suite (tests/conformance/container/, README there).
//
// Runner tests read only committed data: every valid file must open, verify and decode to the
// manifest's hashes; every malformed file must fail with the manifest's error id (and, when the
// calf-verify command is built, make it exit non-zero naming that id); the frozen v1 file must
// read back to its known contents. The generator test re-derives the malformed corpus from the
// committed frozen file and checks it matches what is committed; with CALF_CONFORMANCE_WRITE=1
// it (re)writes the malformed corpus and manifest, and writes valid files only where missing
// (a frozen file is never regenerated).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <sstream>

#include "../conformance/container_corpus.h"
#include "run_command.h"

namespace calf::container {
namespace {

namespace fs = std::filesystem;
using corpus::Bytes;

fs::path suite_dir() {
  const char* root = std::getenv("CALF_SOURCE_DIR");
  return fs::path(root ? root : ".") / "tests" / "conformance" / "container";
}

Bytes read_file(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return Bytes(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

void write_file(const fs::path& p, const Bytes& b) {
  std::ofstream out(p, std::ios::binary);
  out.write(reinterpret_cast<const char*>(b.data()), static_cast<std::streamsize>(b.size()));
}

std::string hex64(uint64_t v) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(v));
  return buf;
}

struct Manifest {
  struct Valid {
    std::string file_hash;
    uint32_t chunk_count = 0;
    std::map<uint32_t, std::pair<uint64_t, std::string>> chunks;  // id -> (raw size, raw hash)
  };
  std::map<std::string, Valid> valid;
  std::map<std::string, std::string> malformed;  // file -> "CALF-Ennn"
};

Manifest read_manifest() {
  Manifest m;
  std::ifstream in(suite_dir() / "manifest.txt");
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream ls(line);
    std::string type, file;
    ls >> type >> file;
    if (type == "valid") {
      ls >> m.valid[file].file_hash >> m.valid[file].chunk_count;
    } else if (type == "chunk") {
      uint32_t id;
      uint64_t size;
      std::string hash;
      ls >> id >> size >> hash;
      m.valid[file].chunks[id] = {size, hash};
    } else if (type == "malformed") {
      ls >> m.malformed[file];
    }
  }
  return m;
}

// The manifest text for the committed valid files and a malformed corpus.
std::string manifest_text(const std::vector<std::string>& valid_names,
                          const std::vector<corpus::Malformed>& malformed) {
  std::ostringstream os;
  os << "# calf container conformance manifest (format/SPEC.md, tests/conformance/README.md).\n"
        "#   valid FILE FILE_XXH3 CHUNK_COUNT\n"
        "#   chunk FILE ID RAW_SIZE RAW_XXH3     decoded chunk: size and XXH3-64 (hex)\n"
        "#   malformed FILE ERROR_ID             the first error a reader must report\n";
  for (const auto& name : valid_names) {
    const Bytes file = read_file(suite_dir() / name);
    auto r = Reader::open(memory_source(std::span<const uint8_t>(file)));
    EXPECT_TRUE(r.ok()) << name << ": " << r.status().to_string();
    if (!r.ok()) continue;
    os << "valid " << name << " " << hex64(hash64(file)) << " " << r->chunks().size() << "\n";
    for (uint32_t i = 0; i < r->chunks().size(); ++i) {
      auto raw = r->read_chunk(i);
      EXPECT_TRUE(raw.ok());
      os << "chunk " << name << " " << i << " " << raw->size() << " " << hex64(hash64(*raw))
         << "\n";
    }
  }
  for (const auto& m : malformed)
    os << "malformed malformed/" << m.name << ".calf " << error_code_string(m.expected) << "\n";
  return os.str();
}

const std::vector<std::string> kValidNames = {"valid/v1_frozen.calf", "valid/empty.calf",
                                              "valid/v1_1_compressed_directory.calf"};

TEST(ContainerConformanceTest, GeneratorReproducesTheCommittedCorpus) {
  const bool write = std::getenv("CALF_CONFORMANCE_WRITE") != nullptr;
  if (write) {
    // Valid files are written once; later runs must never replace a frozen file.
    fs::create_directories(suite_dir() / "valid");
    fs::create_directories(suite_dir() / "malformed");
    if (!fs::exists(suite_dir() / kValidNames[0]))
      write_file(suite_dir() / kValidNames[0], *corpus::make_frozen_v1());
    if (!fs::exists(suite_dir() / kValidNames[1]))
      write_file(suite_dir() / kValidNames[1], *corpus::make_empty());
    if (!fs::exists(suite_dir() / kValidNames[2]))
      write_file(suite_dir() / kValidNames[2], *corpus::make_frozen_v1(true));
  }
  const Bytes frozen = read_file(suite_dir() / kValidNames[0]);
  const Bytes frozen_1_1 = read_file(suite_dir() / kValidNames[2]);
  ASSERT_FALSE(frozen.empty()) << "run once with CALF_CONFORMANCE_WRITE=1 to create the suite";
  ASSERT_FALSE(frozen_1_1.empty()) << "run once with CALF_CONFORMANCE_WRITE=1 to add the 1.1 file";
  auto malformed = corpus::make_malformed(frozen);
  ASSERT_GT(malformed.size(), 40u);
  for (auto& m : corpus::make_malformed_compressed_directory(frozen_1_1))
    malformed.push_back(std::move(m));
  if (write) {
    for (const auto& e : fs::directory_iterator(suite_dir() / "malformed")) fs::remove(e.path());
    for (const auto& m : malformed)
      write_file(suite_dir() / "malformed" / (m.name + ".calf"), m.bytes);
    std::ofstream(suite_dir() / "manifest.txt") << manifest_text(kValidNames, malformed);
  }
  // The committed corpus is exactly what the generator derives from the committed frozen file.
  size_t committed = 0;
  for (const auto& e : fs::directory_iterator(suite_dir() / "malformed")) (void)e, ++committed;
  EXPECT_EQ(committed, malformed.size());
  for (const auto& m : malformed) {
    EXPECT_EQ(read_file(suite_dir() / "malformed" / (m.name + ".calf")), m.bytes) << m.name;
    EXPECT_EQ(corpus::first_error(m.bytes).id(), m.expected)
        << m.name << ": " << corpus::first_error(m.bytes).to_string();
  }
  std::ifstream in(suite_dir() / "manifest.txt");
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_EQ(text.str(), manifest_text(kValidNames, malformed));
  // Today's writer still produces a file with the frozen file's contents (bytes may differ
  // with another zstd / liblzma version, so the comparison is of decoded contents).
  for (const bool compressed : {false, true}) {
    const Bytes fresh = *corpus::make_frozen_v1(compressed);
    const Bytes& frozen_file = compressed ? frozen_1_1 : frozen;
    auto a = Reader::open(memory_source(std::span<const uint8_t>(frozen_file)));
    auto b = Reader::open(memory_source(std::span<const uint8_t>(fresh)));
    ASSERT_TRUE(a.ok() && b.ok());
    EXPECT_EQ(a->metadata().size(), b->metadata().size());
    ASSERT_EQ(a->chunks().size(), b->chunks().size());
    for (uint32_t i = 0; i < a->chunks().size(); ++i)
      EXPECT_EQ(*a->read_chunk(i), *b->read_chunk(i));
  }
}

TEST(ContainerConformanceTest, RunnerValidFilesVerifyAndDecodeToManifestHashes) {
  const Manifest m = read_manifest();
  ASSERT_FALSE(m.valid.empty());
  for (const auto& [name, v] : m.valid) {
    const Bytes file = read_file(suite_dir() / name);
    EXPECT_LE(file.size(), 64u * 1024) << name << " must stay small";
    EXPECT_EQ(hex64(hash64(file)), v.file_hash) << name << " changed: valid files are frozen";
    auto r = Reader::open(suite_dir() / name);
    ASSERT_TRUE(r.ok()) << name << ": " << r.status().to_string();
    EXPECT_TRUE(r->verify().empty()) << name;
    ASSERT_EQ(r->chunks().size(), v.chunk_count) << name;
    ASSERT_EQ(v.chunks.size(), v.chunk_count) << name;
    for (const auto& [id, want] : v.chunks) {
      auto raw = r->read_chunk(id);
      ASSERT_TRUE(raw.ok()) << name << " chunk " << id << ": " << raw.status().to_string();
      EXPECT_EQ(raw->size(), want.first) << name << " chunk " << id;
      EXPECT_EQ(hex64(hash64(*raw)), want.second) << name << " chunk " << id;
    }
  }
}

TEST(ContainerConformanceTest, RunnerMalformedFilesReportTheirErrorIds) {
  const Manifest m = read_manifest();
  ASSERT_GT(m.malformed.size(), 40u);
  for (const auto& [name, id] : m.malformed) {
    const Bytes file = read_file(suite_dir() / name);
    auto r = Reader::open(suite_dir() / name);
    Status first = r.ok() ? Status() : r.status();
    if (r.ok()) {
      auto problems = r->verify();
      if (!problems.empty()) first = problems[0];
    }
    EXPECT_FALSE(first.ok()) << name << " was accepted";
    EXPECT_EQ(error_code_string(first.id()), id) << name << ": " << first.to_string();
  }
}

TEST(ContainerConformanceTest, FrozenV1ReadsItsKnownContents) {
  auto r = Reader::open(suite_dir() / "valid" / "v1_frozen.calf");
  ASSERT_TRUE(r.ok()) << r.status().to_string();
  EXPECT_EQ(r->header().version_major, 1);
  EXPECT_EQ(r->header().version_minor, 0);
  ASSERT_EQ(r->tracks().size(), 5u);
  const auto& lf = std::get<LightfieldTrackHeader>(r->tracks()[0].header);
  EXPECT_EQ(lf.frame_count, 48u);
  EXPECT_EQ(lf.fps_numerator, 24000u);
  EXPECT_EQ(lf.fps_denominator, 1001u);
  EXPECT_EQ(lf.view_count, 3u);
  EXPECT_EQ(lf.face_size, 128u);
  EXPECT_EQ(lf.colour_format, static_cast<uint16_t>(PixelFormat::kBc1));
  EXPECT_EQ(std::get<TilesTrackHeader>(r->tracks()[1].header).tile_count, 12u);
  EXPECT_EQ(std::get<SurfelsTrackHeader>(r->tracks()[2].header).surfel_count, 5000u);
  EXPECT_EQ(std::get<MeshTrackHeader>(r->tracks()[3].header).triangle_count, 500u);
  EXPECT_FALSE(r->tracks()[4].known);  // the unknown optional track is skipped
  EXPECT_EQ(r->tracks()[4].record.kind, 0x7777);
  ASSERT_NE(r->find_metadata("title"), nullptr);
  EXPECT_EQ(*r->find_metadata("title"), "frozen v1 \xe2\x80\x94 \xe2\x9c\x93");
  ASSERT_EQ(r->chunks().size(), std::size(corpus::kFrozenSizes));
  for (uint32_t i = 0; i < r->chunks().size(); ++i) {
    EXPECT_EQ(*r->read_chunk(i), corpus::pattern(i, corpus::kFrozenSizes[i])) << i;
    EXPECT_EQ(r->chunks()[i].compression, i % 3);
    EXPECT_EQ(r->chunks()[i].keys.region, i * 7);
  }
}

// The 1.1 file holds the frozen 1.0 file's directory, compressed: the same header fields but the
// version and feature bit, the same metadata, tracks and chunk entries up to the offsets.
TEST(ContainerConformanceTest, CompressedDirectoryFileHoldsTheFrozenV1Directory) {
  auto a = Reader::open(suite_dir() / "valid" / "v1_frozen.calf");
  auto b = Reader::open(suite_dir() / "valid" / "v1_1_compressed_directory.calf");
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_EQ(a->header().version_minor, 0);
  EXPECT_EQ(a->header().required_features, 0u);
  EXPECT_EQ(b->header().version_minor, 1);
  EXPECT_EQ(b->header().required_features, kFeatureCompressedDirectory);
  EXPECT_EQ(b->directory_body_size(), a->directory_body_size());
  EXPECT_LT(b->header().directory_size, a->header().directory_size);
  ASSERT_EQ(a->metadata().size(), b->metadata().size());
  for (size_t i = 0; i < a->metadata().size(); ++i) {
    EXPECT_EQ(a->metadata()[i].key, b->metadata()[i].key);
    EXPECT_EQ(a->metadata()[i].value, b->metadata()[i].value);
  }
  ASSERT_EQ(a->tracks().size(), b->tracks().size());
  for (size_t i = 0; i < a->tracks().size(); ++i)
    EXPECT_EQ(a->tracks()[i].record.header, b->tracks()[i].record.header);
  ASSERT_EQ(a->chunks().size(), b->chunks().size());
  for (size_t i = 0; i < a->chunks().size(); ++i) {
    EXPECT_EQ(a->chunks()[i].keys, b->chunks()[i].keys) << i;
    EXPECT_EQ(a->chunks()[i].raw_size, b->chunks()[i].raw_size) << i;
    EXPECT_EQ(a->chunks()[i].compression, b->chunks()[i].compression) << i;
  }
}

// The calf-verify command (a build dependency, CALF_VERIFY_EXE) over the corpus, checking the
// container alone (--container-only: the corpus's tracks are placeholder bytes): exit 0 on valid
// files; exit 1, naming the expected id, on malformed ones.
TEST(ContainerConformanceTest, CalfVerifyCommandAgrees) {
  const fs::path exe = CALF_VERIFY_EXE;
  ASSERT_TRUE(fs::exists(exe)) << exe << " is not built";
  const Manifest m = read_manifest();
  auto run = [&](const std::string& name, std::string* out) {
    return testing_support::run_command(
        "'" + exe.string() + "' --container-only '" + (suite_dir() / name).string() + "'", out);
  };
  for (const auto& [name, v] : m.valid) {
    std::string out;
    EXPECT_EQ(run(name, &out), 0) << name << ": " << out;
  }
  for (const auto& [name, id] : m.malformed) {
    std::string out;
    EXPECT_EQ(run(name, &out), 1) << name << ": " << out;
    EXPECT_NE(out.find(id), std::string::npos) << name << " should report " << id << ": " << out;
  }
}

}  // namespace
}  // namespace calf::container
