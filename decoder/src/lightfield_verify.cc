// Whole-track verification through the reference decoder; the rules are in the public header.
#include "calf/decoder/lightfield_verify.h"

#include <bit>
#include <cstdio>
#include <cstring>

#include "calf/format/container_codec.h"

namespace calf::decoder {
namespace {

// Appends `v` little-endian: the hash is of the file-independent value, not of the host's bytes.
template <class T>
void put_le(std::vector<uint8_t>& out, T v) {
  for (size_t i = 0; i < sizeof(T); ++i) out.push_back(static_cast<uint8_t>(v >> (8 * i)));
}

}  // namespace

uint64_t face_hash(const LightfieldFace& face) {
  std::vector<uint8_t> bytes;
  bytes.reserve(face.colour.size() * 4 + face.depth.size() * 2 + face.material.size());
  for (float c : face.colour) put_le(bytes, std::bit_cast<uint32_t>(c));
  for (uint16_t d : face.depth) put_le(bytes, d);
  bytes.insert(bytes.end(), face.material.begin(), face.material.end());
  // SPEC §14 item 4, a track with coverage only: per texel its mask (u16) and near count (u8).
  for (const lf::CoverageTexel& t : face.coverage) {
    put_le(bytes, t.mask);
    bytes.push_back(t.near);
  }
  return container::hash64(bytes);
}

LightfieldVerifyResult verify_lightfield_track(const container::Reader& reader, uint16_t track,
                                               bool with_hashes, size_t max_problems) {
  LightfieldVerifyResult result;
  const std::string name = "track " + std::to_string(track);
  Expected<LightfieldReference> ref = LightfieldReference::open(reader, track);
  if (!ref.ok()) {
    result.problems.push_back(ref.status().with_context(name));
    return result;
  }
  const auto& h = ref->header();
  // Faces that failed once are skipped afterwards: a broken chunk breaks every frame it serves,
  // and one line per face says enough.
  std::vector<bool> failed(size_t{h.view_count} * 6, false);
  for (uint32_t v = 0; v < h.view_count; ++v) {
    if (ref->view_problem(v).ok()) continue;
    for (uint32_t f = 0; f < 6; ++f) failed[size_t{v} * 6 + f] = true;
    result.problems.push_back(ref->view_problem(v).with_context(name));
    if (result.problems.size() >= max_problems) return result;
  }
  LightfieldFace face;
  for (uint32_t frame = 0; frame < h.frame_count; ++frame) {
    for (uint32_t v = 0; v < h.view_count; ++v) {
      for (uint32_t f = 0; f < 6; ++f) {
        if (failed[size_t{v} * 6 + f]) continue;
        const Status st = ref->decode_face(v, f, frame, &face);
        if (!st.ok()) {
          failed[size_t{v} * 6 + f] = true;
          result.problems.push_back(st.with_context(name + " frame " + std::to_string(frame)));
          if (result.problems.size() >= max_problems) {
            result.hashes.clear();  // hashes only of a track without problems
            return result;
          }
          continue;
        }
        ++result.faces_decoded;
        if (with_hashes) result.hashes.push_back({frame, v, f, face_hash(face)});
      }
    }
  }
  if (!result.problems.empty()) result.hashes.clear();
  return result;
}

std::string face_hash_line(uint16_t track, const FaceHash& h) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "track %u frame %u view %u face %u %016llx", unsigned{track},
                h.frame, h.view, h.face, static_cast<unsigned long long>(h.hash));
  return buf;
}

}  // namespace calf::decoder
