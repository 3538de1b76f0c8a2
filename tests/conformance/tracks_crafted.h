// Test-only generator of the crafted tiles, surfels and mesh conformance clips
// (tests/conformance/{tiles,surfels,mesh}/crafted_*.calf, format/SPEC.md §11.2 – §11.4, §14):
// clips whose every chunk byte is placed here, from SPEC's layouts, not by calf's encoders or
// layout coders, so that they reach what the encoded clips never do — every BC7 mode, partition,
// rotation and index selection in a tiles atlas whose width, height and last band are not
// multiples of 4, tiles and mesh values at their edges (−0, subnormals, U = 0 and U = W), a tiles
// track with no tile, surfel prototypes of one level exactly, of three levels and with a flat
// box, every colour byte, several tracks of one kind in one file, tracks that are not track 0, a
// surfels track before its mesh track, every mesh prototype flag and texture coding, an empty
// prototype, an empty subset, optional chunk flags and zstd content checksums. Every value comes
// from a fixed pseudo-random sequence as exact dyadic numbers (no float rounding anywhere) and
// the chunks are stored as they are or as hand-built zstd Raw_Block frames, so the files never
// depend on a compiler or a library version. Header-only: tests/decoder/tracks_crafted_test.cc
// checks the committed files against it; the runners read only the files.
#pragma once

#include <algorithm>
#include <bit>
#include <cstdint>
#include <string>
#include <vector>

#include "calf/format/container.h"
#include "container_corpus.h"
#include "lightfield_crafted.h"

namespace calf::conformance::tracks_crafted {

using Bytes = std::vector<uint8_t>;
using crafted::Rng;

// Little-endian appender.
struct Put {
  Bytes& b;
  void u16(uint16_t v) {
    for (int i = 0; i < 2; ++i) b.push_back(static_cast<uint8_t>(v >> (8 * i)));
  }
  void u32(uint32_t v) {
    for (int i = 0; i < 4; ++i) b.push_back(static_cast<uint8_t>(v >> (8 * i)));
  }
  void u64(uint64_t v) {
    for (int i = 0; i < 8; ++i) b.push_back(static_cast<uint8_t>(v >> (8 * i)));
  }
  void f32(float v) { u32(std::bit_cast<uint32_t>(v)); }
  void f64(double v) { u64(std::bit_cast<uint64_t>(v)); }
  void timing(uint32_t frames) {  // SPEC §11: frame_count, fps 24 / 1
    u32(frames);
    u32(24);
    u32(1);
  }
};

// n 32-bit words as four byte planes (SPEC §11.2.3, §11.4.1).
inline void put_byte_planes(Bytes& out, const std::vector<uint32_t>& words) {
  for (int k = 0; k < 4; ++k) {
    for (uint32_t w : words) out.push_back(static_cast<uint8_t>(w >> (8 * k)));
  }
}

// A sequence (SPEC §11.4.1): word i minus word i − 1, as byte planes.
inline void put_sequence(Bytes& out, const std::vector<uint32_t>& values) {
  std::vector<uint32_t> d(values.size());
  for (size_t i = 0; i < values.size(); ++i) d[i] = values[i] - (i ? values[i - 1] : 0u);
  put_byte_planes(out, d);
}

// A dyadic float in [-range, range] with a 1/64 step, −0 and a subnormal now and then.
inline float dyadic(Rng& rng, int range) {
  switch (rng.below(16)) {
    case 0:
      return -0.0f;
    case 1:
      return 0x1p-140f;  // subnormal
    default:
      return static_cast<float>(
                 static_cast<int>(rng.below(static_cast<uint32_t>(128 * range + 1))) - 64 * range) /
             64.0f;
  }
}

// Writes chunks in turn as stored bytes, as a zstd frame with a content checksum, and as stored
// bytes given optional chunk flags (bits 8 and 15, SPEC §6.2) once the file is written.
struct Chunks {
  container::Writer& w;
  uint32_t serial = 0;
  std::vector<uint32_t> flagged;
  Status add(const container::ChunkKeys& k, const Bytes& raw) {
    const uint32_t s = serial++;
    Expected<uint32_t> id =
        s % 3 == 1
            ? w.add_stored_chunk(
                  k,
                  container::StoredChunk{container::Compression::kZstd, raw.size(),
                                         container::corpus::raw_zstd_frame(raw, raw.size(), true)})
            : w.add_chunk(k, raw, container::Compression::kNone);
    if (!id.ok()) return id.status();
    if (s % 3 == 2) flagged.push_back(*id);
    return Status::Ok();
  }
};

// Sets optional flag bits on the chunk index entries `ids` of a file with a plain directory and
// re-seals the directory checksum (the chunk hashes cover only the stored bytes).
inline Status set_optional_flags(Bytes& file, const std::vector<uint32_t>& ids) {
  auto reader = container::Reader::open(container::memory_source(std::span<const uint8_t>(file)));
  if (!reader.ok()) return reader.status();
  const uint64_t dir = reader->header().directory_offset;
  const uint64_t index_at = file.size() - 8 - 64 * uint64_t{reader->header().chunk_count};
  for (size_t i = 0; i < ids.size(); ++i) {
    const uint16_t flags = i % 2 == 0 ? 0x0100 : 0x8100;
    uint8_t* p = &file[index_at + 64 * uint64_t{ids[i]} + 34];
    p[0] = static_cast<uint8_t>(flags);
    p[1] = static_cast<uint8_t>(flags >> 8);
  }
  const uint64_t sum =
      container::hash64(std::span<const uint8_t>(file).subspan(dir, file.size() - dir - 8));
  for (int i = 0; i < 8; ++i) file[file.size() - 8 + i] = static_cast<uint8_t>(sum >> (8 * i));
  return Status::Ok();
}

inline Expected<container::Writer> plain_writer(Bytes* file) {
  return container::Writer::create(
      container::memory_sink(file),
      container::CompressionOptions{.compress_directory = false, .store_when_larger = false});
}

// An unknown optional track (kind 0x7777) with one chunk, so that the next track is track 1.
inline Status add_unknown_track(container::Writer& w) {
  CALF_RETURN_IF_ERROR(w.add_track(0x7777, 0, Bytes{'c', 'r', 'a', 'f', 't'}).status());
  container::ChunkKeys k;
  k.stream = 1;
  return w.add_chunk(k, Bytes{1, 2, 3, 4, 5}, container::Compression::kNone).status();
}

// ---- Tiles (SPEC §11.2) --------------------------------------------------------------------

struct TilesSpec {
  uint32_t tiles, width, height, band_rows;
  uint16_t format;  // 8 BC7, 1 rgba8
};

// A tiles track: header, index, quads (SPEC §11.2.3's prediction, component and byte planes),
// then the atlas bands. BC7 blocks run through crafted::bc7_block's forced headers in atlas
// block order (row-major over the whole atlas), so every mode and partition occurs.
inline Status add_tiles_track(container::Writer& w, Chunks& chunks, const TilesSpec& s, Rng& rng) {
  Bytes header;
  Put h{header};
  h.timing(1);
  h.u32(s.tiles);
  h.u32(s.width);
  h.u32(s.height);
  h.u16(s.format);
  h.u16(0);
  CALF_ASSIGN_OR_RETURN(uint16_t track, w.add_track(2, 1, header));
  container::ChunkKeys k;
  k.track = track;
  Bytes index;
  Put ix{index};
  ix.u32(1);
  ix.u32(0);
  const double view_min[3] = {-2.5, 0.0, 1.0 / 1024}, view_max[3] = {2.5, 0.0, 3.0};  // y flat
  for (double v : view_min) ix.f64(v);
  for (double v : view_max) ix.f64(v);
  ix.u32(s.band_rows);
  k.stream = 0;
  CALF_RETURN_IF_ERROR(chunks.add(k, index));
  // Tiles: corner positions dyadic (−0, subnormals), W in (0, 4], U and V from 0 to W.
  const uint32_t n = s.tiles;
  std::vector<uint32_t> words(24 * size_t{n});
  for (uint32_t t = 0; t < n; ++t) {
    for (int c = 0; c < 4; ++c) {
      uint32_t* f = &words[24 * size_t{t} + 6 * c];
      for (int a = 0; a < 3; ++a) f[a] = std::bit_cast<uint32_t>(dyadic(rng, 100));
      const float wv = static_cast<float>(1 + rng.below(256)) / 64.0f;
      const float u = wv * (static_cast<float>(rng.below(17)) / 16.0f);
      const float v = wv * (static_cast<float>(rng.below(17)) / 16.0f);
      f[3] = std::bit_cast<uint32_t>(u);
      f[4] = std::bit_cast<uint32_t>(v);
      f[5] = std::bit_cast<uint32_t>(wv);
    }
  }
  std::vector<uint32_t> residuals(words.size());
  for (uint32_t t = 0; t < n; ++t) {
    for (uint32_t i = 0; i < 24; ++i) {
      const uint32_t pred =
          i < 6 ? (t ? words[24 * size_t{t - 1} + i] : 0u) : words[24 * size_t{t} + i % 6];
      residuals[size_t{i} * n + t] = words[24 * size_t{t} + i] - pred;
    }
  }
  Bytes quads;
  put_byte_planes(quads, residuals);
  k.stream = 2;
  CALF_RETURN_IF_ERROR(chunks.add(k, quads));
  // Atlas.
  const uint32_t bw = (s.width + 3) / 4, bh = (s.height + 3) / 4;
  Bytes blocks;
  if (s.format == 8) {
    blocks.resize(16 * size_t{bw} * bh);
    for (uint32_t i = 0; i < bw * bh; ++i) crafted::bc7_block(i, rng, &blocks[16 * size_t{i}]);
  } else {
    blocks.resize(4 * size_t{s.width} * s.height);
    for (uint8_t& b : blocks) b = rng.byte();
  }
  k.stream = 1;
  for (uint32_t b = 0, r0 = 0; r0 < s.height; ++b, r0 += s.band_rows) {
    const uint32_t r1 = std::min(r0 + s.band_rows, s.height);
    const size_t from = s.format == 8 ? 16 * size_t{bw} * (r0 / 4) : 4 * size_t{s.width} * r0;
    const size_t to = s.format == 8 ? 16 * size_t{bw} * ((r1 + 3) / 4) : 4 * size_t{s.width} * r1;
    k.region = b;
    CALF_RETURN_IF_ERROR(chunks.add(k, Bytes(blocks.begin() + static_cast<std::ptrdiff_t>(from),
                                             blocks.begin() + static_cast<std::ptrdiff_t>(to))));
  }
  return Status::Ok();
}

// crafted_bc7_multi: track 0 an unknown optional kind; track 1 tiles with a BC7 atlas of 74 x 66
// texels (19 x 17 = 323 blocks: the 286 forced headers, then random modes; a last block column
// of 2 texels), bands of 20 rows (20, 20, 20, 6: the last band's second block row has 2 rows);
// track 2 tiles with no tile and a 5 x 9 rgba8 atlas in bands of 4 rows (4, 4, 1).
inline Expected<Bytes> make_tiles_clip() {
  Bytes file;
  CALF_ASSIGN_OR_RETURN(container::Writer w, plain_writer(&file));
  CALF_RETURN_IF_ERROR(w.set_metadata("calf.conformance", "crafted crafted_bc7_multi"));
  CALF_RETURN_IF_ERROR(add_unknown_track(w));
  Chunks chunks{w, 0, {}};
  Rng rng{0x711E5};
  CALF_RETURN_IF_ERROR(add_tiles_track(w, chunks, {7, 74, 66, 20, 8}, rng));
  CALF_RETURN_IF_ERROR(add_tiles_track(w, chunks, {0, 5, 9, 4, 1}, rng));
  CALF_RETURN_IF_ERROR(w.finish());
  CALF_RETURN_IF_ERROR(set_optional_flags(file, chunks.flagged));
  return file;
}

// ---- Mesh (SPEC §11.4) ---------------------------------------------------------------------

struct MeshProto {
  uint32_t v, t, flags, states, triangles_of;
};
struct MeshObject {
  uint32_t prototype, material, transforms, flags;
  std::vector<uint32_t> subset;  // sorted triangle ids, without the all-triangles flag
};
struct MeshSpec {
  uint32_t frames;
  std::vector<uint32_t> material_textures;  // one per material; empty: layout 1
  std::vector<uint32_t> texture_sizes;      // (width, height, coding) per texture
  std::vector<MeshProto> prototypes;
  std::vector<MeshObject> objects;
};

inline std::vector<uint32_t> vec3_words(Rng& rng, uint32_t v, int range) {
  std::vector<uint32_t> w(3 * size_t{v});
  for (uint32_t& x : w) x = std::bit_cast<uint32_t>(dyadic(rng, range));
  return w;  // component planes: word c·V + i
}

inline Expected<uint16_t> add_mesh_track(container::Writer& w, Chunks& chunks, const MeshSpec& s,
                                         Rng& rng) {
  const bool layout2 = !s.material_textures.empty();
  uint64_t vertices = 0, triangles = 0;
  for (const MeshProto& p : s.prototypes) vertices += p.v;
  for (const MeshObject& o : s.objects) {
    triangles += o.flags & 1 ? s.prototypes[o.prototype].t : o.subset.size();
  }
  Bytes header;
  Put h{header};
  h.timing(s.frames);
  h.u64(vertices);
  h.u64(triangles);
  h.u32(0);
  h.u16(0);
  CALF_ASSIGN_OR_RETURN(uint16_t track, w.add_track(4, 0, header));
  container::ChunkKeys k;
  k.track = track;
  Bytes index;
  Put ix{index};
  ix.u32(layout2 ? 2 : 1);
  ix.u32(0);
  for (double v : {-1.0, -0.5, -0.0, 1.0, 0.5, 0.0}) ix.f64(v);
  const uint32_t materials = layout2 ? static_cast<uint32_t>(s.material_textures.size()) : 2;
  ix.u32(materials);
  for (uint32_t m = 0; m < materials; ++m) {
    for (int c = 0; c < 3; ++c) ix.f32(static_cast<float>(rng.below(257)) / 256.0f);
    for (int c = 0; c < 3; ++c) ix.f32(static_cast<float>(rng.below(65)) / 16.0f);
  }
  ix.u32(static_cast<uint32_t>(s.prototypes.size()));
  for (const MeshProto& p : s.prototypes) {
    for (uint32_t v : {p.v, p.t, p.flags, p.states, p.triangles_of}) ix.u32(v);
  }
  ix.u32(static_cast<uint32_t>(s.objects.size()));
  for (size_t o = 0; o < s.objects.size(); ++o) {
    const MeshObject& ob = s.objects[o];
    const uint32_t kk =
        ob.flags & 1 ? s.prototypes[ob.prototype].t : static_cast<uint32_t>(ob.subset.size());
    for (uint32_t v :
         {static_cast<uint32_t>(10 + o), ob.prototype, ob.material, ob.transforms, ob.flags, kk}) {
      ix.u32(v);
    }
  }
  if (layout2) {
    ix.u32(static_cast<uint32_t>(s.texture_sizes.size() / 3));
    for (size_t x = 0; x < s.texture_sizes.size(); x += 3) {
      ix.u32(s.texture_sizes[x]);
      ix.u32(s.texture_sizes[x + 1]);
      ix.u32(s.texture_sizes[x + 2]);
      ix.u32(0);
    }
    for (uint32_t t : s.material_textures) ix.u32(t);
  }
  k.stream = 0;
  CALF_RETURN_IF_ERROR(chunks.add(k, index));
  for (uint32_t p = 0; p < s.prototypes.size(); ++p) {
    const MeshProto& pr = s.prototypes[p];
    k.region = p;
    Bytes vx;
    const std::vector<uint32_t> positions = vec3_words(rng, pr.v, 50);
    put_byte_planes(vx, positions);
    if (pr.flags & 1) {  // normals: non-zero (x is never 0)
      std::vector<uint32_t> nrm = vec3_words(rng, pr.v, 2);
      for (uint32_t i = 0; i < pr.v; ++i) {
        nrm[i] = std::bit_cast<uint32_t>(static_cast<float>(1 + rng.below(64)) / 32.0f);
      }
      put_byte_planes(vx, nrm);
    }
    if (pr.flags & 2) {  // colours in [0, 1]
      std::vector<uint32_t> col(3 * size_t{pr.v});
      for (uint32_t& c : col)
        c = std::bit_cast<uint32_t>(static_cast<float>(rng.below(257)) / 256.0f);
      put_byte_planes(vx, col);
    }
    if (pr.flags & 8) {  // UVs, beyond [0, 1] too
      std::vector<uint32_t> uv(2 * size_t{pr.v});
      for (uint32_t& c : uv) c = std::bit_cast<uint32_t>(dyadic(rng, 3));
      put_byte_planes(vx, uv);
    }
    std::vector<uint32_t> times;
    for (uint32_t i = 0; i < pr.states; ++i) {
      times.push_back(std::bit_cast<uint32_t>(static_cast<float>(i * 5 + rng.below(5)) / 8.0f));
    }
    put_sequence(vx, times);
    std::vector<uint32_t> ref = positions;
    for (uint32_t i = 0; i < pr.states; ++i) {
      const std::vector<uint32_t> st = vec3_words(rng, pr.v, 50);
      std::vector<uint32_t> d(st.size());
      for (size_t j = 0; j < st.size(); ++j) d[j] = st[j] - ref[j];
      put_byte_planes(vx, d);
      ref = st;
    }
    k.stream = 1;
    CALF_RETURN_IF_ERROR(chunks.add(k, vx));
    if (pr.triangles_of != p) continue;
    Bytes tri;
    std::vector<uint32_t> indices(3 * size_t{pr.t});
    for (uint32_t& i : indices) i = rng.below(pr.v);
    put_sequence(tri, indices);
    if (pr.flags & 4) {
      std::vector<uint32_t> mats(pr.t);
      for (uint32_t& m : mats) {
        m = rng.below(materials + 1);
        if (m == materials) m = 0xFFFFFFFFu;
      }
      put_sequence(tri, mats);
    }
    k.stream = 2;
    CALF_RETURN_IF_ERROR(chunks.add(k, tri));
  }
  for (uint32_t o = 0; o < s.objects.size(); ++o) {
    const MeshObject& ob = s.objects[o];
    std::vector<uint32_t> m(12 * size_t{ob.transforms});
    for (uint32_t f = 0; f < ob.transforms; ++f) {
      for (uint32_t e = 0; e < 12; ++e) {
        m[size_t{e} * ob.transforms + f] = std::bit_cast<uint32_t>(dyadic(rng, 4));
      }
    }
    std::vector<uint32_t> d(m.size());  // element planes, each predicted by its previous transform
    for (uint32_t e = 0; e < 12; ++e) {
      for (uint32_t f = 0; f < ob.transforms; ++f) {
        const size_t i = size_t{e} * ob.transforms + f;
        d[i] = m[i] - (f ? m[i - 1] : 0u);
      }
    }
    Bytes vis;
    put_byte_planes(vis, d);
    if (!(ob.flags & 1)) {  // maximal runs of the sorted subset
      std::vector<uint32_t> gaps, lens;
      uint32_t end = 0;
      for (size_t i = 0; i < ob.subset.size(); ++i) {
        if (i > 0 && ob.subset[i] == ob.subset[i - 1] + 1) {
          ++lens.back();
        } else {
          gaps.push_back(ob.subset[i] - end);
          lens.push_back(1);
        }
        end = ob.subset[i] + 1;
      }
      Put{vis}.u32(static_cast<uint32_t>(gaps.size()));
      put_byte_planes(vis, gaps);
      put_byte_planes(vis, lens);
    }
    k.region = o;
    k.stream = 3;
    CALF_RETURN_IF_ERROR(chunks.add(k, vis));
  }
  for (uint32_t x = 0; 3 * size_t{x} < s.texture_sizes.size(); ++x) {
    Bytes tex(4 * size_t{s.texture_sizes[3 * x]} * s.texture_sizes[3 * x + 1]);
    for (uint8_t& b : tex) b = rng.byte();  // texels (coding 1) or MED residuals (coding 0)
    k.region = x;
    k.stream = 4;
    CALF_RETURN_IF_ERROR(chunks.add(k, tex));
  }
  return track;
}

// crafted_layout2_multi: track 0 an unknown optional kind; track 1 a layout-2 mesh of 3 frames —
// a prototype with every flag (normals, colours, triangle materials naming every material and
// the object's, UVs) and 2 vertex states, a prototype drawing its triangles with UVs only, an
// empty prototype (no vertex, no triangle), a prototype with colours and 1 state; objects with a
// subset of two runs (the first after a gap, the last ending at the last triangle) and per-frame
// transforms, with all triangles, with an empty subset, and of the empty prototype; textures
// 5 x 3 MED-coded, 1 x 1 and 4 x 2 plain, materials with a texture, none and the last texture;
// track 2 a layout-1 mesh of one prototype and one object.
inline MeshSpec rich_mesh() {
  MeshSpec s;
  s.frames = 3;
  s.material_textures = {0, 0xFFFFFFFFu, 2};
  s.texture_sizes = {5, 3, 0, 1, 1, 1, 4, 2, 1};
  s.prototypes = {{5, 5, 15, 2, 0}, {5, 5, 12, 0, 0}, {0, 0, 0, 0, 2}, {4, 2, 2, 1, 3}};
  s.objects = {{0, 0, 3, 0, {1, 3, 4}}, {1, 1, 1, 1, {}}, {3, 2, 3, 0, {}}, {2, 0, 1, 1, {}}};
  return s;
}
inline MeshSpec small_mesh(uint32_t prototypes) {
  MeshSpec s;
  s.frames = 1;
  for (uint32_t p = 0; p < prototypes; ++p) s.prototypes.push_back({3, 1, 0, 0, p});
  s.objects = {{0, 1, 1, 1, {}}};
  return s;
}

inline Expected<Bytes> make_mesh_clip() {
  Bytes file;
  CALF_ASSIGN_OR_RETURN(container::Writer w, plain_writer(&file));
  CALF_RETURN_IF_ERROR(w.set_metadata("calf.conformance", "crafted crafted_layout2_multi"));
  CALF_RETURN_IF_ERROR(add_unknown_track(w));
  Chunks chunks{w, 0, {}};
  Rng rng{0x4E54};
  CALF_RETURN_IF_ERROR(add_mesh_track(w, chunks, rich_mesh(), rng).status());
  CALF_RETURN_IF_ERROR(add_mesh_track(w, chunks, small_mesh(1), rng).status());
  CALF_RETURN_IF_ERROR(w.finish());
  CALF_RETURN_IF_ERROR(set_optional_flags(file, chunks.flagged));
  return file;
}

// ---- Surfels (SPEC §11.3) ------------------------------------------------------------------

struct SurfelsProto {
  uint32_t n, flags;
  float box_min[3], box_max[3];
};

inline uint32_t level_count(uint32_t n) {
  uint32_t k = 0;
  while (n > (k == 0 ? 0u : 1024u << (k - 1))) ++k;
  return k;
}

// A surfels track naming `mesh_track`. Codes are random with the extremes 0 and 65535 at the
// start of each level; colour byte i of each channel is i mod 256 for the first 256 surfels of a
// prototype (every byte value), random after.
inline Status add_surfels_track(container::Writer& w, Chunks& chunks, uint32_t mesh_track,
                                const std::vector<SurfelsProto>& protos, Rng& rng) {
  uint64_t total = 0;
  for (const SurfelsProto& p : protos) total += p.n;
  Bytes header;
  Put h{header};
  h.timing(1);
  h.u32(static_cast<uint32_t>(protos.size()));
  h.u64(total);
  h.u16(0);
  CALF_ASSIGN_OR_RETURN(uint16_t track, w.add_track(3, 0, header));
  container::ChunkKeys k;
  k.track = track;
  Bytes index;
  Put ix{index};
  ix.u32(1);
  ix.u32(0);
  ix.u32(mesh_track);
  ix.u32(static_cast<uint32_t>(protos.size()));
  for (const SurfelsProto& p : protos) {
    ix.u32(p.n);
    ix.u32(p.flags);
    ix.u32(p.n ? 1 + rng.below(p.n) : 0);
    ix.f32(p.n ? static_cast<float>(1 + rng.below(64)) / 128.0f : 0.0f);
    for (float v : p.box_min) ix.f32(v);
    for (float v : p.box_max) ix.f32(v);
  }
  k.stream = 0;
  CALF_RETURN_IF_ERROR(chunks.add(k, index));
  k.stream = 1;
  for (uint32_t p = 0; p < protos.size(); ++p) {
    k.region = p;
    const uint32_t levels = level_count(protos[p].n);
    for (uint32_t l = 0; l < levels; ++l) {
      const uint32_t b = l == 0 ? 0 : 1024u << (l - 1);
      const uint32_t e = std::min(1024u << l, protos[p].n);
      const uint32_t n = e - b;
      auto code = [&](uint32_t i) -> uint16_t {
        return i == 0 ? 0 : i == 1 ? 65535 : static_cast<uint16_t>(rng.next());
      };
      std::vector<uint16_t> q(5 * size_t{n});
      for (uint32_t c = 0; c < 5; ++c) {
        for (uint32_t i = 0; i < n; ++i) q[size_t{c} * n + i] = code(i);
      }
      Bytes level;
      for (size_t i = 0; i < 3 * size_t{n}; ++i) level.push_back(static_cast<uint8_t>(q[i]));
      for (size_t i = 0; i < 3 * size_t{n}; ++i) level.push_back(static_cast<uint8_t>(q[i] >> 8));
      for (size_t i = 3 * size_t{n}; i < q.size(); ++i) level.push_back(static_cast<uint8_t>(q[i]));
      for (size_t i = 3 * size_t{n}; i < q.size(); ++i) {
        level.push_back(static_cast<uint8_t>(q[i] >> 8));
      }
      for (int c = 0; c < 3; ++c) {
        for (uint32_t i = b; i < e; ++i) {
          level.push_back(i < 256 ? static_cast<uint8_t>(i) : rng.byte());
        }
      }
      k.layer = l;
      CALF_RETURN_IF_ERROR(chunks.add(k, level));
    }
  }
  return Status::Ok();
}

// crafted_levels_multi: track 0 surfels (prototypes of 3100 surfels: 3 levels, the last of 1052, so
// levels double, colour is base; 1024: exactly one level, a box flat in y; 0; 1025: a level of one
// surfel, a negative box) and track 2 surfels (1, 0, 3 and 2 surfels), both naming the mesh track 1
// that follows track 0 (4 prototypes).
inline Expected<Bytes> make_surfels_clip() {
  Bytes file;
  CALF_ASSIGN_OR_RETURN(container::Writer w, plain_writer(&file));
  CALF_RETURN_IF_ERROR(w.set_metadata("calf.conformance", "crafted crafted_levels_multi"));
  Chunks chunks{w, 0, {}};
  Rng rng{0x5E4F};
  const std::vector<SurfelsProto> a = {{3100, 1, {-1.5f, -2.0f, 0.25f}, {3.0f, 2.0f, 0.75f}},
                                       {1024, 0, {-1.0f, 0.5f, -1.0f}, {1.0f, 0.5f, 1.0f}},
                                       {0, 0, {0, 0, 0}, {0, 0, 0}},
                                       {1025, 0, {-9.0f, -8.5f, -7.0f}, {-8.0f, -8.25f, -6.5f}}};
  const std::vector<SurfelsProto> b = {{1, 1, {0, 0, 0}, {1, 1, 1}},
                                       {0, 0, {0, 0, 0}, {0, 0, 0}},
                                       {3, 0, {-0.125f, 0, 0}, {0.125f, 0, 0}},
                                       {2, 1, {1, 2, 3}, {4, 5, 6}}};
  CALF_RETURN_IF_ERROR(add_surfels_track(w, chunks, 1, a, rng));
  CALF_RETURN_IF_ERROR(add_mesh_track(w, chunks, small_mesh(4), rng).status());
  CALF_RETURN_IF_ERROR(add_surfels_track(w, chunks, 1, b, rng));
  CALF_RETURN_IF_ERROR(w.finish());
  CALF_RETURN_IF_ERROR(set_optional_flags(file, chunks.flagged));
  return file;
}

// The clips, by suite folder and name (tests/conformance/README.md says what each exercises).
struct Clip {
  std::string folder, name;
  Expected<Bytes> (*make)();
};
inline std::vector<Clip> clips() {
  return {{"tiles", "crafted_bc7_multi", make_tiles_clip},
          {"surfels", "crafted_levels_multi", make_surfels_clip},
          {"mesh", "crafted_layout2_multi", make_mesh_clip}};
}

}  // namespace calf::conformance::tracks_crafted
