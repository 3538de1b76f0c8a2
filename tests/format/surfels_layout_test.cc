// The surfels track's chunk layouts (format/SPEC.md §11.3, calf/format/surfels_layout.h) with
// values worked out by hand from the SPEC text: level ranges, the index chunk's bytes, the
// decoded values of chosen codes, a level chunk's planes, and the prefix for a radius.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstring>
#include <vector>

#include "calf/format/surfels_layout.h"

namespace calf::surfels {
namespace {

TEST(SurfelsLayout, LevelsCutAtPowersOfTwoTimes1024) {
  EXPECT_EQ(level_count(0), 0u);
  EXPECT_EQ(level_count(1), 1u);
  EXPECT_EQ(level_count(1024), 1u);
  EXPECT_EQ(level_count(1025), 2u);
  EXPECT_EQ(level_count(2048), 2u);
  EXPECT_EQ(level_count(2049), 3u);
  EXPECT_EQ(level_count(100000), 8u);  // 1024 * 2^6 = 65536 < 100000 <= 131072
  EXPECT_EQ(level_count(kMaxSurfels), 17u);
  EXPECT_EQ(level_count(UINT64_MAX), 55u) << "the bounds saturate, no shift overflows";
  EXPECT_EQ(level_begin(0), 0u);
  EXPECT_EQ(level_begin(1), 1024u);
  EXPECT_EQ(level_begin(2), 2048u);
  EXPECT_EQ(level_begin(3), 4096u);
  EXPECT_EQ(level_end(0, 100), 100u);
  EXPECT_EQ(level_end(2, 3000), 3000u);
  EXPECT_EQ(level_end(1, 3000), 2048u);
  EXPECT_EQ(level_chunk_size(2, 3000), 13u * 952);
  EXPECT_EQ(level_chunk_size(0, 100000), 13u * 1024);
  EXPECT_EQ(level_chunk_size(7, 100000), 13u * (100000 - 65536));
  // The largest level chunk stays under the container's 1 GiB.
  EXPECT_LT(level_chunk_size(16, kMaxSurfels), uint64_t{1} << 30);
}

TEST(SurfelsLayout, PositionCodesSpanTheBox) {
  EXPECT_EQ(decode_position(0, -2.0f, 6.0f), -2.0f);
  EXPECT_EQ(decode_position(65535, -2.0f, 6.0f), 6.0f);
  // 8 / 65535 * 32768 - 2 = 2.0000610360...
  EXPECT_FLOAT_EQ(decode_position(32768, -2.0f, 6.0f), 2.0000610f);
  EXPECT_EQ(decode_position(1234, 3.5f, 3.5f), 3.5f) << "a flat axis";
  // Awkward floats still give the ends exactly.
  EXPECT_EQ(decode_position(65535, 0.1f, 0.7f), 0.7f);
  EXPECT_EQ(decode_position(0, 0.1f, 0.7f), 0.1f);
}

TEST(SurfelsLayout, OctahedralCodesDecodeToUnitNormals) {
  float n[3];
  // u = v = 0: a = b = -1, z = -1 < 0, folded to (0, 0): the -Z pole.
  decode_normal(0, 0, n);
  EXPECT_EQ(n[2], -1.0f);
  EXPECT_EQ(std::fabs(n[0]) + std::fabs(n[1]), 0.0f);
  // u = 65535, v = 32767: a = 1, b = -1/65535, z = -1/65535 < 0: folded a = (1 - 1/65535),
  // b = -0; nearly +X.
  decode_normal(65535, 32767, n);
  EXPECT_NEAR(n[0], 1.0, 1e-9);
  EXPECT_NEAR(n[1], 0.0, 1e-4);
  EXPECT_NEAR(n[2], -1.0 / 65535, 1e-6);
  // u = v = 32767: a = b = -1/65535, z = 1 - 2/65535: nearly +Z.
  decode_normal(32767, 32767, n);
  EXPECT_NEAR(n[2], 1.0, 1e-9);
  EXPECT_LT(n[0], 0.0f);
  EXPECT_LT(n[1], 0.0f);
  // Every code is a unit vector (a grid over the whole square).
  for (uint32_t u = 0; u <= 65535; u += 4369) {
    for (uint32_t v = 0; v <= 65535; v += 4369) {
      decode_normal(static_cast<uint16_t>(u), static_cast<uint16_t>(v), n);
      EXPECT_NEAR(double{n[0]} * n[0] + double{n[1]} * n[1] + double{n[2]} * n[2], 1.0, 1e-6);
    }
  }
}

TEST(SurfelsLayout, ColoursAreTheSrgbCurve) {
  EXPECT_EQ(decode_colour(0), 0.0f);
  EXPECT_EQ(decode_colour(255), 1.0f);
  EXPECT_FLOAT_EQ(decode_colour(10), static_cast<float>(10 / 255.0 / 12.92));
  EXPECT_FLOAT_EQ(decode_colour(128),
                  static_cast<float>(std::pow((128 / 255.0 + 0.055) / 1.055, 2.4)));
}

void put32(std::vector<uint8_t>& b, uint32_t v) {
  for (int i = 0; i < 4; ++i) b.push_back(static_cast<uint8_t>(v >> (8 * i)));
}

// An index chunk written byte by byte from SPEC §11.3.2.
std::vector<uint8_t> index_bytes(uint32_t n, uint32_t pm, float rm) {
  std::vector<uint8_t> b;
  put32(b, 1);  // layout version
  put32(b, 0);  // flags
  put32(b, 3);  // mesh track
  put32(b, 2);  // two prototypes
  // prototype 0: n surfels, colour is base
  put32(b, n);
  put32(b, kColourIsBase);
  put32(b, pm);
  put32(b, std::bit_cast<uint32_t>(rm));
  for (float f : {-1.0f, -2.0f, -3.0f, 1.0f, 2.0f, 3.0f}) put32(b, std::bit_cast<uint32_t>(f));
  // prototype 1: none
  for (int i = 0; i < 10; ++i) put32(b, 0);
  return b;
}

TEST(SurfelsLayout, IndexChunkBytesAndChecks) {
  const auto bytes = index_bytes(5000, 1000, 0.25f);
  ASSERT_EQ(bytes.size(), 16u + 2 * 40);
  auto x = parse_index(bytes, "index");
  ASSERT_TRUE(x.ok()) << x.status().to_string();
  EXPECT_EQ(x->mesh_track, 3u);
  ASSERT_EQ(x->prototypes.size(), 2u);
  EXPECT_EQ(x->prototypes[0].surfel_count, 5000u);
  EXPECT_EQ(x->prototypes[0].flags, kColourIsBase);
  EXPECT_EQ(x->prototypes[0].prefix_radius, 0.25f);
  EXPECT_EQ(x->prototypes[0].box_max[2], 3.0f);
  auto back = serialize_index(*x);
  ASSERT_TRUE(back.ok());
  EXPECT_EQ(*back, bytes);
  EXPECT_EQ(parse_index(index_bytes(5000, 5001, 0.25f), "i").status().id(), ErrorId::kSurfelsValue);
  EXPECT_EQ(parse_index(index_bytes(5000, 0, 0.25f), "i").status().id(), ErrorId::kSurfelsValue);
  EXPECT_EQ(parse_index(index_bytes(5000, 10, 0.0f), "i").status().id(), ErrorId::kSurfelsValue);
  EXPECT_EQ(parse_index(index_bytes(5000, 10, INFINITY), "i").status().id(),
            ErrorId::kSurfelsValue);
  EXPECT_EQ(parse_index(index_bytes(kMaxSurfels + 1, 10, 1.0f), "i").status().id(),
            ErrorId::kSurfelsLimit);
  EXPECT_EQ(parse_index(std::vector<uint8_t>(3, 0), "i").status().id(), ErrorId::kSurfelsChunk);
  auto v2 = bytes;
  v2[0] = 2;
  EXPECT_EQ(parse_index(v2, "i").status().id(), ErrorId::kSurfelsUnsupported);
  // The writer refuses what the reader refuses.
  IndexChunk bad = *x;
  bad.prototypes[1].prefix_count = 1;
  EXPECT_EQ(serialize_index(bad).status().id(), ErrorId::kContainerWriterMisuse);
}

TEST(SurfelsLayout, LevelChunkPlanes) {
  // Two surfels, codes chosen so every byte is distinct.
  SurfelCodes c;
  c.positions = {0x0102, 0x0304, 0x0506, 0x0708, 0x090a, 0x0b0c};
  c.normals = {0x1112, 0x1314, 0x1516, 0x1718};
  c.colours = {0x21, 0x22, 0x23, 0x24, 0x25, 0x26};
  auto raw = encode_level(c, 0, 2);
  ASSERT_TRUE(raw.ok());
  // Positions: words x0 x1 y0 y1 z0 z1, low bytes then high bytes; normals u0 u1 v0 v1 likewise;
  // colours r0 r1 g0 g1 b0 b1.
  const std::vector<uint8_t> want = {0x02, 0x08, 0x04, 0x0a, 0x06, 0x0c, 0x01, 0x07, 0x03,
                                     0x09, 0x05, 0x0b, 0x12, 0x16, 0x14, 0x18, 0x11, 0x15,
                                     0x13, 0x17, 0x21, 0x24, 0x22, 0x25, 0x23, 0x26};
  EXPECT_EQ(*raw, want);
  PrototypeRecord r;
  r.surfel_count = 2;
  r.prefix_count = 1;
  r.prefix_radius = 1;
  for (int k = 0; k < 3; ++k) r.box_max[k] = 65535.0f;  // code q decodes to q
  SurfelArrays out;
  ASSERT_TRUE(decode_level(want, r, 0, &out, "level").ok());
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out.positions, (std::vector<float>{0x0102, 0x0304, 0x0506, 0x0708, 0x090a, 0x0b0c}));
  float n[3];
  decode_normal(0x1516, 0x1718, n);  // surfel 1: (u, v) = codes 2 and 3
  EXPECT_EQ(out.normals[3], n[0]);
  EXPECT_EQ(out.colours[5], decode_colour(0x26));
  // A chunk of another size is E230; a level appended out of order is the caller's error.
  SurfelArrays again;
  EXPECT_EQ(decode_level(std::vector<uint8_t>(25), r, 0, &again, "level").id(),
            ErrorId::kSurfelsChunk);
  EXPECT_EQ(decode_level(want, r, 0, &out, "level").id(), ErrorId::kInvalidArgument);
  EXPECT_EQ(decode_level(want, r, 1, &again, "level").id(), ErrorId::kInvalidArgument);
}

TEST(SurfelsLayout, PrefixForRadiusIsPaperEquationOne) {
  PrototypeRecord r;
  r.surfel_count = 10000;
  r.prefix_count = 1000;
  r.prefix_radius = 0.1f;
  const double rm = 0.1f;  // the float's value
  EXPECT_EQ(prefix_for_radius(r, rm / 2), 4000u);
  EXPECT_EQ(prefix_for_radius(r, rm * 2), 250u);
  EXPECT_EQ(prefix_for_radius(r, rm), 1000u);
  EXPECT_EQ(prefix_for_radius(r, rm / 4), 10000u) << "clamped to N";
  EXPECT_EQ(prefix_for_radius(r, 1e-300), 10000u);
  EXPECT_EQ(prefix_for_radius(r, 1e6), 1u) << "at least one surfel";
  EXPECT_EQ(prefix_for_radius(r, 0.0), 10000u);
  EXPECT_EQ(prefix_for_radius(r, -1.0), 10000u);
  EXPECT_EQ(prefix_for_radius(r, std::nan("")), 10000u);
  r.surfel_count = 0;
  EXPECT_EQ(prefix_for_radius(r, 0.05), 0u);
}

}  // namespace
}  // namespace calf::surfels
