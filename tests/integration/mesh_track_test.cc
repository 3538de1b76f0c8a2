// The mesh track end to end (format/SPEC.md §11.4): a scene made by code (mesh_scene.h) encoded
// by encode_mesh_track, decoded by MeshTrack, compared with the scene itself (positions bitwise,
// subsets exactly); determinism; damaged chunks give the track's ids, never a crash; and the
// frozen conformance clips of tests/conformance/mesh/ still decode to the scene and their hashes.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cstddef>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

#include "calf/decoder/mesh_track.h"
#include "calf/decoder/mesh_verify.h"
#include "calf/encoder/mesh_encode.h"
#include "calf/encoder/sphere_mesh.h"
#include "calf/format/container.h"
#include "mesh_scene.h"

namespace calf {
namespace {

using container::Compression;
using container::MeshStream;
using decoder::MeshObject;
using decoder::MeshPrototype;
using decoder::MeshTrack;
using encoder::kSphereTriangles;
using encoder::kSphereVertices;

std::vector<uint8_t> encode(const capture::SceneFile& scene,
                            const std::vector<std::vector<uint32_t>>* visible,
                            encoder::MeshEncodeOptions options = {},
                            encoder::MeshEncodeStats* stats = nullptr) {
  std::vector<uint8_t> file;
  auto w = container::Writer::create(container::memory_sink(&file), options.levels);
  EXPECT_TRUE(w.ok());
  const Status st = encoder::encode_mesh_track(scene, visible, options, &*w, stats);
  EXPECT_TRUE(st.ok()) << st.to_string();
  EXPECT_TRUE(w->finish().ok());
  return file;
}

container::Reader open_reader(const std::vector<uint8_t>& file) {
  auto r = container::Reader::open(container::memory_source(std::span<const uint8_t>(file)));
  EXPECT_TRUE(r.ok()) << r.status().to_string();
  return std::move(*r);
}

template <class T>
bool same_bits(const std::vector<T>& a, const std::vector<T>& b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i) {
    if (std::bit_cast<uint32_t>(a[i]) != std::bit_cast<uint32_t>(b[i])) return false;
  }
  return true;
}

// What the track must hold for a scene mesh, built here from the scene and the sphere contract
// (not from the encoder's prototype_arrays).
MeshPrototype expected_prototype(const capture::SceneMesh& m) {
  MeshPrototype p;
  p.positions = m.positions;
  p.normals = m.normals;
  p.colours = m.colors;
  p.indices = m.indices;
  p.triangle_materials = m.triangle_materials;
  p.state_times = m.state_times;
  const bool normals = !m.normals.empty() || m.indices.empty();
  std::vector<float> sphere_pos, sphere_nrm, ignored;
  for (const auto& s : m.spheres) {
    std::vector<uint32_t> idx;
    const size_t before = sphere_pos.size() / 3;
    encoder::append_sphere_mesh(s.center.data(), s.radius, &sphere_pos, &sphere_nrm, &idx);
    for (uint32_t i : idx) p.indices.push_back(i + static_cast<uint32_t>(m.vertex_count()));
    EXPECT_EQ(idx.front(), before);
  }
  p.positions.insert(p.positions.end(), sphere_pos.begin(), sphere_pos.end());
  if (normals) p.normals.insert(p.normals.end(), sphere_nrm.begin(), sphere_nrm.end());
  if (!m.spheres.empty() && !m.triangle_materials.empty())
    p.triangle_materials.resize(p.indices.size() / 3, mesh::kObjectMaterial);
  for (size_t k = 0; k < m.state_times.size(); ++k) {
    const size_t n = m.positions.size();
    p.state_positions.insert(p.state_positions.end(), m.state_positions.begin() + k * n,
                             m.state_positions.begin() + (k + 1) * n);
    p.state_positions.insert(p.state_positions.end(), sphere_pos.begin(), sphere_pos.end());
  }
  return p;
}

void expect_prototype(const MeshPrototype& got, const MeshPrototype& want, size_t index) {
  SCOPED_TRACE("prototype " + std::to_string(index));
  EXPECT_TRUE(same_bits(got.positions, want.positions));
  EXPECT_TRUE(same_bits(got.normals, want.normals));
  EXPECT_TRUE(same_bits(got.colours, want.colours));
  EXPECT_EQ(got.indices, want.indices);
  EXPECT_EQ(got.triangle_materials, want.triangle_materials);
  EXPECT_TRUE(same_bits(got.state_times, want.state_times));
  EXPECT_TRUE(same_bits(got.state_positions, want.state_positions));
}

TEST(SphereMesh, IcosphereCountsAndUnitNormals) {
  std::vector<float> pos, nrm;
  std::vector<uint32_t> idx = {7};  // appended after what is there
  const float c[3] = {1, 2, 3};
  pos.assign(6, 0.0f);  // two vertices already present
  encoder::append_sphere_mesh(c, 2.0f, &pos, &nrm, &idx);
  ASSERT_EQ(pos.size(), 6 + 3 * size_t{kSphereVertices});
  ASSERT_EQ(nrm.size(), 3 * size_t{kSphereVertices});
  ASSERT_EQ(idx.size(), 1 + 3 * size_t{kSphereTriangles});
  EXPECT_EQ(kSphereVertices, 642u);
  EXPECT_EQ(kSphereTriangles, 1280u);
  for (size_t i = 1; i < idx.size(); ++i) {
    EXPECT_GE(idx[i], 2u);
    EXPECT_LT(idx[i], 2u + kSphereVertices);
  }
  for (size_t v = 0; v < kSphereVertices; ++v) {
    const float* n = &nrm[3 * v];
    EXPECT_NEAR(n[0] * n[0] + n[1] * n[1] + n[2] * n[2], 1.0, 1e-6);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(pos[6 + 3 * v + k], c[k] + 2.0f * n[k], 1e-5);
  }
  // Counter-clockwise from outside: every face normal points away from the centre.
  for (size_t t = 1; t < idx.size(); t += 3) {
    const float* a = &pos[3 * idx[t]];
    const float* b = &pos[3 * idx[t + 1]];
    const float* d = &pos[3 * idx[t + 2]];
    const double e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    const double e2[3] = {d[0] - a[0], d[1] - a[1], d[2] - a[2]};
    const double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                         e1[0] * e2[1] - e1[1] * e2[0]};
    const double out = n[0] * (a[0] - c[0]) + n[1] * (a[1] - c[1]) + n[2] * (a[2] - c[2]);
    EXPECT_GT(out, 0) << "triangle " << t / 3;
  }
}

TEST(MeshTrack, FullSceneRoundTrip) {
  const capture::SceneFile scene = test::make_mesh_test_scene(3);
  encoder::MeshEncodeStats stats;
  const auto file = encode(scene, nullptr, {}, &stats);
  const auto reader = open_reader(file);
  auto track = MeshTrack::open(reader, 0);
  ASSERT_TRUE(track.ok()) << track.status().to_string();
  // Counts worked out by hand: quad 4 + strip 8 + balls 3 + 2 x 642 + ball 642 + panel 4
  // vertices; floor, tile, mover 2 triangles each, grass 6, toys 1 + 2 x 1280, sun 1280, sign 2.
  EXPECT_EQ(track->header().vertex_count, 1945u);
  EXPECT_EQ(track->header().triangle_count, 3855u);
  EXPECT_EQ(stats.triangles, 3855u);
  EXPECT_EQ(stats.scene_triangles, 3855u);
  EXPECT_EQ(track->header().flags, 0);
  EXPECT_EQ(track->frame_count(), 3u);
  EXPECT_DOUBLE_EQ(track->fps(), 24.0);
  EXPECT_EQ(track->view_volume().min, (Vec3{-1, 1.5, -1}));
  EXPECT_EQ(track->view_volume().max, (Vec3{1, 1.7, 1}));
  ASSERT_EQ(track->materials().size(), 3u);
  EXPECT_EQ(track->materials()[1].base_colour, (std::array<float, 3>{1, 0.75f, 0.25f}));
  EXPECT_EQ(track->materials()[1].emission, (std::array<float, 3>{4, 3, 2}));
  ASSERT_EQ(track->prototype_count(), 5u);
  ASSERT_EQ(track->object_count(), 7u);
  // The panel (prototype 4) draws the quad's triangles: one triangles chunk for both.
  EXPECT_EQ(track->index().prototypes[4].triangles_of, 0u);
  EXPECT_EQ(stats.triangles_stream.chunks, 4u);
  EXPECT_EQ(stats.vertices_stream.chunks, 5u);
  for (uint32_t p = 0; p < 5; ++p) {
    MeshPrototype got;
    ASSERT_TRUE(track->prototype(p, &got).ok());
    expect_prototype(got, expected_prototype(scene.meshes[p]), p);
  }
  // The mixed mesh (own triangle without normals + spheres) has no normals; the sphere alone has.
  MeshPrototype balls, ball;
  ASSERT_TRUE(track->prototype(2, &balls).ok());
  ASSERT_TRUE(track->prototype(3, &ball).ok());
  EXPECT_TRUE(balls.normals.empty());
  EXPECT_EQ(ball.normals.size(), 3 * size_t{kSphereVertices});
  for (uint32_t o = 0; o < 7; ++o) {
    MeshObject got;
    ASSERT_TRUE(track->object(o, &got).ok());
    const auto& so = scene.objects[o];
    EXPECT_EQ(got.prototype, so.mesh);
    EXPECT_EQ(got.material, so.material);
    EXPECT_TRUE(got.all_triangles);
    EXPECT_TRUE(got.triangles.empty());
    for (uint32_t f = 0; f < 4; ++f)
      EXPECT_EQ(decoder::transform_at(got, f), capture::transform_at(so, f)) << o << " " << f;
    EXPECT_EQ(got.transforms.size(), o == 2 ? 3u : 1u) << "static objects keep one transform";
  }
  // States: the decoder's positions_at gives the scene reader's floats.
  MeshPrototype strip;
  ASSERT_TRUE(track->prototype(1, &strip).ok());
  for (double t : {-1.0, 0.0, 0.01, 0.05, 0.075, 0.1, 5.0}) {
    std::vector<float> got, want;
    decoder::positions_at(strip, t, &got);
    capture::positions_at(scene.meshes[1], t, &want);
    EXPECT_TRUE(same_bits(got, want)) << "time " << t;
  }
  // Out-of-range requests are errors.
  MeshObject o;
  MeshPrototype p;
  EXPECT_EQ(track->object(7, &o).id(), ErrorId::kInvalidArgument);
  EXPECT_EQ(track->prototype(5, &p).id(), ErrorId::kInvalidArgument);
  EXPECT_EQ(MeshTrack::open(reader, 1).status().id(), ErrorId::kInvalidArgument);
}

// A visible set: per scene object a sorted list of mesh triangles.
// Without spheres the toys draw their one triangle and the tetrahedron three of its four.
std::vector<std::vector<uint32_t>> test_subset(bool spheres = true) {
  if (!spheres) return {{1}, {}, {0, 1}, {0, 2, 3, 5}, {0}, {0, 2, 3}, {1}};
  std::vector<uint32_t> toys = {0};
  for (uint32_t t = 1; t <= kSphereTriangles; ++t) toys.push_back(t);  // the first sphere whole
  toys.push_back(2000);
  return {{1}, {}, {0, 1}, {0, 2, 3, 5}, toys, {5, 6, 7, 900}, {1}};
}

TEST(MeshTrack, SubsetRoundTrip) {
  const capture::SceneFile scene = test::make_mesh_test_scene(3);
  const auto visible = test_subset();
  encoder::MeshEncodeOptions options;
  options.segment_count = 8;
  const auto file = encode(scene, &visible, options);
  const auto reader = open_reader(file);
  auto track = MeshTrack::open(reader, 0);
  ASSERT_TRUE(track.ok()) << track.status().to_string();
  EXPECT_EQ(track->header().flags, mesh::kHeaderVisibleSet);
  EXPECT_EQ(track->header().segment_count, 8u);
  EXPECT_EQ(track->header().triangle_count, 1u + 2 + 4 + 1282 + 4 + 1);
  // The tile (object 1) draws nothing and is left out; every mesh is still used.
  ASSERT_EQ(track->object_count(), 6u);
  ASSERT_EQ(track->prototype_count(), 5u);
  const uint32_t sources[6] = {0, 2, 3, 4, 5, 6};
  for (uint32_t o = 0; o < 6; ++o) {
    MeshObject got;
    ASSERT_TRUE(track->object(o, &got).ok());
    const uint32_t s = sources[o];
    EXPECT_EQ(track->index().objects[o].source_object, s);
    EXPECT_EQ(got.prototype, scene.objects[s].mesh);
    if (s == 2) {
      EXPECT_TRUE(got.all_triangles) << "a list of every triangle is stored as all";
      EXPECT_TRUE(got.triangles.empty());
    } else {
      EXPECT_FALSE(got.all_triangles);
      EXPECT_EQ(got.triangles, visible[s]) << "object " << s;
    }
  }
}

TEST(MeshTrack, DeterministicForThreadsAndDecodesTheSameForEveryScheme) {
  const capture::SceneFile scene = test::make_mesh_test_scene(4);
  const auto visible = test_subset();
  encoder::MeshEncodeOptions one, many;
  many.threads = 4;
  EXPECT_EQ(encode(scene, &visible, one), encode(scene, &visible, many));
  EXPECT_EQ(encode(scene, nullptr, one), encode(scene, nullptr, one));
  std::vector<uint64_t> first;
  for (Compression c : {Compression::kZstd, Compression::kLzma2, Compression::kNone}) {
    encoder::MeshEncodeOptions o;
    o.supercompression = c;
    const auto file = encode(scene, &visible, o);
    const auto reader = open_reader(file);
    const auto r = decoder::verify_mesh_track(reader, 0, true, 10);
    ASSERT_TRUE(r.problems.empty()) << r.problems[0].to_string();
    std::vector<uint64_t> hashes;
    for (const auto& line : r.hash_lines) hashes.push_back(std::hash<std::string>{}(line));
    if (first.empty()) {
      first = hashes;
    } else {
      EXPECT_EQ(hashes, first);
    }
  }
}

TEST(MeshTrack, BadVisibleSetsAreRefused) {
  const capture::SceneFile scene = test::make_mesh_test_scene(2);
  std::vector<uint8_t> file;
  auto w = container::Writer::create(container::memory_sink(&file));
  ASSERT_TRUE(w.ok());
  std::vector<std::vector<uint32_t>> short_list = {{0}};
  EXPECT_EQ(encoder::encode_mesh_track(scene, &short_list, {}, &*w).id(), ErrorId::kEncoderInput);
  auto unsorted = test_subset();
  unsorted[3] = {2, 1};
  EXPECT_EQ(encoder::encode_mesh_track(scene, &unsorted, {}, &*w).id(), ErrorId::kEncoderInput);
  auto beyond = test_subset();
  beyond[0] = {2};  // the quad has 2 triangles
  EXPECT_EQ(encoder::encode_mesh_track(scene, &beyond, {}, &*w).id(), ErrorId::kEncoderInput);
  capture::SceneFile far = scene;
  far.meshes[0].positions[0] = 2e12f;  // beyond the coordinate bound
  EXPECT_EQ(encoder::encode_mesh_track(far, nullptr, {}, &*w).id(), ErrorId::kEncoderInput);
}

// check_mesh_scene refuses, without encoding, what encode_mesh_track refuses in the placed
// meshes (calf-encode --visible-set calls it before solving the set): a vertex or a sphere far
// beyond the coordinate bound. A mesh no object places is not checked.
TEST(MeshTrack, SceneCheckRefusesWhatTheTrackRefuses) {
  const capture::SceneFile scene = test::make_mesh_test_scene(2);
  EXPECT_TRUE(encoder::check_mesh_scene(scene).ok());
  capture::SceneFile far = scene;
  far.meshes[0].positions[0] = 3e38f;
  Status s = encoder::check_mesh_scene(far);
  EXPECT_EQ(s.id(), ErrorId::kEncoderInput) << s.to_string();
  EXPECT_NE(s.message().find("scene mesh 0"), std::string::npos) << s.to_string();
  std::vector<uint8_t> file;
  auto w = container::Writer::create(container::memory_sink(&file));
  ASSERT_TRUE(w.ok());
  EXPECT_EQ(encoder::encode_mesh_track(far, nullptr, {}, &*w).id(), s.id());
  capture::SceneFile ball = scene;
  ball.meshes[0].spheres.push_back({{0, 0, 0}, 3e38f});
  EXPECT_EQ(encoder::check_mesh_scene(ball).id(), ErrorId::kEncoderInput);
}

// ---- Damaged chunks: the file is rebuilt with valid hashes, so the track's parser sees them ----

struct Edit {
  std::function<void(const container::ChunkKeys&, std::vector<uint8_t>&, bool& drop)> chunk;
  std::function<void(container::MeshTrackHeader&)> header;
  bool duplicate_last = false;
};

std::vector<uint8_t> rebuild(const std::vector<uint8_t>& file, const Edit& edit) {
  const auto reader = open_reader(file);
  std::vector<uint8_t> out;
  auto w = container::Writer::create(container::memory_sink(&out));
  EXPECT_TRUE(w.ok());
  auto h = std::get<container::MeshTrackHeader>(reader.tracks()[0].header);
  if (edit.header) edit.header(h);
  EXPECT_TRUE(w->add_track(h).ok());
  std::vector<uint8_t> last;
  container::ChunkKeys last_keys;
  for (uint32_t id = 0; id < reader.chunks().size(); ++id) {
    auto raw = reader.read_chunk(id);
    EXPECT_TRUE(raw.ok());
    bool drop = false;
    if (edit.chunk) edit.chunk(reader.chunks()[id].keys, *raw, drop);
    if (drop) continue;
    EXPECT_TRUE(w->add_chunk(reader.chunks()[id].keys, *raw, Compression::kNone).ok());
    last = *raw;
    last_keys = reader.chunks()[id].keys;
  }
  if (edit.duplicate_last) {
    EXPECT_TRUE(w->add_chunk(last_keys, last, Compression::kNone).ok());
  }
  EXPECT_TRUE(w->finish().ok());
  return out;
}

// The first problem of verifying the damaged file (open's error, else decoding's).
ErrorId damage_id(const std::vector<uint8_t>& file) {
  const auto reader = open_reader(file);
  const auto r = decoder::verify_mesh_track(reader, 0, false, 10);
  return r.problems.empty() ? ErrorId::kOk : r.problems[0].id();
}

// Drops the last n bytes. erase, not resize: resize's growing branch (never taken here) draws
// GCC 12's -Wstringop-overflow / -Warray-bounds false positives at -O1, as it cannot tell that
// the new size is not larger.
void shrink(std::vector<uint8_t>& r, size_t n) {
  r.erase(r.end() - static_cast<std::ptrdiff_t>(std::min(n, r.size())), r.end());
}

bool is(const container::ChunkKeys& k, MeshStream s, uint32_t region) {
  return k.stream == static_cast<uint16_t>(s) && k.region == region;
}

TEST(MeshTrack, DamagedChunksGiveTheTrackIds) {
  const capture::SceneFile scene = test::make_mesh_test_scene(3);
  const auto visible = test_subset();
  const auto good = encode(scene, &visible);
  ASSERT_EQ(damage_id(rebuild(good, {})), ErrorId::kOk) << "rebuilding alone changes nothing";
  // Offsets in the index chunk (§11.4.2): 3 materials, 5 prototypes.
  constexpr size_t kObjects = 4 + 4 + 48 + 4 + 3 * 24 + 4 + 5 * 20 + 4;
  constexpr size_t kPrototypes = 4 + 4 + 48 + 4 + 3 * 24 + 4;
  auto on = [](MeshStream s, uint32_t region, std::function<void(std::vector<uint8_t>&)> f) {
    Edit e;
    e.chunk = [=](const container::ChunkKeys& k, std::vector<uint8_t>& raw, bool&) {
      if (is(k, s, region)) f(raw);
    };
    return e;
  };
  struct Case {
    const char* name;
    Edit edit;
    ErrorId id;
  };
  std::vector<Case> cases = {
      {"layout version 3", on(MeshStream::kIndex, 0, [](auto& r) { r[0] = 3; }),
       ErrorId::kMeshUnsupported},
      {"index flags", on(MeshStream::kIndex, 0, [](auto& r) { r[4] = 1; }),
       ErrorId::kMeshUnsupported},
      {"index truncated", on(MeshStream::kIndex, 0, [](auto& r) { shrink(r, 1); }),
       ErrorId::kMeshChunk},
      {"index trailing byte", on(MeshStream::kIndex, 0, [](auto& r) { r.push_back(0); }),
       ErrorId::kMeshChunk},
      {"view region inverted", on(MeshStream::kIndex, 0, [](auto& r) { r[8 + 7] = 0x40; }),
       ErrorId::kMeshValue},
      {"material NaN",
       on(MeshStream::kIndex, 0, [](auto& r) { r[60 + 2] = 0xc0, r[60 + 3] = 0x7f; }),
       ErrorId::kMeshValue},
      {"materials count huge",
       on(MeshStream::kIndex, 0, [](auto& r) { r[56] = 0xff, r[57] = 0xff, r[58] = 0x0f; }),
       ErrorId::kMeshLimit},
      {"object prototype out of range",
       on(MeshStream::kIndex, 0, [](auto& r) { r[kObjects + 4] = 9; }), ErrorId::kMeshIndex},
      {"object material out of range",
       on(MeshStream::kIndex, 0, [](auto& r) { r[kObjects + 8] = 3; }), ErrorId::kMeshIndex},
      {"transform count 2", on(MeshStream::kIndex, 0, [](auto& r) { r[kObjects + 12] = 2; }),
       ErrorId::kMeshIndex},
      {"prototype vertex count", on(MeshStream::kIndex, 0, [](auto& r) { r[kPrototypes] = 5; }),
       ErrorId::kMeshChunk},
      {"triangles of a later prototype",
       on(MeshStream::kIndex, 0, [](auto& r) { r[kPrototypes + 16] = 4; }), ErrorId::kMeshIndex},
      {"shared triangles claimed as own",
       on(MeshStream::kIndex, 0, [](auto& r) { r[kPrototypes + 4 * 20 + 16] = 4; }),
       ErrorId::kMeshChunk},
      {"position NaN",
       on(MeshStream::kVertices, 0,
          [](auto& r) { r[0] = 0, r[12] = 0, r[24] = 0xc0, r[36] = 0x7f; }),
       ErrorId::kMeshValue},
      {"colour above 1", on(MeshStream::kVertices, 0, [](auto& r) { r[2 * 48 + 36] = 0x40; }),
       ErrorId::kMeshValue},
      {"state times not increasing",
       on(MeshStream::kVertices, 1, [](auto& r) { r[96 + 3 * 3 + 1] = 0xbf; }),
       ErrorId::kMeshValue},
      {"vertices chunk short", on(MeshStream::kVertices, 1, [](auto& r) { shrink(r, 4); }),
       ErrorId::kMeshChunk},
      {"vertex index out of range", on(MeshStream::kTriangles, 0, [](auto& r) { r[0] = 100; }),
       ErrorId::kMeshIndex},
      {"triangle material out of range", on(MeshStream::kTriangles, 0, [](auto& r) { r[24] = 7; }),
       ErrorId::kMeshIndex},
      {"transform NaN", on(MeshStream::kVisibility, 0, [](auto& r) { r[24] = 0xc0, r[36] = 0x7f; }),
       ErrorId::kMeshValue},
      {"visibility short", on(MeshStream::kVisibility, 0, [](auto& r) { r.resize(20); }),
       ErrorId::kMeshChunk},
      {"run count wrong", on(MeshStream::kVisibility, 0, [](auto& r) { r[48] = 3; }),
       ErrorId::kMeshChunk},
      {"run beyond the prototype", on(MeshStream::kVisibility, 0, [](auto& r) { r[52] = 200; }),
       ErrorId::kMeshIndex},
      {"empty run", on(MeshStream::kVisibility, 0, [](auto& r) { r[56] = 0; }),
       ErrorId::kMeshIndex},
  };
  Edit drop;
  drop.chunk = [](const container::ChunkKeys& k, std::vector<uint8_t>&, bool& d) {
    d = is(k, MeshStream::kVisibility, 4);
  };
  cases.push_back({"visibility chunk missing", drop, ErrorId::kMeshChunk});
  Edit drop_index;
  drop_index.chunk = [](const container::ChunkKeys& k, std::vector<uint8_t>&, bool& d) {
    d = is(k, MeshStream::kTriangles, 2);
  };
  cases.push_back({"triangles chunk missing", drop_index, ErrorId::kMeshChunk});
  Edit twice;
  twice.duplicate_last = true;
  cases.push_back({"visibility chunk twice", twice, ErrorId::kMeshChunk});
  Edit count;
  count.header = [](container::MeshTrackHeader& h) { h.triangle_count += 1; };
  cases.push_back({"header triangle count", count, ErrorId::kMeshChunk});
  Edit flags;
  flags.header = [](container::MeshTrackHeader& h) { h.flags = 2; };
  cases.push_back({"header reserved flag", flags, ErrorId::kMeshUnsupported});
  for (const Case& c : cases) {
    EXPECT_EQ(damage_id(rebuild(good, c.edit)), c.id) << c.name;
  }
}

// ---- Layout 2: UVs and textures ----

TEST(MeshTrack, TexturedRoundTripAndUntexturedStaysLayout1) {
  const capture::SceneFile scene = test::make_textured_mesh_test_scene();
  encoder::MeshEncodeStats stats;
  const auto file = encode(scene, nullptr, {}, &stats);
  const auto reader = open_reader(file);
  auto track = MeshTrack::open(reader, 0);
  ASSERT_TRUE(track.ok()) << track.status().to_string();
  EXPECT_EQ(track->index().layout_version, 2u);
  ASSERT_EQ(track->texture_count(), 3u);
  ASSERT_EQ(track->materials().size(), 3u);
  for (size_t m = 0; m < 3; ++m)
    EXPECT_EQ(track->materials()[m].base_colour_texture, scene.materials[m].base_color_texture);
  for (uint32_t t = 0; t < 3; ++t) {
    mesh::TextureTexels got;
    ASSERT_TRUE(track->texture(t, &got).ok());
    EXPECT_EQ(got.width, scene.textures[t].width);
    EXPECT_EQ(got.height, scene.textures[t].height);
    EXPECT_EQ(got.rgba, scene.textures[t].rgba);
  }
  for (uint32_t p = 0; p < 3; ++p) {
    MeshPrototype got;
    ASSERT_TRUE(track->prototype(p, &got).ok());
    EXPECT_TRUE(same_bits(got.uvs, scene.meshes[p].uvs)) << p;
    EXPECT_EQ(got.indices, scene.meshes[p].indices);
  }
  EXPECT_EQ(stats.textures.chunks, 3u);
  EXPECT_EQ(stats.textures.raw, 4u * (32 + 15 + 4));
  // Threads never change the bytes.
  encoder::MeshEncodeOptions four;
  four.threads = 4;
  EXPECT_EQ(encode(scene, nullptr, four), file);
  // A texture without its pixels is the encoder's input error.
  capture::SceneFile unloaded = scene;
  unloaded.textures[1].rgba.clear();
  std::vector<uint8_t> sink;
  auto w = container::Writer::create(container::memory_sink(&sink));
  ASSERT_TRUE(w.ok());
  EXPECT_EQ(encoder::encode_mesh_track(unloaded, nullptr, {}, &*w).id(), ErrorId::kEncoderInput);
  // Without textures and UVs the track is written in layout 1 (the 1.0 bytes).
  const std::vector<uint8_t> plain_bytes = encode(test::make_mesh_test_scene(2), nullptr);
  const auto plain = open_reader(plain_bytes);  // reads plain_bytes in place
  auto plain_track = MeshTrack::open(plain, 0);
  ASSERT_TRUE(plain_track.ok());
  EXPECT_EQ(plain_track->index().layout_version, 1u);
  EXPECT_EQ(plain_track->texture_count(), 0u);
}

TEST(MeshTrack, DamagedTexturedChunksGiveTheTrackIds) {
  const auto good = encode(test::make_textured_mesh_test_scene(), nullptr);
  ASSERT_EQ(damage_id(rebuild(good, {})), ErrorId::kOk);
  const auto on = [](MeshStream s, uint32_t region, std::function<void(std::vector<uint8_t>&)> f) {
    Edit e;
    e.chunk = [=](const container::ChunkKeys& k, std::vector<uint8_t>& raw, bool&) {
      if (is(k, s, region)) f(raw);
    };
    return e;
  };
  // The index ends with the 3 materials' textures: material 2's is the last word.
  EXPECT_EQ(damage_id(rebuild(good, on(MeshStream::kIndex, 0, [](auto& r) { r.back() = 1; }))),
            ErrorId::kMeshIndex)
      << "material texture 0x01000001";
  EXPECT_EQ(damage_id(rebuild(good, on(MeshStream::kTextures, 1, [](auto& r) { shrink(r, 1); }))),
            ErrorId::kMeshChunk)
      << "texture chunk short";
  // Prototype 0's UVs follow its positions and normals (96 bytes): u of vertex 0 made +inf.
  EXPECT_EQ(damage_id(rebuild(
                good, on(MeshStream::kVertices, 0,
                         [](auto& r) { r[96] = 0, r[104] = 0, r[112] = 0x80, r[120] = 0x7f; }))),
            ErrorId::kMeshValue)
      << "uv inf";
  Edit drop;
  drop.chunk = [](const container::ChunkKeys& k, std::vector<uint8_t>&, bool& d) {
    d = is(k, MeshStream::kTextures, 2);
  };
  EXPECT_EQ(damage_id(rebuild(good, drop)), ErrorId::kMeshChunk) << "texture chunk missing";
  Edit extra;
  extra.duplicate_last = true;  // the last chunk is texture 2's
  EXPECT_EQ(damage_id(rebuild(good, extra)), ErrorId::kMeshChunk) << "texture chunk twice";
}

// ---- The frozen conformance clips (tests/conformance/mesh/) ----

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
  bool subset;
  Compression compression;
  bool textured = false;  // layout 2: the textured scene (mesh_scene.h), all triangles
};
// The conformance clips are of the scene without spheres (a few KB): the decoder sees a sphere
// as triangles like any other, and the round trips above cover the spheres.
constexpr Clip kClips[] = {{"full_none", false, Compression::kNone},
                           {"subset_zstd", true, Compression::kZstd},
                           {"full_lzma2", false, Compression::kLzma2},
                           {"textured_zstd", false, Compression::kZstd, true}};

// The frozen clips are container 1.0 files: a plain directory (SPEC §4.1 is 1.1), every chunk in
// the clip's scheme even where it is larger than raw (as the pinned 1.0 clips store them).
std::vector<uint8_t> make_clip(const Clip& c) {
  if (c.textured) {
    encoder::MeshEncodeOptions o;
    o.supercompression = c.compression;
    o.levels.compress_directory = false;
    o.levels.store_when_larger = false;
    return encode(test::make_textured_mesh_test_scene(), nullptr, o);
  }
  const capture::SceneFile scene = test::make_mesh_test_scene(3, false);
  const auto visible = test_subset(false);
  encoder::MeshEncodeOptions o;
  o.supercompression = c.compression;
  o.levels.compress_directory = false;
  o.levels.store_when_larger = false;  // as the writers of 1.0 did
  o.segment_count = c.subset ? 8 : 0;
  return encode(scene, c.subset ? &visible : nullptr, o);
}

// The generator (tests/conformance/README.md): with CALF_CONFORMANCE_OUT=DIR it writes the clips
// there; the committed copies are never regenerated for a new version.
TEST(MeshConformance, Generator) {
  const char* out = std::getenv("CALF_CONFORMANCE_OUT");
  if (!out) GTEST_SKIP() << "set CALF_CONFORMANCE_OUT to write the clips";
  auto write = [](const std::string& path, const std::vector<uint8_t>& bytes) {
    std::ofstream f(path, std::ios::binary);
    f.write(reinterpret_cast<const char*>(bytes.data()),
            static_cast<std::streamsize>(bytes.size()));
    ASSERT_TRUE(f.good()) << path;
  };
  for (const Clip& c : kClips) write(std::string(out) + "/" + c.name + ".calf", make_clip(c));
  // Fuzz seeds (tests/fuzz/corpus/mesh_track_fuzz/): the clips, and damaged copies whose chunks
  // are stored uncompressed with valid hashes, so that mutations reach the track's parsers.
  const std::string fuzz = std::string(out) + "/fuzz";
  std::filesystem::create_directories(fuzz);
  const auto subset = make_clip(kClips[1]);
  write(fuzz + "/valid_full_none.calf", make_clip(kClips[0]));
  write(fuzz + "/valid_subset_zstd.calf", subset);
  write(fuzz + "/valid_subset_none.calf", rebuild(subset, {}));
  const auto damaged = [&](const char* name, MeshStream stream, uint32_t region, size_t at,
                           uint8_t value) {
    Edit e;
    e.chunk = [=](const container::ChunkKeys& k, std::vector<uint8_t>& raw, bool&) {
      if (is(k, stream, region) && at < raw.size()) raw[at] = value;
    };
    write(fuzz + "/" + name + ".calf", rebuild(subset, e));
  };
  damaged("bad_index_version", MeshStream::kIndex, 0, 0, 3);
  damaged("bad_position_nan", MeshStream::kVertices, 0, 36, 0x7f);
  damaged("bad_vertex_index", MeshStream::kTriangles, 0, 0, 100);
  damaged("bad_run_gap", MeshStream::kVisibility, 0, 52, 200);
  // Layout 2 seeds: the textured clip stored, and damaged in its texture and UV parts.
  const auto textured = make_clip(kClips[3]);
  write(fuzz + "/valid_textured_none.calf", rebuild(textured, {}));
  const auto damaged_textured = [&](const char* name, MeshStream stream, uint32_t region, size_t at,
                                    uint8_t value) {
    Edit e;
    e.chunk = [=](const container::ChunkKeys& k, std::vector<uint8_t>& raw, bool&) {
      if (is(k, stream, region) && at < raw.size()) raw[at] = value;
    };
    write(fuzz + "/" + name + ".calf", rebuild(textured, e));
  };
  damaged_textured("bad_texture_width", MeshStream::kIndex, 0,
                   8 + 48 + 4 + 3 * 24 + 4 + 3 * 20 + 4 + 3 * 24 + 4 + 1, 0x40);
  damaged_textured("bad_uv_nan", MeshStream::kVertices, 0, 126, 0x7f);  // v of vertex 2: NaN
}

// The runner: each committed clip decodes to the scene it was made from, and to its hashes.
TEST(MeshConformance, CommittedClipsDecodeToTheSceneAndTheirHashes) {
  const capture::SceneFile plain = test::make_mesh_test_scene(3, false);
  const capture::SceneFile textured = test::make_textured_mesh_test_scene();
  const auto visible = test_subset(false);
  for (const Clip& c : kClips) {
    SCOPED_TRACE(c.name);
    const capture::SceneFile& scene = c.textured ? textured : plain;
    const auto bytes =
        read_bytes(source_path(std::string("tests/conformance/mesh/") + c.name + ".calf"));
    ASSERT_FALSE(bytes.empty());
    const auto reader = open_reader(bytes);
    auto track = MeshTrack::open(reader, 0);
    ASSERT_TRUE(track.ok()) << track.status().to_string();
    for (uint32_t p = 0; p < track->prototype_count(); ++p) {
      MeshPrototype got;
      ASSERT_TRUE(track->prototype(p, &got).ok());
      expect_prototype(got, expected_prototype(scene.meshes[p]), p);
      EXPECT_TRUE(same_bits(got.uvs, scene.meshes[p].uvs));
    }
    EXPECT_EQ(track->texture_count(), scene.textures.size());
    for (uint32_t t = 0; t < track->texture_count(); ++t) {
      mesh::TextureTexels got;
      ASSERT_TRUE(track->texture(t, &got).ok());
      EXPECT_EQ(got.rgba, scene.textures[t].rgba);
    }
    for (uint32_t o = 0; o < track->object_count(); ++o) {
      MeshObject got;
      ASSERT_TRUE(track->object(o, &got).ok());
      const uint32_t s = track->index().objects[o].source_object;
      if (!got.all_triangles) {
        EXPECT_EQ(got.triangles, visible[s]);
      }
      EXPECT_EQ(decoder::transform_at(got, 2), capture::transform_at(scene.objects[s], 2));
    }
    const auto result = decoder::verify_mesh_track(reader, 0, true, 10);
    std::ostringstream lines;
    for (const auto& l : result.hash_lines) lines << l << "\n";
    const auto want =
        read_bytes(source_path(std::string("tests/conformance/mesh/") + c.name + ".hashes"));
    EXPECT_EQ(lines.str(), std::string(want.begin(), want.end()));
    // Today's encoder still writes the frozen bytes (a change means a new clip, not an edit).
    EXPECT_EQ(make_clip(c), bytes);
  }
}

}  // namespace
}  // namespace calf
