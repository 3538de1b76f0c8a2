// The surfels track end to end (format/SPEC.md §11.3): a mesh track of the mesh test scene
// (mesh_scene.h) and a surfels track of synthetic per-prototype buffers in one clip, encoded by
// encode_surfels_track, decoded by SurfelsTrack and compared with the input within the
// quantisation bounds of §11.3.3 (computed here from the input, not from the encoder); prefixes
// read only their levels; determinism for any thread count; bad input and damaged chunks give
// their ids; and the frozen conformance clips of tests/conformance/surfels/ still decode to their
// hashes.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

#include "calf/decoder/mesh_track.h"
#include "calf/decoder/surfels_track.h"
#include "calf/decoder/surfels_verify.h"
#include "calf/encoder/mesh_encode.h"
#include "calf/encoder/surfels_encode.h"
#include "calf/format/colour.h"
#include "calf/format/container.h"
#include "mesh_scene.h"

namespace calf {
namespace {

using container::Compression;
using container::SurfelsStream;
using decoder::SurfelBuffer;
using decoder::SurfelsTrack;
using encoder::SurfelPrototypeInput;
using encoder::SurfelsTrackInput;

// splitmix64: the same numbers on every machine (std distributions are not portable).
struct Rng {
  uint64_t s;
  uint64_t next() {
    uint64_t z = (s += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
  }
  double uniform() { return static_cast<double>(next() >> 11) * 0x1p-53; }
};

// n surfels on a sphere in random order (a blue-noise order is as uncorrelated from one surfel to
// the next), normals scaled by 2.5 (the encoder normalises), colours smooth over the sphere.
SurfelPrototypeInput sphere_surfels(uint32_t n, uint64_t seed, float radius, float cx) {
  SurfelPrototypeInput in;
  Rng rng{seed};
  for (uint32_t i = 0; i < n; ++i) {
    const double z = 2 * rng.uniform() - 1, phi = 2 * M_PI * rng.uniform();
    const double s = std::sqrt(1 - z * z);
    const double d[3] = {s * std::cos(phi), s * std::sin(phi), z};
    for (int c = 0; c < 3; ++c) {
      in.positions.push_back(static_cast<float>((c == 0 ? cx : 0) + radius * d[c]));
      in.normals.push_back(static_cast<float>(2.5 * d[c]));
      in.colours.push_back(static_cast<float>(0.5 + 0.5 * d[(c + 1) % 3]));
    }
  }
  if (n) {
    in.prefix_count = std::min<uint32_t>(n, 100);
    in.prefix_radius = radius * 0.3f;
  }
  return in;
}

// Per prototype of the mesh test scene: a buffer of 3 levels, none, one surfel, one whole level,
// and the rest small (colour_is_base on one).
SurfelsTrackInput test_input(uint32_t prototypes, bool big = true) {
  SurfelsTrackInput input;
  input.mesh_track = 0;
  input.frame_count = 3;
  const uint32_t counts[] = {big ? 3000u : 1500u, 0, 1, big ? 1024u : 300u};
  for (uint32_t p = 0; p < prototypes; ++p) {
    const uint32_t n = p < 4 ? counts[p] : 50;
    input.prototypes.push_back(sphere_surfels(n, 1000 + p, 0.5f + 0.25f * p, 2.0f * p));
  }
  input.prototypes[3].colour_is_base = true;
  return input;
}

std::vector<uint8_t> encode(const SurfelsTrackInput& input,
                            encoder::SurfelsEncodeOptions options = {},
                            encoder::SurfelsEncodeStats* stats = nullptr, bool spheres = false) {
  std::vector<uint8_t> file;
  auto w = container::Writer::create(container::memory_sink(&file), options.levels);
  EXPECT_TRUE(w.ok());
  encoder::MeshEncodeOptions mesh_options;
  mesh_options.supercompression = options.supercompression;
  mesh_options.levels = options.levels;
  Status st = encoder::encode_mesh_track(test::make_mesh_test_scene(3, spheres), nullptr,
                                         mesh_options, &*w);
  EXPECT_TRUE(st.ok()) << st.to_string();
  st = encoder::encode_surfels_track(input, options, &*w, stats);
  EXPECT_TRUE(st.ok()) << st.to_string();
  EXPECT_TRUE(w->finish().ok());
  return file;
}

encoder::SurfelsEncodeOptions opts(Compression c, uint32_t threads = 1) {
  encoder::SurfelsEncodeOptions o;
  o.supercompression = c;
  o.threads = threads;
  return o;
}

container::Reader open_reader(const std::vector<uint8_t>& file) {
  auto r = container::Reader::open(container::memory_source(std::span<const uint8_t>(file)));
  EXPECT_TRUE(r.ok()) << r.status().to_string();
  return std::move(*r);
}

uint32_t mesh_prototypes(bool spheres = false) {
  const auto file = encode(SurfelsTrackInput{}, {}, nullptr, spheres);
  const auto reader = open_reader(file);
  auto mesh = decoder::MeshTrack::open(reader, 0);
  EXPECT_TRUE(mesh.ok());
  return mesh.ok() ? mesh->prototype_count() : 0;
}

double angle(const float* a, const float* b) {
  const double dot = double{a[0]} * b[0] + double{a[1]} * b[1] + double{a[2]} * b[2];
  const double la = std::sqrt(double{a[0]} * a[0] + double{a[1]} * a[1] + double{a[2]} * a[2]);
  const double lb = std::sqrt(double{b[0]} * b[0] + double{b[1]} * b[1] + double{b[2]} * b[2]);
  return std::acos(std::clamp(dot / (la * lb), -1.0, 1.0));
}

// Checks a decoded buffer against its input within §11.3.3's bounds; raises *worst to the
// largest normal angle seen.
void expect_within_bounds(const SurfelBuffer& got, const SurfelPrototypeInput& in,
                          const surfels::PrototypeRecord& r, double* worst) {
  EXPECT_EQ(got.size(), in.size());
  for (int c = 0; c < 3; ++c) {
    // The box is the input's tight bounds.
    float lo = in.size() ? in.positions[c] : 0, hi = lo;
    for (size_t i = 0; i < in.size(); ++i) {
      lo = std::min(lo, in.positions[3 * i + c]);
      hi = std::max(hi, in.positions[3 * i + c]);
    }
    EXPECT_EQ(r.box_min[c], lo);
    EXPECT_EQ(r.box_max[c], hi);
  }
  for (size_t i = 0; i < std::min(got.size(), in.size()); ++i) {
    for (int c = 0; c < 3; ++c) {
      const double step = (double{r.box_max[c]} - r.box_min[c]) / 65535;
      const double tol =
          0.5 * step + 1.2e-7 * std::max(std::fabs(r.box_min[c]), std::fabs(r.box_max[c]));
      ASSERT_LE(std::fabs(double{got.positions[3 * i + c]} - in.positions[3 * i + c]), tol)
          << "surfel " << i << " axis " << c;
      ASSERT_GE(got.positions[3 * i + c], r.box_min[c]);
      ASSERT_LE(got.positions[3 * i + c], r.box_max[c]);
      // The colour is the nearest sRGB level: its neighbours are no nearer.
      const float want = in.colours[3 * i + c], have = got.colours[3 * i + c];
      const uint8_t b = srgb8_from_linear(have);
      ASSERT_EQ(linear_from_srgb8(b), have) << "a decoded colour is an sRGB level";
      for (int d : {-1, 1}) {
        if (b + d < 0 || b + d > 255) continue;
        ASSERT_LE(std::fabs(have - want),
                  std::fabs(linear_from_srgb8(static_cast<uint8_t>(b + d)) - want))
            << "surfel " << i << " colour " << c;
      }
    }
    const float* n = &got.normals[3 * i];
    EXPECT_NEAR(double{n[0]} * n[0] + double{n[1]} * n[1] + double{n[2]} * n[2], 1.0, 1e-6);
    *worst = std::max(*worst, angle(n, &in.normals[3 * i]));
  }
}

TEST(SurfelsTrack, RoundTripWithinTheQuantisationBounds) {
  const uint32_t np = mesh_prototypes();
  ASSERT_GE(np, 4u);
  const SurfelsTrackInput input = test_input(np);
  encoder::SurfelsEncodeStats stats;
  const auto file = encode(input, {}, &stats);
  const auto reader = open_reader(file);
  auto track = SurfelsTrack::open(reader, 1);
  ASSERT_TRUE(track.ok()) << track.status().to_string();
  auto mesh = decoder::MeshTrack::open(reader, 0);
  ASSERT_TRUE(mesh.ok());
  EXPECT_TRUE(track->check_pairing(*mesh).ok());
  EXPECT_EQ(track->mesh_track(), 0);
  EXPECT_EQ(track->prototype_count(), np);
  const uint64_t total = 3000 + 0 + 1 + 1024 + 50 * (np - 4);
  EXPECT_EQ(track->header().object_count, np);
  EXPECT_EQ(track->header().surfel_count, total);
  EXPECT_EQ(track->header().frame_count, 3u);
  EXPECT_EQ(reader.tracks()[1].record.flags, 0) << "a surfels track is optional";
  EXPECT_EQ(stats.surfels, total);
  EXPECT_EQ(stats.prototypes_with_surfels, np - 1);
  // Levels by hand: 3000 -> [0,1024) [1024,2048) [2048,3000); 1 -> 1; 1024 -> 1; 50 -> 1.
  EXPECT_EQ(stats.level_chunks, 3u + 1 + 1 + (np - 4));
  EXPECT_EQ(stats.surfels_raw, 13 * total);
  EXPECT_EQ(stats.plain_bytes, 36 * total);
  EXPECT_EQ(track->record(3).flags, surfels::kColourIsBase);
  EXPECT_EQ(track->record(0).prefix_count, 100u);
  EXPECT_EQ(track->record(0).prefix_radius, 0.5f * 0.3f);
  double worst = 0;
  for (uint32_t p = 0; p < np; ++p) {
    SCOPED_TRACE("prototype " + std::to_string(p));
    SurfelBuffer got;
    ASSERT_TRUE(track->prototype(p, &got).ok());
    expect_within_bounds(got, input.prototypes[p], track->record(p), &worst);
  }
  // Octahedral u16 with the best of four codes: SPEC §11.3.3 states 5e-5 rad.
  EXPECT_LT(worst, 5e-5);
  EXPECT_GT(worst, 1e-6) << "the bound is not vacuous";
  std::printf("largest normal error: %.3g rad\n", worst);
  // The prototype without surfels.
  SurfelBuffer none;
  ASSERT_TRUE(track->prototype(1, &none).ok());
  EXPECT_EQ(none.size(), 0u);
  EXPECT_EQ(surfels::prefix_for_radius(track->record(1), 0.01), 0u);
  // Out-of-range requests are errors.
  EXPECT_EQ(track->prototype(np, &none).id(), ErrorId::kInvalidArgument);
  EXPECT_EQ(track->prefix(0, 3001, &none).id(), ErrorId::kInvalidArgument);
  EXPECT_EQ(SurfelsTrack::open(reader, 0).status().id(), ErrorId::kInvalidArgument);
  EXPECT_EQ(SurfelsTrack::open(reader, 2).status().id(), ErrorId::kInvalidArgument);
}

TEST(SurfelsTrack, RandomNormalsStayWithinTheStatedAngle) {
  // Directions over the whole sphere, the poles, the equator and the octahedron's folds included.
  SurfelsTrackInput input;
  SurfelPrototypeInput in;
  Rng rng{7};
  const float special[][3] = {{0, 0, 1},  {0, 0, -1}, {1, 0, 0},       {-1, 0, 0},  {0, 1, 0},
                              {0, -1, 0}, {1, 1, 0},  {1, -1, -1e-7f}, {-1, -1, -1}};
  for (const auto& n : special) in.normals.insert(in.normals.end(), n, n + 3);
  for (int i = 0; i < 20000; ++i) {
    for (int c = 0; c < 3; ++c) in.normals.push_back(static_cast<float>(2 * rng.uniform() - 1));
  }
  const size_t n = in.normals.size() / 3;
  in.positions.assign(3 * n, 1.0f);
  in.colours.assign(3 * n, 0.5f);
  in.prefix_count = 1;
  in.prefix_radius = 1;
  surfels::PrototypeRecord r;
  const surfels::SurfelCodes codes = encoder::quantise_surfels(in, r);
  double worst = 0;
  for (size_t i = 0; i < n; ++i) {
    float d[3];
    surfels::decode_normal(codes.normals[2 * i], codes.normals[2 * i + 1], d);
    worst = std::max(worst, angle(d, &in.normals[3 * i]));
  }
  EXPECT_LT(worst, 5e-5);
  EXPECT_GT(worst, 3e-5) << "the sample comes near the bound";
  std::printf("largest normal error over %zu directions: %.3g rad\n", n, worst);
}

container::ChunkQuery level_query(uint32_t prototype, uint32_t level) {
  container::ChunkQuery q;
  q.track = 1;
  q.stream = static_cast<uint16_t>(SurfelsStream::kSurfels);
  q.region = prototype;
  q.layer = level;
  return q;
}

TEST(SurfelsTrack, PrefixReadsOnlyItsLevels) {
  const uint32_t np = mesh_prototypes();
  const SurfelsTrackInput input = test_input(np);
  std::vector<uint8_t> file = encode(input, opts(Compression::kNone));
  // Damage the stored bytes of prototype 0's level 2 (surfels [2048, 3000)): the chunk's hash
  // fails when it is read, so only a reader that fetches it sees the damage.
  {
    const auto reader = open_reader(file);
    const auto ids = reader.find_chunks(level_query(0, 2));
    ASSERT_EQ(ids.size(), 1u);
    file[reader.chunks()[ids[0]].offset + 5] ^= 0x40;
  }
  const auto reader = open_reader(file);
  auto track = SurfelsTrack::open(reader, 1);
  ASSERT_TRUE(track.ok()) << track.status().to_string();
  SurfelBuffer whole, part;
  EXPECT_EQ(track->prototype(0, &whole).id(), ErrorId::kContainerChunkHash);
  ASSERT_TRUE(track->prefix(0, 2048, &part).ok()) << "levels 0 and 1 only";
  EXPECT_EQ(part.size(), 2048u);
  EXPECT_EQ(track->prefix(0, 2049, &part).id(), ErrorId::kContainerChunkHash);
  // Prefixes are the first surfels of the whole buffer (of an undamaged prototype: 3).
  SurfelBuffer full;
  ASSERT_TRUE(track->prototype(3, &full).ok());
  for (uint32_t count : {0u, 1u, 77u, 1023u, 1024u}) {
    ASSERT_TRUE(track->prefix(3, count, &part).ok());
    ASSERT_EQ(part.size(), count);
    EXPECT_TRUE(std::equal(part.positions.begin(), part.positions.end(), full.positions.begin()));
    EXPECT_TRUE(std::equal(part.normals.begin(), part.normals.end(), full.normals.begin()));
    EXPECT_TRUE(std::equal(part.colours.begin(), part.colours.end(), full.colours.begin()));
  }
}

TEST(SurfelsTrack, DeterministicForThreadsAndSchemesAndStableUnderReencoding) {
  const uint32_t np = mesh_prototypes();
  const SurfelsTrackInput input = test_input(np);
  EXPECT_EQ(encode(input, opts(Compression::kZstd, 1)), encode(input, opts(Compression::kZstd, 4)));
  EXPECT_EQ(encode(input, opts(Compression::kZstd, 0)), encode(input, opts(Compression::kZstd, 3)));
  std::vector<std::string> first;
  for (Compression c : {Compression::kZstd, Compression::kLzma2, Compression::kNone}) {
    const auto file = encode(input, opts(c));
    const auto reader = open_reader(file);
    const auto r = decoder::verify_surfels_track(reader, 1, true, 10);
    ASSERT_TRUE(r.problems.empty()) << r.problems[0].to_string();
    ASSERT_EQ(r.hash_lines.size(), np);
    EXPECT_EQ(r.prototypes_decoded, np);
    if (first.empty()) {
      first = r.hash_lines;
    } else {
      EXPECT_EQ(r.hash_lines, first);
    }
  }
  // Decoded surfels lie on the grid: encoding them again gives the same track bytes.
  const auto file = encode(input);
  const auto reader = open_reader(file);
  auto track = SurfelsTrack::open(reader, 1);
  ASSERT_TRUE(track.ok());
  SurfelsTrackInput again = input;
  for (uint32_t p = 0; p < np; ++p) {
    SurfelBuffer b;
    ASSERT_TRUE(track->prototype(p, &b).ok());
    again.prototypes[p].positions = b.positions;
    again.prototypes[p].normals = b.normals;
    again.prototypes[p].colours = b.colours;
  }
  EXPECT_EQ(encode(again), file);
}

TEST(SurfelsTrack, BadInputIsRefused) {
  const uint32_t np = mesh_prototypes();
  const SurfelsTrackInput good = test_input(np, false);
  EXPECT_TRUE(encoder::validate_surfels_input(good).ok());
  std::vector<std::pair<const char*, std::function<void(SurfelsTrackInput&)>>> cases = {
      {"short normals", [](auto& in) { in.prototypes[0].normals.pop_back(); }},
      {"NaN position", [](auto& in) { in.prototypes[0].positions[4] = std::nanf(""); }},
      {"far position", [](auto& in) { in.prototypes[2].positions[0] = 2e12f; }},
      {"zero normal",
       [](auto& in) { std::fill_n(in.prototypes[0].normals.begin() + 30, 3, 0.0f); }},
      {"inf normal", [](auto& in) { in.prototypes[0].normals[7] = INFINITY; }},
      {"colour above 1", [](auto& in) { in.prototypes[3].colours[5] = 1.5f; }},
      {"colour NaN", [](auto& in) { in.prototypes[3].colours[5] = std::nanf(""); }},
      {"p_m above N", [](auto& in) { in.prototypes[2].prefix_count = 2; }},
      {"p_m zero", [](auto& in) { in.prototypes[0].prefix_count = 0; }},
      {"r_m zero", [](auto& in) { in.prototypes[0].prefix_radius = 0; }},
      {"r_m NaN", [](auto& in) { in.prototypes[0].prefix_radius = std::nanf(""); }},
      {"empty with p_m", [](auto& in) { in.prototypes[1].prefix_count = 1; }},
      {"mesh track 256", [](auto& in) { in.mesh_track = 256; }},
  };
  for (const auto& [name, edit] : cases) {
    SurfelsTrackInput bad = good;
    edit(bad);
    std::vector<uint8_t> file;
    auto w = container::Writer::create(container::memory_sink(&file));
    ASSERT_TRUE(w.ok());
    EXPECT_EQ(encoder::encode_surfels_track(bad, {}, &*w).id(), ErrorId::kSurfelsInput) << name;
    ASSERT_TRUE(w->finish().ok());
    EXPECT_TRUE(open_reader(file).tracks().empty()) << name << ": nothing written";
  }
  std::vector<uint8_t> file;
  auto w = container::Writer::create(container::memory_sink(&file));
  ASSERT_TRUE(w.ok());
  EXPECT_EQ(encoder::encode_surfels_track(good, opts(Compression::kZstd, 300), &*w).id(),
            ErrorId::kEncoderOption);
}

// ---- Damaged chunks: the file is rebuilt with valid hashes, so the track's parser sees them ----

struct Edit {
  std::function<void(const container::ChunkKeys&, std::vector<uint8_t>&, bool& drop)> chunk;
  std::function<void(container::SurfelsTrackHeader&)> header;
  std::function<void(container::ChunkKeys&)> keys;  // applied to surfels chunks
  bool duplicate_last = false;
  bool drop_mesh_index = false;
};

std::vector<uint8_t> rebuild(const std::vector<uint8_t>& file, const Edit& edit) {
  const auto reader = open_reader(file);
  std::vector<uint8_t> out;
  auto w = container::Writer::create(container::memory_sink(&out));
  EXPECT_TRUE(w.ok());
  EXPECT_TRUE(w->add_track(std::get<container::MeshTrackHeader>(reader.tracks()[0].header)).ok());
  auto h = std::get<container::SurfelsTrackHeader>(reader.tracks()[1].header);
  if (edit.header) edit.header(h);
  EXPECT_TRUE(w->add_track(h, 0).ok());
  std::vector<uint8_t> last;
  container::ChunkKeys last_keys;
  for (uint32_t id = 0; id < reader.chunks().size(); ++id) {
    auto raw = reader.read_chunk(id);
    EXPECT_TRUE(raw.ok());
    container::ChunkKeys keys = reader.chunks()[id].keys;
    bool drop = false;
    if (keys.track == 1) {
      if (edit.chunk) edit.chunk(keys, *raw, drop);
      if (edit.keys) edit.keys(keys);
    } else if (edit.drop_mesh_index && keys.stream == 0) {
      drop = true;
    }
    if (drop) continue;
    EXPECT_TRUE(w->add_chunk(keys, *raw, Compression::kNone).ok());
    last = *raw;
    last_keys = keys;
  }
  if (edit.duplicate_last) {
    EXPECT_TRUE(w->add_chunk(last_keys, last, Compression::kNone).ok());
  }
  EXPECT_TRUE(w->finish().ok());
  return out;
}

// The first problem of verifying the damaged file's surfels track (open's, pairing's, decoding's).
ErrorId damage_id(const std::vector<uint8_t>& file) {
  const auto reader = open_reader(file);
  const auto r = decoder::verify_surfels_track(reader, 1, false, 10);
  return r.problems.empty() ? ErrorId::kOk : r.problems[0].id();
}

bool is(const container::ChunkKeys& k, SurfelsStream s, uint32_t region, uint32_t layer = 0) {
  return k.stream == static_cast<uint16_t>(s) && k.region == region && k.layer == layer;
}

void put32(std::vector<uint8_t>& r, size_t at, uint32_t v) {
  for (int i = 0; i < 4; ++i) r[at + i] = static_cast<uint8_t>(v >> (8 * i));
}

TEST(SurfelsTrack, DamagedChunksGiveTheTrackIds) {
  const uint32_t np = mesh_prototypes();
  const auto good = encode(test_input(np, false));
  ASSERT_EQ(damage_id(rebuild(good, {})), ErrorId::kOk) << "rebuilding alone changes nothing";
  // Offsets in the index chunk (§11.3.2): 16 bytes of head, then 40 per prototype.
  constexpr size_t kRecords = 16;
  const auto rec = [](uint32_t p, size_t field) { return kRecords + 40 * p + field; };
  auto on = [](SurfelsStream s, uint32_t region, uint32_t layer,
               std::function<void(std::vector<uint8_t>&)> f) {
    Edit e;
    e.chunk = [=](const container::ChunkKeys& k, std::vector<uint8_t>& raw, bool&) {
      if (is(k, s, region, layer)) f(raw);
    };
    return e;
  };
  const auto index = [&](std::function<void(std::vector<uint8_t>&)> f) {
    return on(SurfelsStream::kIndex, 0, 0, f);
  };
  struct Case {
    const char* name;
    Edit edit;
    ErrorId id;
  };
  std::vector<Case> cases = {
      {"layout version 2", index([](auto& r) { r[0] = 2; }), ErrorId::kSurfelsUnsupported},
      {"index flags", index([](auto& r) { r[4] = 1; }), ErrorId::kSurfelsUnsupported},
      {"index truncated", index([](auto& r) { r.pop_back(); }), ErrorId::kSurfelsChunk},
      {"index trailing byte", index([](auto& r) { r.push_back(0); }), ErrorId::kSurfelsChunk},
      {"prototype count huge", index([](auto& r) { put32(r, 12, (1u << 20) + 1); }),
       ErrorId::kSurfelsLimit},
      {"surfel count above 2^26", index([&](auto& r) { put32(r, rec(0, 0), (1u << 26) + 1); }),
       ErrorId::kSurfelsLimit},
      {"prototype flag 2", index([&](auto& r) { r[rec(0, 4)] = 2; }), ErrorId::kSurfelsUnsupported},
      {"p_m above N", index([&](auto& r) { put32(r, rec(2, 8), 2); }), ErrorId::kSurfelsValue},
      {"p_m of an empty prototype", index([&](auto& r) { put32(r, rec(1, 8), 1); }),
       ErrorId::kSurfelsValue},
      {"r_m negative", index([&](auto& r) { r[rec(0, 15)] |= 0x80; }), ErrorId::kSurfelsValue},
      {"r_m NaN", index([&](auto& r) { put32(r, rec(0, 12), 0x7fc00000u); }),
       ErrorId::kSurfelsValue},
      {"box NaN", index([&](auto& r) { put32(r, rec(0, 16), 0x7fc00000u); }),
       ErrorId::kSurfelsValue},
      {"box inverted", index([&](auto& r) { put32(r, rec(0, 28), 0xc2c80000u); }),  // -100
       ErrorId::kSurfelsValue},
      {"box beyond 1e12", index([&](auto& r) { put32(r, rec(0, 28), 0x7f000000u); }),
       ErrorId::kSurfelsValue},
      {"surfel count + 1", index([&](auto& r) { r[rec(3, 0)] += 1; }), ErrorId::kSurfelsChunk},
      {"mesh track is itself", index([](auto& r) { r[8] = 1; }), ErrorId::kSurfelsPairing},
      {"mesh track 9", index([](auto& r) { r[8] = 9; }), ErrorId::kSurfelsPairing},
      {"level short", on(SurfelsStream::kSurfels, 0, 1, [](auto& r) { r.pop_back(); }),
       ErrorId::kSurfelsChunk},
  };
  const auto drop = [](SurfelsStream s, uint32_t region, uint32_t layer) {
    Edit e;
    e.chunk = [=](const container::ChunkKeys& k, std::vector<uint8_t>&, bool& d) {
      d = is(k, s, region, layer);
    };
    return e;
  };
  cases.push_back({"level missing", drop(SurfelsStream::kSurfels, 0, 1), ErrorId::kSurfelsChunk});
  cases.push_back({"index missing", drop(SurfelsStream::kIndex, 0, 0), ErrorId::kOk});
  Edit twice;
  twice.duplicate_last = true;
  cases.push_back({"level twice", twice, ErrorId::kSurfelsChunk});
  const auto rekey = [](std::function<void(container::ChunkKeys&)> f) {
    Edit e;
    e.keys = f;
    return e;
  };
  cases.push_back({"layer beyond the levels", rekey([](auto& k) {
                     if (k.stream == 1 && k.region == 2) k.layer = 1;
                   }),
                   ErrorId::kSurfelsChunk});
  cases.push_back({"region beyond the prototypes", rekey([&](auto& k) {
                     if (k.stream == 1 && k.region == np - 1) k.region = np;
                   }),
                   ErrorId::kSurfelsChunk});
  cases.push_back({"view key set", rekey([](auto& k) {
                     if (k.stream == 1) k.view = 1;
                   }),
                   ErrorId::kSurfelsChunk});
  cases.push_back({"index layer set", rekey([](auto& k) {
                     if (k.stream == 0) k.layer = 1;
                   }),
                   ErrorId::kSurfelsChunk});
  Edit count;
  count.header = [](container::SurfelsTrackHeader& h) { h.surfel_count += 1; };
  cases.push_back({"header surfel count", count, ErrorId::kSurfelsChunk});
  Edit objects;
  objects.header = [](container::SurfelsTrackHeader& h) { h.object_count += 1; };
  cases.push_back({"header prototype count", objects, ErrorId::kSurfelsChunk});
  Edit flags;
  flags.header = [](container::SurfelsTrackHeader& h) { h.flags = 1; };
  cases.push_back({"header reserved flag", flags, ErrorId::kSurfelsUnsupported});
  Edit no_mesh;
  no_mesh.drop_mesh_index = true;
  cases.push_back({"mesh track without index", no_mesh, ErrorId::kSurfelsPairing});
  for (const Case& c : cases) {
    EXPECT_EQ(damage_id(rebuild(good, c.edit)), c.id) << c.name;
  }
  // A surfels track with another number of prototypes than its mesh track.
  const auto fewer = encode(test_input(np - 1, false));
  EXPECT_EQ(damage_id(fewer), ErrorId::kSurfelsPairing);
}

// ---- The frozen conformance clips (tests/conformance/surfels/) ----

std::string source_path(const std::string& rel) {
  const char* root = std::getenv("CALF_SOURCE_DIR");
  return std::string(root ? root : ".") + "/" + rel;
}

std::vector<uint8_t> read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

struct Clip {
  const char* name;
  Compression compression;
};
constexpr Clip kClips[] = {{"levels_none", Compression::kNone},
                           {"levels_zstd", Compression::kZstd},
                           {"levels_lzma2", Compression::kLzma2}};

// The frozen clips are container 1.0 files: a plain directory (SPEC §4.1 is 1.1), every chunk in
// the clip's scheme even where it is larger than raw (as the pinned 1.0 clips store them).
std::vector<uint8_t> make_clip(const Clip& c) {
  encoder::SurfelsEncodeOptions o = opts(c.compression);
  o.levels.compress_directory = false;
  o.levels.store_when_larger = false;
  return encode(test_input(mesh_prototypes(), false), o);
}

// The generator (tests/conformance/README.md): with CALF_CONFORMANCE_OUT=DIR it writes the clips
// there; the committed copies are never regenerated for a new version.
TEST(SurfelsConformance, Generator) {
  const char* out = std::getenv("CALF_CONFORMANCE_OUT");
  if (!out) GTEST_SKIP() << "set CALF_CONFORMANCE_OUT to write the clips";
  auto write = [](const std::string& path, const std::vector<uint8_t>& bytes) {
    std::ofstream f(path, std::ios::binary);
    f.write(reinterpret_cast<const char*>(bytes.data()),
            static_cast<std::streamsize>(bytes.size()));
    ASSERT_TRUE(f.good()) << path;
  };
  for (const Clip& c : kClips) write(std::string(out) + "/" + c.name + ".calf", make_clip(c));
  // Fuzz seeds (tests/fuzz/corpus/surfels_track_fuzz/): a small valid clip, stored and zstd, and
  // damaged copies with valid hashes, so that mutations reach the track's parsers.
  const std::string fuzz = std::string(out) + "/fuzz";
  std::filesystem::create_directories(fuzz);
  SurfelsTrackInput small = test_input(mesh_prototypes(), false);
  small.prototypes[0] = sphere_surfels(1100, 5, 1.0f, 0.0f);  // two levels, few bytes
  small.prototypes[3] = sphere_surfels(20, 6, 1.0f, 0.0f);
  const auto valid = encode(small, opts(Compression::kNone));
  write(fuzz + "/valid_none.calf", valid);
  write(fuzz + "/valid_zstd.calf", encode(small));
  const auto damaged = [&](const char* name, SurfelsStream stream, uint32_t region, uint32_t layer,
                           size_t at, uint8_t value) {
    Edit e;
    e.chunk = [=](const container::ChunkKeys& k, std::vector<uint8_t>& raw, bool&) {
      if (is(k, stream, region, layer) && at < raw.size()) raw[at] = value;
    };
    write(fuzz + "/" + name + ".calf", rebuild(valid, e));
  };
  damaged("bad_index_version", SurfelsStream::kIndex, 0, 0, 0, 2);
  damaged("bad_mesh_track", SurfelsStream::kIndex, 0, 0, 8, 1);
  damaged("bad_surfel_count", SurfelsStream::kIndex, 0, 0, 16, 0x55);
  damaged("bad_box", SurfelsStream::kIndex, 0, 0, 16 + 31, 0xff);
}

// The runner: each committed clip decodes to its hashes, within bounds of the input it was made
// from, and today's encoder still writes its bytes.
TEST(SurfelsConformance, CommittedClipsDecodeToTheirHashes) {
  const SurfelsTrackInput input = test_input(mesh_prototypes(), false);
  for (const Clip& c : kClips) {
    SCOPED_TRACE(c.name);
    const auto bytes =
        read_bytes(source_path(std::string("tests/conformance/surfels/") + c.name + ".calf"));
    ASSERT_FALSE(bytes.empty());
    const auto reader = open_reader(bytes);
    auto track = SurfelsTrack::open(reader, 1);
    ASSERT_TRUE(track.ok()) << track.status().to_string();
    for (uint32_t p = 0; p < track->prototype_count(); ++p) {
      SurfelBuffer got;
      ASSERT_TRUE(track->prototype(p, &got).ok());
      double worst = 0;
      expect_within_bounds(got, input.prototypes[p], track->record(p), &worst);
    }
    const auto result = decoder::verify_surfels_track(reader, 1, true, 10);
    std::ostringstream lines;
    for (const auto& l : result.hash_lines) lines << l << "\n";
    const auto want =
        read_bytes(source_path(std::string("tests/conformance/surfels/") + c.name + ".hashes"));
    // The .hashes file holds calf-verify --decode's lines: the mesh track's, then these.
    const std::string all(want.begin(), want.end());
    const size_t at = all.find("track 1 surfels ");
    ASSERT_NE(at, std::string::npos);
    EXPECT_EQ(lines.str(), all.substr(at));
    EXPECT_EQ(make_clip(c), bytes);
  }
}

}  // namespace
}  // namespace calf
