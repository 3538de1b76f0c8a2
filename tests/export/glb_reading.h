// Reading a .glb in the export tests: its JSON and binary chunks (glTF 2.0 §4.4), and the check
// that an EXT_meshopt_compression file holds exactly the geometry of the plain file of the same
// export, decoded here by meshoptimizer's own decoders.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <meshoptimizer.h>
#include <nlohmann/json.hpp>

namespace calf::test {

struct Glb {
  nlohmann::json json;
  std::vector<uint8_t> bin;
};

// The chunks of `glb`; an empty JSON when it is not a GLB.
inline Glb read_glb(const std::vector<uint8_t>& glb) {
  Glb out;
  const auto u32 = [&](size_t at) {
    uint32_t v = 0;
    if (at + 4 <= glb.size()) std::memcpy(&v, glb.data() + at, 4);
    return v;
  };
  if (glb.size() < 20 || u32(0) != 0x46546C67u || u32(8) != glb.size()) return out;
  const size_t json_length = u32(12);
  if (u32(16) != 0x4E4F534Au || 20 + json_length > glb.size()) return out;
  out.json =
      nlohmann::json::parse(glb.begin() + 20, glb.begin() + 20 + json_length, nullptr, false);
  const size_t bin_at = 20 + json_length;
  if (bin_at + 8 <= glb.size() && u32(bin_at + 4) == 0x004E4942u) {
    const size_t length = std::min<size_t>(u32(bin_at), glb.size() - bin_at - 8);
    out.bin.assign(glb.begin() + bin_at + 8, glb.begin() + bin_at + 8 + length);
  }
  return out;
}

// The bytes of bufferView `v` of a GLB whose views all lie in its binary chunk.
inline std::vector<uint8_t> view_bytes(const Glb& glb, size_t v) {
  const nlohmann::json& view = glb.json["bufferViews"][v];
  const size_t at = view.value("byteOffset", size_t{0}), length = view["byteLength"];
  if (at + length > glb.bin.size()) return {};
  return std::vector<uint8_t>(glb.bin.begin() + at, glb.bin.begin() + at + length);
}

// A triangle list's triangles, each rotated to start at its smallest index (meshoptimizer's
// index codec may rotate a triangle, keeping its winding).
inline std::vector<std::array<uint32_t, 3>> canonical_triangles(const std::vector<uint8_t>& bytes) {
  std::vector<uint32_t> indices(bytes.size() / 4);
  std::memcpy(indices.data(), bytes.data(), indices.size() * 4);
  std::vector<std::array<uint32_t, 3>> out;
  for (size_t t = 0; t + 2 < indices.size(); t += 3) {
    std::array<uint32_t, 3> tri = {indices[t], indices[t + 1], indices[t + 2]};
    while (tri[0] != std::min({tri[0], tri[1], tri[2]})) tri = {tri[1], tri[2], tri[0]};
    out.push_back(tri);
  }
  return out;
}

// `compressed` (an export with GltfOptions::meshopt) against `plain` (the same export without):
// the same views in the same order; every vertex and index view of `plain` is, in `compressed`,
// an EXT_meshopt_compression view of the same length in the fallback buffer 1 (no data, marked
// fallback) whose compressed bytes in buffer 0 decode to the plain view's bytes (triangles in the
// same order, each possibly rotated); the other views (images) hold the same bytes;
// EXT_meshopt_compression is used and required. Returns the compressed views' bytes (encoded,
// plain) through the pointers.
inline void expect_meshopt_equals_plain(const Glb& plain, const Glb& compressed, size_t* encoded,
                                        size_t* decoded) {
  *encoded = *decoded = 0;
  ASSERT_FALSE(plain.json.is_discarded());
  ASSERT_FALSE(compressed.json.is_discarded());
  const nlohmann::json& j = compressed.json;
  const auto has = [&](const char* list) {
    const nlohmann::json names = j.value(list, nlohmann::json::array());
    return std::find(names.begin(), names.end(), "EXT_meshopt_compression") != names.end();
  };
  EXPECT_TRUE(has("extensionsUsed"));
  EXPECT_TRUE(has("extensionsRequired"));
  ASSERT_EQ(j["buffers"].size(), 2u);
  EXPECT_FALSE(j["buffers"][0].contains("uri")) << "buffer 0 is the GLB's binary chunk";
  EXPECT_FALSE(j["buffers"][1].contains("uri"));
  EXPECT_EQ(j["buffers"][1]["extensions"]["EXT_meshopt_compression"]["fallback"], true);
  const size_t fallback_length = j["buffers"][1]["byteLength"];
  ASSERT_EQ(j["bufferViews"].size(), plain.json["bufferViews"].size());
  for (size_t v = 0; v < j["bufferViews"].size(); ++v) {
    const nlohmann::json& view = j["bufferViews"][v];
    const std::vector<uint8_t> want = view_bytes(plain, v);
    ASSERT_EQ(view["byteLength"], want.size()) << "view " << v;
    const int target = plain.json["bufferViews"][v].value("target", 0);
    if (target == 0) {  // an image
      EXPECT_EQ(view.value("buffer", -1), 0);
      EXPECT_EQ(view_bytes(compressed, v), want) << "view " << v;
      continue;
    }
    ASSERT_TRUE(view.contains("extensions")) << "view " << v;
    const nlohmann::json& ext = view["extensions"]["EXT_meshopt_compression"];
    EXPECT_EQ(view["buffer"], 1);
    EXPECT_LE(view.value("byteOffset", size_t{0}) + want.size(), fallback_length);
    EXPECT_EQ(ext["buffer"], 0);
    const size_t at = ext.value("byteOffset", size_t{0}), length = ext["byteLength"];
    const size_t stride = ext["byteStride"], count = ext["count"];
    ASSERT_LE(at + length, compressed.bin.size());
    ASSERT_EQ(stride * count, want.size());
    std::vector<uint8_t> got(want.size());
    const uint8_t* data = compressed.bin.data() + at;
    if (target == 34963) {  // ELEMENT_ARRAY_BUFFER
      EXPECT_EQ(ext["mode"], "TRIANGLES");
      ASSERT_EQ(meshopt_decodeIndexBuffer(got.data(), count, stride, data, length), 0);
      EXPECT_EQ(canonical_triangles(got), canonical_triangles(want)) << "view " << v;
    } else {
      EXPECT_EQ(ext["mode"], "ATTRIBUTES");
      ASSERT_EQ(meshopt_decodeVertexBuffer(got.data(), count, stride, data, length), 0);
      EXPECT_EQ(got, want) << "view " << v;
    }
    *encoded += length;
    *decoded += want.size();
  }
}

}  // namespace calf::test
