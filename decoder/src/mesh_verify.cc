// Whole-track verification of a mesh track; the rules are in the public header.
#include "calf/decoder/mesh_verify.h"

#include <bit>
#include <cstdio>

#include "calf/format/container_codec.h"

namespace calf::decoder {
namespace {

void put(std::vector<uint8_t>& out, uint32_t v) {
  for (int i = 0; i < 4; ++i) out.push_back(static_cast<uint8_t>(v >> (8 * i)));
}
void put_floats(std::vector<uint8_t>& out, const std::vector<float>& a) {
  for (float f : a) put(out, std::bit_cast<uint32_t>(f));
}
void put_words(std::vector<uint8_t>& out, const std::vector<uint32_t>& a) {
  for (uint32_t w : a) put(out, w);
}

std::string line(uint16_t track, const char* what, uint32_t i, uint64_t hash) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "track %u %s %u %016llx", unsigned{track}, what, i,
                static_cast<unsigned long long>(hash));
  return buf;
}

}  // namespace

uint64_t prototype_hash(const MeshPrototype& p) {
  std::vector<uint8_t> b;
  put_floats(b, p.positions);
  put_floats(b, p.normals);
  put_floats(b, p.colours);
  put_words(b, p.indices);
  put_words(b, p.triangle_materials);
  put_floats(b, p.state_times);
  put_floats(b, p.state_positions);
  put_floats(b, p.uvs);
  return container::hash64(b);
}

uint64_t texture_hash(const mesh::TextureTexels& t) {
  std::vector<uint8_t> b;
  put(b, t.width);
  put(b, t.height);
  b.insert(b.end(), t.rgba.begin(), t.rgba.end());
  return container::hash64(b);
}

uint64_t object_hash(const MeshObject& o) {
  std::vector<uint8_t> b;
  put(b, o.prototype);
  put(b, o.material);
  put(b, o.all_triangles ? 1 : 0);
  for (const auto& t : o.transforms) {
    for (float f : t) put(b, std::bit_cast<uint32_t>(f));
  }
  put_words(b, o.triangles);
  return container::hash64(b);
}

MeshVerifyResult verify_mesh_track(const container::Reader& reader, uint16_t track,
                                   bool with_hashes, size_t max_problems) {
  MeshVerifyResult result;
  const std::string name = "track " + std::to_string(track);
  container::ChunkQuery q;
  q.track = track;
  q.stream = static_cast<uint16_t>(container::MeshStream::kIndex);
  if (reader.find_chunks(q).empty()) {
    result.skipped = true;
    return result;
  }
  Expected<MeshTrack> t = MeshTrack::open(reader, track);
  if (!t.ok()) {
    result.problems.push_back(t.status().with_context(name));
    return result;
  }
  auto note = [&](const Status& st) {
    result.problems.push_back(st.with_context(name));
    return result.problems.size() >= max_problems;
  };
  MeshPrototype p;
  for (uint32_t i = 0; i < t->prototype_count(); ++i) {
    const Status st = t->prototype(i, &p);
    if (!st.ok()) {
      if (note(st)) break;
      continue;
    }
    ++result.prototypes_decoded;
    if (with_hashes) result.hash_lines.push_back(line(track, "prototype", i, prototype_hash(p)));
  }
  MeshObject o;
  for (uint32_t i = 0; i < t->object_count() && result.problems.size() < max_problems; ++i) {
    const Status st = t->object(i, &o);
    if (!st.ok()) {
      if (note(st)) break;
      continue;
    }
    ++result.objects_decoded;
    if (with_hashes) result.hash_lines.push_back(line(track, "object", i, object_hash(o)));
  }
  mesh::TextureTexels texels;
  for (uint32_t i = 0; i < t->texture_count() && result.problems.size() < max_problems; ++i) {
    const Status st = t->texture(i, &texels);
    if (!st.ok()) {
      if (note(st)) break;
      continue;
    }
    ++result.textures_decoded;
    if (with_hashes) result.hash_lines.push_back(line(track, "texture", i, texture_hash(texels)));
  }
  if (!result.problems.empty()) result.hash_lines.clear();
  return result;
}

}  // namespace calf::decoder
