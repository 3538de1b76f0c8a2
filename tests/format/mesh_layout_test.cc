// The mesh track's chunk layouts (format/mesh_layout.h, SPEC §11.4) on their own: every array
// round-trips bit for bit (odd floats included), the bytes are the documented planes, and each
// broken rule gives its id.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <limits>

#include "calf/format/colour.h"
#include "calf/format/mesh_layout.h"
#include "calf/format/mesh_texture.h"

namespace calf::mesh {
namespace {

std::vector<uint32_t> bits_of(const std::vector<float>& a) {
  std::vector<uint32_t> out;
  for (float f : a) out.push_back(std::bit_cast<uint32_t>(f));
  return out;
}

IndexChunk small_index() {
  IndexChunk x;
  x.view_min[0] = -1;
  x.view_max[0] = 2;
  x.materials.resize(2);
  x.materials[1].emission[2] = 5;
  x.prototypes.push_back({3, 1, kHasNormals | kHasColours | kHasTriangleMaterials, 2});
  x.prototypes.push_back({4, 2, 0, 0, 1});
  x.objects.push_back({7, 0, 1, 1, kAllTriangles, 1});
  x.objects.push_back({9, 1, 0, 3, 0, 1});
  return x;
}

TEST(MeshLayout, IndexRoundTripAndSize) {
  const IndexChunk x = small_index();
  auto bytes = serialize_index(x, 3);
  ASSERT_TRUE(bytes.ok()) << bytes.status().to_string();
  // 8 + 48 + (4 + 2 x 24) + (4 + 2 x 20) + (4 + 2 x 24), by hand.
  EXPECT_EQ(bytes->size(), 8u + 48 + 52 + 44 + 52);
  auto back = parse_index(*bytes, 3, "index");
  ASSERT_TRUE(back.ok()) << back.status().to_string();
  EXPECT_EQ(back->objects[1].source_object, 9u);
  EXPECT_EQ(back->prototypes[0].state_count, 2u);
  EXPECT_EQ(back->materials[1].emission[2], 5.0f);
  EXPECT_EQ(back->view_max[0], 2.0);
  // A prototype may draw an earlier one's triangles, of the same count and flag bit 2 only.
  IndexChunk shared = x;
  shared.prototypes.push_back({5, 2, 0, 0, 1});
  EXPECT_TRUE(serialize_index(shared, 3).ok());
  shared.prototypes.back().triangles_of = 0;  // 1 triangle and triangle materials
  EXPECT_EQ(serialize_index(shared, 3).status().id(), ErrorId::kContainerWriterMisuse);
  shared.prototypes.back().triangles_of = 3;  // not earlier
  EXPECT_EQ(serialize_index(shared, 3).status().id(), ErrorId::kContainerWriterMisuse);
  auto forward = serialize_index(x, 3);
  (*forward)[8 + 48 + 4 + 48 + 4 + 16] = 1;  // prototype 0 draws prototype 1's triangles
  EXPECT_EQ(parse_index(*forward, 3, "index").status().id(), ErrorId::kMeshIndex);
  // transform_count 3 is only valid for a 3-frame track.
  EXPECT_EQ(parse_index(*bytes, 4, "index").status().id(), ErrorId::kMeshIndex);
  EXPECT_EQ(serialize_index(x, 4).status().id(), ErrorId::kContainerWriterMisuse);
}

TEST(MeshLayout, IndexVersionIsCheckedFirst) {
  auto bytes = serialize_index(small_index(), 3);
  ASSERT_TRUE(bytes.ok());
  std::vector<uint8_t> v3 = *bytes;
  v3[0] = 3;
  v3.resize(6);  // a later layout may be anything after its version
  EXPECT_EQ(parse_index(v3, 3, "index").status().id(), ErrorId::kMeshUnsupported);
  // Layout 2 after a layout-1 body: its texture arrays are missing.
  std::vector<uint8_t> v2 = *bytes;
  v2[0] = 2;
  EXPECT_EQ(parse_index(v2, 3, "index").status().id(), ErrorId::kMeshChunk);
  EXPECT_EQ(parse_index(std::span<const uint8_t>(bytes->data(), 3), 3, "index").status().id(),
            ErrorId::kMeshChunk);
  std::vector<uint8_t> cut(bytes->begin(), bytes->end() - 1);
  EXPECT_EQ(parse_index(cut, 3, "index").status().id(), ErrorId::kMeshChunk);
}

TEST(MeshLayout, VerticesRoundTripBitForBitAsDocumentedPlanes) {
  const PrototypeRecord p{3, 1, kHasNormals | kHasColours, 2};
  VertexArrays a;
  const float denormal = std::numeric_limits<float>::denorm_min();
  a.positions = {-0.0f, 1e12f, -1e12f, denormal, 3.5f, -2, 1, 1, 1};
  a.normals = {0, 1, 0, 0, 0, -1, 1e-30f, 0, 0};
  a.colours = {0, 0.5f, 1, 1, 1, 1, 0.25f, 0, 0};
  a.state_times = {0, 0.5f};
  a.state_positions = {-0.0f, 1e12f, -1e12f, denormal, 3.5f, -2, 1, 1, 1,
                       0,     1,     2,      3,        4,    5,  6, 7, 8};
  auto bytes = encode_vertices(p, a);
  ASSERT_TRUE(bytes.ok()) << bytes.status().to_string();
  ASSERT_EQ(bytes->size(), vertices_chunk_size(p));
  EXPECT_EQ(bytes->size(), 4u * (3 * 3 * 3 + 2 + 2 * 9));
  // Byte planes of component planes: word 0 is x of vertex 0 (-0.0f = 0x80000000), word 1 x of
  // vertex 1 (denorm_min = 0x00000001), word 3 y of vertex 0 (1e12f = 0x5368d4a5); 9 words, so
  // plane 3 starts at byte 27.
  EXPECT_EQ((*bytes)[0], 0x00);
  EXPECT_EQ((*bytes)[27], 0x80);
  EXPECT_EQ((*bytes)[1], 0x01);
  EXPECT_EQ((*bytes)[28], 0x00);
  EXPECT_EQ((*bytes)[3], 0xa5);
  EXPECT_EQ((*bytes)[30], 0x53);
  VertexArrays back;
  ASSERT_TRUE(decode_vertices(*bytes, p, &back, "v").ok());
  EXPECT_EQ(bits_of(back.positions), bits_of(a.positions));
  EXPECT_EQ(bits_of(back.normals), bits_of(a.normals));
  EXPECT_EQ(bits_of(back.colours), bits_of(a.colours));
  EXPECT_EQ(bits_of(back.state_times), bits_of(a.state_times));
  EXPECT_EQ(bits_of(back.state_positions), bits_of(a.state_positions));
  // State 0 equal to the rest pose codes as zero words.
  for (size_t i = 4 * (27 + 2); i < 4 * (27 + 2 + 9); ++i) EXPECT_EQ((*bytes)[i], 0) << i;
}

TEST(MeshLayout, VertexValuesAreChecked) {
  const PrototypeRecord p{1, 0, kHasNormals, 2};
  VertexArrays a;
  a.positions = {0, 0, 0};
  a.normals = {0, 0, 1};
  a.state_times = {0, 1};
  a.state_positions = {0, 0, 0, 0, 0, 0};
  ASSERT_TRUE(encode_vertices(p, a).ok());
  VertexArrays bad = a;
  bad.positions[1] = 2e12f;
  EXPECT_EQ(encode_vertices(p, bad).status().id(), ErrorId::kContainerWriterMisuse);
  bad = a;
  bad.normals = {0, 0, 0};
  auto zero = encode_vertices(p, bad);
  EXPECT_EQ(zero.status().id(), ErrorId::kContainerWriterMisuse);
  bad = a;
  bad.state_times = {1, 1};
  EXPECT_EQ(encode_vertices(p, bad).status().id(), ErrorId::kContainerWriterMisuse);
  bad = a;
  bad.state_times = {0};
  EXPECT_EQ(encode_vertices(p, bad).status().id(), ErrorId::kContainerWriterMisuse);
  // A decoded NaN is E223, a short chunk E220.
  auto bytes = encode_vertices(p, a);
  std::vector<uint8_t> nan = *bytes;
  nan[2 * 3] = 0xc0;  // word 0 (x of vertex 0), plane 2 at 2 x 3 words
  nan[3 * 3] = 0x7f;
  VertexArrays out;
  EXPECT_EQ(decode_vertices(nan, p, &out, "v").id(), ErrorId::kMeshValue);
  std::vector<uint8_t> cut(bytes->begin(), bytes->end() - 1);
  EXPECT_EQ(decode_vertices(cut, p, &out, "v").id(), ErrorId::kMeshChunk);
}

TEST(MeshLayout, TrianglesRoundTripAndIndicesAreChecked) {
  const PrototypeRecord p{5, 3, kHasTriangleMaterials, 0};
  TriangleArrays a;
  a.indices = {0, 1, 2, 4, 3, 2, 0, 4, 1};
  a.triangle_materials = {1, kObjectMaterial, 0};
  auto bytes = encode_triangles(p, a);
  ASSERT_TRUE(bytes.ok());
  ASSERT_EQ(bytes->size(), triangles_chunk_size(p));
  EXPECT_EQ(bytes->size(), 4u * (9 + 3));
  TriangleArrays back;
  ASSERT_TRUE(decode_triangles(*bytes, p, 2, &back, "t").ok());
  EXPECT_EQ(back.indices, a.indices);
  EXPECT_EQ(back.triangle_materials, a.triangle_materials);
  EXPECT_EQ(decode_triangles(*bytes, p, 1, &back, "t").id(), ErrorId::kMeshIndex);
  PrototypeRecord fewer = p;
  fewer.vertex_count = 4;
  EXPECT_EQ(decode_triangles(*bytes, fewer, 2, &back, "t").id(), ErrorId::kMeshIndex);
}

TEST(MeshLayout, VisibilityRunsRoundTrip) {
  const PrototypeRecord p{3, 100, 0, 0};
  ObjectRecord o{0, 0, 0, 2, 0, 0};
  Visibility v;
  v.transforms = {{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0},
                  {1, 0, 0, 0.5f, 0, 1, 0, 0, 0, 0, 1, -0.0f}};
  v.triangles = {0, 1, 2, 7, 9, 10, 99};
  o.triangle_count = static_cast<uint32_t>(v.triangles.size());
  auto bytes = encode_visibility(o, p, v);
  ASSERT_TRUE(bytes.ok()) << bytes.status().to_string();
  // Runs [0, 3), [7, 8), [9, 11), [99, 100): 4 runs, 96 + 4 + 32 bytes.
  ASSERT_EQ(bytes->size(), 96u + 4 + 4 * 8);
  EXPECT_EQ((*bytes)[96], 4);
  Visibility back;
  ASSERT_TRUE(decode_visibility(*bytes, o, p, &back, "vis").ok());
  EXPECT_EQ(back.triangles, v.triangles);
  ASSERT_EQ(back.transforms.size(), 2u);
  EXPECT_EQ(std::bit_cast<uint32_t>(back.transforms[1][11]), 0x80000000u);
  EXPECT_EQ(back.transforms[1][3], 0.5f);
  // Unsorted subsets are refused by the writer; a wrong object count by the reader.
  Visibility unsorted = v;
  std::swap(unsorted.triangles[0], unsorted.triangles[1]);
  EXPECT_EQ(encode_visibility(o, p, unsorted).status().id(), ErrorId::kContainerWriterMisuse);
  ObjectRecord more = o;
  more.triangle_count += 1;
  EXPECT_EQ(decode_visibility(*bytes, more, p, &back, "vis").id(), ErrorId::kMeshIndex);
  // All triangles: transforms only.
  ObjectRecord all{0, 0, 0, 1, kAllTriangles, 100};
  Visibility t1;
  t1.transforms = {v.transforms[0]};
  auto b1 = encode_visibility(all, p, t1);
  ASSERT_TRUE(b1.ok());
  EXPECT_EQ(b1->size(), 48u);
  b1->push_back(0);
  EXPECT_EQ(decode_visibility(*b1, all, p, &back, "vis").id(), ErrorId::kMeshChunk);
}

// ---- Layout 2: textures and UVs ----

IndexChunk textured_index() {
  IndexChunk x = small_index();
  x.layout_version = kLayoutVersion;
  x.prototypes[1].flags = kHasUvs;
  x.textures.push_back({3, 2});
  x.textures.push_back({1, 1});
  x.material_textures = {kNoTexture, 1};
  return x;
}

TEST(MeshLayout, Layout2IndexRoundTripAndChecks) {
  const IndexChunk x = textured_index();
  auto bytes = serialize_index(x, 3);
  ASSERT_TRUE(bytes.ok()) << bytes.status().to_string();
  // Layout 1's bytes, then u32 X + 2 x 16 texture bytes, then 2 material textures (no count).
  EXPECT_EQ(bytes->size(), 8u + 48 + 52 + 44 + 52 + 4 + 32 + 8);
  auto back = parse_index(*bytes, 3, "index");
  ASSERT_TRUE(back.ok()) << back.status().to_string();
  ASSERT_EQ(back->textures.size(), 2u);
  EXPECT_EQ(back->textures[0].width, 3u);
  EXPECT_EQ(back->textures[0].height, 2u);
  EXPECT_EQ(back->material_texture(0), kNoTexture);
  EXPECT_EQ(back->material_texture(1), 1u);
  // The last word is material 1's texture: 2 is out of range (E222).
  std::vector<uint8_t> bad = *bytes;
  bad[bad.size() - 4] = 2;
  EXPECT_EQ(parse_index(bad, 3, "index").status().id(), ErrorId::kMeshIndex);
  // Texture 0's width 0 (E223), coding 2 (E221), width above 16384 (E224).
  const size_t tex0 = 8 + 48 + 52 + 44 + 52 + 4;
  bad = *bytes;
  bad[tex0] = 0;
  EXPECT_EQ(parse_index(bad, 3, "index").status().id(), ErrorId::kMeshValue);
  bad = *bytes;
  bad[tex0 + 8] = 2;
  EXPECT_EQ(parse_index(bad, 3, "index").status().id(), ErrorId::kMeshUnsupported);
  bad = *bytes;
  bad[tex0 + 2] = 1;  // width 65539
  EXPECT_EQ(parse_index(bad, 3, "index").status().id(), ErrorId::kMeshLimit);
  // Layout 1 has neither UVs nor textures.
  IndexChunk v1 = x;
  v1.layout_version = kLayoutVersionUntextured;
  EXPECT_EQ(serialize_index(v1, 3).status().id(), ErrorId::kContainerWriterMisuse);
  v1.textures.clear();
  v1.material_textures.clear();
  EXPECT_EQ(serialize_index(v1, 3).status().id(), ErrorId::kContainerWriterMisuse);  // UV flag
  v1.prototypes[1].flags = 0;
  EXPECT_TRUE(serialize_index(v1, 3).ok());
  // A layout-2 index needs one texture entry per material.
  IndexChunk short_list = x;
  short_list.material_textures.pop_back();
  EXPECT_EQ(serialize_index(short_list, 3).status().id(), ErrorId::kContainerWriterMisuse);
}

TEST(MeshLayout, UvsRoundTripAfterColoursAndAreChecked) {
  const PrototypeRecord p{2, 0, kHasColours | kHasUvs, 0};
  VertexArrays a;
  a.positions = {0, 0, 0, 1, 0, 0};
  a.colours = {1, 1, 1, 0, 0, 0};
  a.uvs = {0.25f, -3.5f, 1e6f, 0.75f};
  auto bytes = encode_vertices(p, a);
  ASSERT_TRUE(bytes.ok()) << bytes.status().to_string();
  ASSERT_EQ(bytes->size(), 24u + 24 + 16);
  // UV component planes after the colours: word 0 u0 (0.25f = 0x3e800000), word 2 v0 (-3.5f =
  // 0xc0600000); byte plane 3 starts 12 bytes in.
  EXPECT_EQ((*bytes)[48 + 12], 0x3e);
  EXPECT_EQ((*bytes)[48 + 14], 0xc0);
  VertexArrays back;
  ASSERT_TRUE(decode_vertices(*bytes, p, &back, "v").ok());
  EXPECT_EQ(bits_of(back.uvs), bits_of(a.uvs));
  std::vector<uint8_t> inf = *bytes;
  inf[48 + 12 + 1] = 0x7f;  // u1 = 0x7f800000 (+inf), byte by byte
  inf[48 + 8 + 1] = 0x80;
  inf[48 + 4 + 1] = 0x00;
  inf[48 + 1] = 0x00;
  EXPECT_EQ(decode_vertices(inf, p, &back, "v").id(), ErrorId::kMeshValue);
  VertexArrays missing = a;
  missing.uvs.pop_back();
  EXPECT_EQ(encode_vertices(p, missing).status().id(), ErrorId::kContainerWriterMisuse);
}

TEST(MeshLayout, TextureIsLosslessMedPlanes) {
  const TextureRecord r{3, 2};
  TextureTexels t{3, 2, {}};
  // Row 0: (10, 200, 0, 255) (20, 190, 20, 255) (30, 180, 250, 255);
  // row 1: (15, 100, 1, 128) (40, 0, 7, 128) (25, 255, 3, 0).
  t.rgba = {10, 200, 0, 255, 20, 190, 20, 255, 30, 180, 250, 255,
            15, 100, 1, 128, 40, 0,   7,  128, 25, 255, 3,   0};
  auto bytes = encode_texture(r, t);
  ASSERT_TRUE(bytes.ok()) << bytes.status().to_string();
  ASSERT_EQ(bytes->size(), 24u);
  // Red plane by hand: 10 (from 0), 20 - 10, 30 - 20 (left on row 0); 15 - 10 (above in column
  // 0); texel (1, 1): a = 15, b = 20, c = 10 <= min -> max(a, b) = 20, 40 - 20 = 20; texel
  // (2, 1): a = 40, b = 30, c = 20 <= min -> 40, 25 - 40 = -15 = 241.
  const std::vector<uint8_t> red(bytes->begin(), bytes->begin() + 6);
  EXPECT_EQ(red, (std::vector<uint8_t>{10, 10, 10, 5, 20, 241}));
  // Green (1, 1): a = 100, b = 190, c = 200 >= max -> min = 100, 0 - 100 = 156.
  EXPECT_EQ((*bytes)[6 + 4], 156);
  // Blue (2, 1): a = 7, b = 250, c = 20: between -> a + b - c = 237, 3 - 237 = 22.
  EXPECT_EQ((*bytes)[12 + 5], 22);
  TextureTexels back;
  ASSERT_TRUE(decode_texture(*bytes, r, &back, "tex").ok());
  EXPECT_EQ(back.rgba, t.rgba);
  EXPECT_EQ(back.width, 3u);
  std::vector<uint8_t> cut(bytes->begin(), bytes->end() - 1);
  EXPECT_EQ(decode_texture(cut, r, &back, "tex").id(), ErrorId::kMeshChunk);
  TextureTexels wrong = t;
  wrong.rgba.pop_back();
  EXPECT_EQ(encode_texture(r, wrong).status().id(), ErrorId::kContainerWriterMisuse);
  // Plain: the texels as they are.
  const TextureRecord plain{3, 2, kTextureSrgba8Plain};
  auto same = encode_texture(plain, t);
  ASSERT_TRUE(same.ok());
  EXPECT_EQ(*same, t.rgba);
  ASSERT_TRUE(decode_texture(*same, plain, &back, "tex").ok());
  EXPECT_EQ(back.rgba, t.rgba);
}

TEST(MeshTexture, MipChainAveragesInLinearLight) {
  EXPECT_EQ(mip_level_count(1, 1), 1u);
  EXPECT_EQ(mip_level_count(5, 3), 3u);  // 5x3, 2x1, 1x1
  EXPECT_EQ(mip_level_count(256, 16), 9u);
  // 3 x 2: level 1 is 1 x 1 from texels (0..1, 0..1); column 2 is not part of it.
  TextureTexels t{3, 2, {}};
  t.rgba = {0, 255, 10, 0,   255, 255, 10, 255, 99, 99, 99, 99,
            0, 255, 10, 100, 255, 255, 10, 101, 99, 99, 99, 99};
  const auto chain = mip_chain(t);
  ASSERT_EQ(chain.size(), 2u);
  ASSERT_EQ(chain[1].width, 1u);
  ASSERT_EQ(chain[1].height, 1u);
  // Red: half 0, half 1 in linear light = 0.5 linear = sRGB byte 188 (0.7354 * 255 = 187.5..).
  EXPECT_EQ(chain[1].rgba[0], srgb8_from_linear(0.5f));
  EXPECT_EQ(chain[1].rgba[0], 188);
  EXPECT_EQ(chain[1].rgba[1], 255);
  EXPECT_EQ(chain[1].rgba[2], 10);
  // Alpha as bytes: (0 + 255 + 100 + 101 + 2) / 4 = 114.
  EXPECT_EQ(chain[1].rgba[3], 114);
  // A side of 1 averages its one texel twice: 1 x 4 -> 1 x 2 -> 1 x 1.
  TextureTexels column{1, 4, std::vector<uint8_t>(16, 7)};
  column.rgba[12] = 200;
  const auto c2 = mip_chain(column);
  ASSERT_EQ(c2.size(), 3u);
  EXPECT_EQ(c2[1].width, 1u);
  EXPECT_EQ(c2[1].height, 2u);
  EXPECT_EQ(c2[1].rgba[0], 7);
  EXPECT_EQ(c2[1].rgba[4], srgb8_from_linear((linear_from_srgb8(7) + linear_from_srgb8(200)) / 2));
}

}  // namespace
}  // namespace calf::mesh
