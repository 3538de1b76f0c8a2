// The mesh track's chunk layouts (format/SPEC.md §11.4); the rules are in mesh_layout.h.
#include "calf/format/mesh_layout.h"

#include <algorithm>
#include <bit>
#include <cmath>

#include "calf/format/coordinates.h"

namespace calf::mesh {
namespace {

using container::cat;

Status error(ErrorId id, const std::string& what, const std::string& message) {
  return Status(id, what + ": " + message);
}

// ---- Words as byte planes (§11.4.1) ----

// Appends `words` as four byte planes: byte 0 of every word, then byte 1, 2, 3. Float bit
// patterns and small deltas keep their near-constant high bytes together, which zstd and LZMA2
// compress far better than interleaved words.
void put_planes(std::vector<uint8_t>& out, std::span<const uint32_t> words) {
  const size_t at = out.size(), n = words.size();
  out.resize(at + 4 * n);
  for (size_t k = 0; k < 4; ++k) {
    uint8_t* plane = out.data() + at + k * n;
    for (size_t i = 0; i < n; ++i) plane[i] = static_cast<uint8_t>(words[i] >> (8 * k));
  }
}

// Reads n words stored as byte planes at `in` (4n bytes, checked by the caller).
void get_planes(const uint8_t* in, size_t n, uint32_t* words) {
  for (size_t i = 0; i < n; ++i) {
    words[i] = uint32_t{in[i]} | uint32_t{in[n + i]} << 8 | uint32_t{in[2 * n + i]} << 16 |
               uint32_t{in[3 * n + i]} << 24;
  }
}

uint32_t bits(float f) {
  return std::bit_cast<uint32_t>(f);
}
float from_bits(uint32_t w) {
  return std::bit_cast<float>(w);
}

// A vec3 array of `v` vertices as component planes: word c*v + i is component c of vertex i,
// minus (modulo 2^32) the same component of the same vertex of `ref` when one is given. Not
// predicted from the previous vertex: measured on the built-in scenes' meshes (whose vertex order
// is not spatial) zstd -19 stored 10-40 % more bytes with that prediction than without.
void put_vec3(std::vector<uint8_t>& out, const float* a, const float* ref, size_t v) {
  std::vector<uint32_t> words(3 * v);
  for (size_t c = 0; c < 3; ++c) {
    for (size_t i = 0; i < v; ++i)
      words[c * v + i] = bits(a[3 * i + c]) - (ref ? bits(ref[3 * i + c]) : 0u);
  }
  put_planes(out, words);
}

// Inverse of put_vec3: reads 12v bytes at `in` into a (3v floats).
void get_vec3(const uint8_t* in, float* a, const float* ref, size_t v) {
  std::vector<uint32_t> words(3 * v);
  get_planes(in, 3 * v, words.data());
  for (size_t c = 0; c < 3; ++c) {
    for (size_t i = 0; i < v; ++i)
      a[3 * i + c] = from_bits(words[c * v + i] + (ref ? bits(ref[3 * i + c]) : 0u));
  }
}

// A vec2 array of `v` vertices (UVs) as component planes, unpredicted: word c*v + i is component
// c of vertex i.
void put_vec2(std::vector<uint8_t>& out, const float* a, size_t v) {
  std::vector<uint32_t> words(2 * v);
  for (size_t c = 0; c < 2; ++c) {
    for (size_t i = 0; i < v; ++i) words[c * v + i] = bits(a[2 * i + c]);
  }
  put_planes(out, words);
}
void get_vec2(const uint8_t* in, float* a, size_t v) {
  std::vector<uint32_t> words(2 * v);
  get_planes(in, 2 * v, words.data());
  for (size_t c = 0; c < 2; ++c) {
    for (size_t i = 0; i < v; ++i) a[2 * i + c] = from_bits(words[c * v + i]);
  }
}

// A sequence of words as deltas from the previous word (the first from 0), as byte planes.
void put_sequence(std::vector<uint8_t>& out, std::span<const uint32_t> values) {
  std::vector<uint32_t> words(values.size());
  for (size_t i = 0; i < values.size(); ++i) words[i] = values[i] - (i ? values[i - 1] : 0u);
  put_planes(out, words);
}
void get_sequence(const uint8_t* in, size_t n, uint32_t* values) {
  get_planes(in, n, values);
  for (size_t i = 1; i < n; ++i) values[i] += values[i - 1];
}

std::string vertex_text(size_t i) {
  return cat("vertex ", i);
}

}  // namespace

// ---- Index ----

namespace {

Status check_index(const IndexChunk& x, uint32_t frame_count, const std::string& what) {
  if (x.flags != 0)
    return error(ErrorId::kMeshUnsupported, what, cat("reserved flags ", x.flags, " set"));
  const bool v1 = x.layout_version < 2;
  for (size_t i = 0; i < x.prototypes.size(); ++i) {
    if (x.prototypes[i].flags & ~(v1 ? kPrototypeFlagsV1 : kPrototypeFlags))
      return error(ErrorId::kMeshUnsupported, what,
                   cat("prototypes[", i, "]: reserved flags in ", x.prototypes[i].flags,
                       " for layout ", x.layout_version));
  }
  for (size_t i = 0; i < x.textures.size(); ++i) {
    if (x.textures[i].coding > kTextureSrgba8Plain || x.textures[i].flags != 0)
      return error(ErrorId::kMeshUnsupported, what,
                   cat("textures[", i, "]: coding ", x.textures[i].coding, " or flags ",
                       x.textures[i].flags, " unknown"));
  }
  for (size_t i = 0; i < x.objects.size(); ++i) {
    if (x.objects[i].flags & ~kAllTriangles)
      return error(ErrorId::kMeshUnsupported, what,
                   cat("objects[", i, "]: reserved flags in ", x.objects[i].flags));
  }
  for (int c = 0; c < 3; ++c) {
    if (!(x.view_min[c] <= x.view_max[c]))
      return error(ErrorId::kMeshValue, what,
                   cat("view region min[", c, "] ", x.view_min[c], " > max ", x.view_max[c]));
  }
  for (size_t i = 0; i < x.materials.size(); ++i) {
    for (int c = 0; c < 3; ++c) {
      const float b = x.materials[i].base_colour[c], e = x.materials[i].emission[c];
      if (!(b >= 0.0f && b <= 1.0f))
        return error(ErrorId::kMeshValue, what,
                     cat("materials[", i, "].base_colour ", b, " is outside [0, 1]"));
      if (!(e >= 0.0f))
        return error(ErrorId::kMeshValue, what,
                     cat("materials[", i, "].emission ", e, " is negative"));
    }
  }
  for (size_t i = 0; i < x.prototypes.size(); ++i) {
    const PrototypeRecord& p = x.prototypes[i];
    if (p.triangles_of == i) continue;
    const uint32_t q = p.triangles_of;
    if (q > i || x.prototypes[q].triangles_of != q ||
        x.prototypes[q].triangle_count != p.triangle_count ||
        ((x.prototypes[q].flags ^ p.flags) & kHasTriangleMaterials)) {
      return error(ErrorId::kMeshIndex, what,
                   cat("prototypes[", i, "].triangles_of ", q,
                       " is not an earlier prototype with its own triangles, ", p.triangle_count,
                       " triangles and the same triangle-material flag"));
    }
  }
  for (size_t i = 0; i < x.objects.size(); ++i) {
    const ObjectRecord& o = x.objects[i];
    const std::string name = cat("objects[", i, "]");
    if (o.prototype >= x.prototypes.size())
      return error(ErrorId::kMeshIndex, what,
                   cat(name, ".prototype ", o.prototype, " of ", x.prototypes.size()));
    if (o.material >= x.materials.size())
      return error(ErrorId::kMeshIndex, what,
                   cat(name, ".material ", o.material, " of ", x.materials.size()));
    if (o.transform_count != 1 && o.transform_count != frame_count)
      return error(
          ErrorId::kMeshIndex, what,
          cat(name, ".transform_count ", o.transform_count, " is neither 1 nor ", frame_count));
    const uint32_t t = x.prototypes[o.prototype].triangle_count;
    if ((o.flags & kAllTriangles) ? o.triangle_count != t : o.triangle_count > t)
      return error(ErrorId::kMeshIndex, what,
                   cat(name, ".triangle_count ", o.triangle_count,
                       (o.flags & kAllTriangles) ? " differs from its prototype's "
                                                 : " exceeds its prototype's ",
                       t));
  }
  for (size_t m = 0; m < x.material_textures.size(); ++m) {
    const uint32_t t = x.material_textures[m];
    if (t != kNoTexture && t >= x.textures.size())
      return error(ErrorId::kMeshIndex, what,
                   cat("material_textures[", m, "] ", t, " of ", x.textures.size(), " textures"));
  }
  return Status::Ok();
}

}  // namespace

Expected<std::vector<uint8_t>> serialize_index(const IndexChunk& index, uint32_t frame_count) {
  if (index.layout_version < 2 && (!index.textures.empty() || !index.material_textures.empty()))
    return Status(ErrorId::kContainerWriterMisuse, "mesh index: layout 1 holds no textures");
  std::vector<uint8_t> out;
  CALF_RETURN_IF_ERROR(container::write_fields(index, out, "mesh index"));
  Expected<IndexChunk> back = parse_index(out, frame_count, "mesh index");
  if (!back.ok()) return Status(ErrorId::kContainerWriterMisuse, back.status().message());
  return out;
}

Expected<IndexChunk> parse_index(std::span<const uint8_t> raw, uint32_t frame_count,
                                 const std::string& what) {
  // The layout version comes first and alone: a later layout may change everything after it.
  if (raw.size() < 4)
    return error(ErrorId::kMeshChunk, what, cat(raw.size(), " bytes, too short for a version"));
  const uint32_t version = static_cast<uint32_t>(container::load_le(raw.data(), 4));
  if (version != kLayoutVersion && version != kLayoutVersionUntextured)
    return error(ErrorId::kMeshUnsupported, what,
                 cat("layout version ", version, ", expected 1 or 2"));
  IndexChunk x;
  container::FieldReader r(raw, ErrorId::kMeshChunk, ErrorId::kMeshValue, what,
                           ErrorId::kMeshLimit);
  CALF_RETURN_IF_ERROR(container::read_fields(x, r));
  if (r.remaining() != 0)
    return error(ErrorId::kMeshChunk, what, cat(r.remaining(), " bytes after the objects"));
  CALF_RETURN_IF_ERROR(check_index(x, frame_count, what));
  return x;
}

// ---- Vertices ----

uint64_t vertices_chunk_size(const PrototypeRecord& p) {
  const uint64_t v = p.vertex_count, s = p.state_count;
  uint64_t arrays = 1 + ((p.flags & kHasNormals) ? 1 : 0) + ((p.flags & kHasColours) ? 1 : 0);
  return 12 * v * arrays + ((p.flags & kHasUvs) ? 8 * v : 0) + 4 * s + 12 * v * s;
}

Expected<std::vector<uint8_t>> encode_vertices(const PrototypeRecord& p, const VertexArrays& a) {
  const size_t v = p.vertex_count, s = p.state_count;
  const auto bad = [](const char* name, size_t have, size_t want) {
    return Status(ErrorId::kContainerWriterMisuse,
                  cat("mesh vertices: ", name, " holds ", have, " floats, not ", want));
  };
  if (a.positions.size() != 3 * v) return bad("positions", a.positions.size(), 3 * v);
  if (a.normals.size() != ((p.flags & kHasNormals) ? 3 * v : 0))
    return bad("normals", a.normals.size(), (p.flags & kHasNormals) ? 3 * v : 0);
  if (a.colours.size() != ((p.flags & kHasColours) ? 3 * v : 0))
    return bad("colours", a.colours.size(), (p.flags & kHasColours) ? 3 * v : 0);
  if (a.uvs.size() != ((p.flags & kHasUvs) ? 2 * v : 0))
    return bad("uvs", a.uvs.size(), (p.flags & kHasUvs) ? 2 * v : 0);
  if (a.state_times.size() != s) return bad("state_times", a.state_times.size(), s);
  if (a.state_positions.size() != 3 * v * s)
    return bad("state_positions", a.state_positions.size(), 3 * v * s);
  std::vector<uint8_t> out;
  out.reserve(vertices_chunk_size(p));
  put_vec3(out, a.positions.data(), nullptr, v);
  if (p.flags & kHasNormals) put_vec3(out, a.normals.data(), nullptr, v);
  if (p.flags & kHasColours) put_vec3(out, a.colours.data(), nullptr, v);
  if (p.flags & kHasUvs) put_vec2(out, a.uvs.data(), v);
  std::vector<uint32_t> times(s);
  for (size_t k = 0; k < s; ++k) times[k] = bits(a.state_times[k]);
  put_sequence(out, times);
  for (size_t k = 0; k < s; ++k) {
    const float* ref = k ? &a.state_positions[3 * v * (k - 1)] : a.positions.data();
    put_vec3(out, &a.state_positions[3 * v * k], ref, v);
  }
  // The writer never writes what its reader refuses.
  VertexArrays check;
  if (Status st = decode_vertices(out, p, &check, "mesh vertices"); !st.ok())
    return Status(ErrorId::kContainerWriterMisuse, st.message());
  return out;
}

Status decode_vertices(std::span<const uint8_t> raw, const PrototypeRecord& p, VertexArrays* out,
                       const std::string& what) {
  if (raw.size() != vertices_chunk_size(p)) {
    return error(ErrorId::kMeshChunk, what,
                 cat(raw.size(), " bytes, expected ", vertices_chunk_size(p), " for ",
                     p.vertex_count, " vertices, ", p.state_count, " states and flags ", p.flags));
  }
  const size_t v = p.vertex_count, s = p.state_count;
  const uint8_t* in = raw.data();
  *out = VertexArrays{};
  out->positions.resize(3 * v);
  get_vec3(in, out->positions.data(), nullptr, v);
  in += 12 * v;
  if (p.flags & kHasNormals) {
    out->normals.resize(3 * v);
    get_vec3(in, out->normals.data(), nullptr, v);
    in += 12 * v;
  }
  if (p.flags & kHasColours) {
    out->colours.resize(3 * v);
    get_vec3(in, out->colours.data(), nullptr, v);
    in += 12 * v;
  }
  if (p.flags & kHasUvs) {
    out->uvs.resize(2 * v);
    get_vec2(in, out->uvs.data(), v);
    in += 8 * v;
  }
  std::vector<uint32_t> times(s);
  get_sequence(in, s, times.data());
  in += 4 * s;
  out->state_times.resize(s);
  for (size_t k = 0; k < s; ++k) out->state_times[k] = from_bits(times[k]);
  out->state_positions.resize(3 * v * s);
  for (size_t k = 0; k < s; ++k) {
    const float* ref = k ? &out->state_positions[3 * v * (k - 1)] : out->positions.data();
    get_vec3(in, &out->state_positions[3 * v * k], ref, v);
    in += 12 * v;
  }
  // Values (§11.4.3), in array order.
  for (size_t i = 0; i < 3 * v; ++i) {
    if (!coordinate_ok(out->positions[i]))
      return error(ErrorId::kMeshValue, what,
                   cat(vertex_text(i / 3), " position ", out->positions[i],
                       " is not a finite number within +-1e12"));
  }
  for (size_t i = 0; i < out->normals.size(); i += 3) {
    const float* n = &out->normals[i];
    if (!std::isfinite(n[0]) || !std::isfinite(n[1]) || !std::isfinite(n[2]) ||
        (n[0] == 0 && n[1] == 0 && n[2] == 0))
      return error(ErrorId::kMeshValue, what,
                   cat(vertex_text(i / 3), " normal (", n[0], ", ", n[1], ", ", n[2],
                       ") is zero or not finite"));
  }
  for (size_t i = 0; i < out->colours.size(); ++i) {
    const float c = out->colours[i];
    if (!(c >= 0.0f && c <= 1.0f))
      return error(ErrorId::kMeshValue, what,
                   cat(vertex_text(i / 3), " colour ", c, " is outside [0, 1]"));
  }
  for (size_t i = 0; i < out->uvs.size(); ++i) {
    if (!std::isfinite(out->uvs[i]))
      return error(ErrorId::kMeshValue, what,
                   cat(vertex_text(i / 2), " uv ", out->uvs[i], " is not finite"));
  }
  for (size_t k = 0; k < s; ++k) {
    const float t = out->state_times[k];
    if (!std::isfinite(t) || t < 0 || (k && !(t > out->state_times[k - 1])))
      return error(ErrorId::kMeshValue, what,
                   cat("state ", k, " time ", t, " is not finite, >= 0 and after the last"));
  }
  for (size_t i = 0; i < out->state_positions.size(); ++i) {
    if (!coordinate_ok(out->state_positions[i]))
      return error(ErrorId::kMeshValue, what,
                   cat("state ", i / (3 * v), " ", vertex_text(i % (3 * v) / 3), " position ",
                       out->state_positions[i], " is not a finite number within +-1e12"));
  }
  return Status::Ok();
}

// ---- Triangles ----

uint64_t triangles_chunk_size(const PrototypeRecord& p) {
  return uint64_t{p.triangle_count} * ((p.flags & kHasTriangleMaterials) ? 16 : 12);
}

Expected<std::vector<uint8_t>> encode_triangles(const PrototypeRecord& p, const TriangleArrays& a) {
  const size_t t = p.triangle_count;
  const size_t tm = (p.flags & kHasTriangleMaterials) ? t : 0;
  if (a.indices.size() != 3 * t || a.triangle_materials.size() != tm) {
    return Status(ErrorId::kContainerWriterMisuse,
                  cat("mesh triangles: ", a.indices.size(), " indices and ",
                      a.triangle_materials.size(), " triangle materials for ", t, " triangles"));
  }
  std::vector<uint8_t> out;
  out.reserve(triangles_chunk_size(p));
  put_sequence(out, a.indices);
  put_sequence(out, a.triangle_materials);
  return out;
}

Status decode_triangles(std::span<const uint8_t> raw, const PrototypeRecord& p,
                        uint32_t material_count, TriangleArrays* out, const std::string& what) {
  if (raw.size() != triangles_chunk_size(p)) {
    return error(ErrorId::kMeshChunk, what,
                 cat(raw.size(), " bytes, expected ", triangles_chunk_size(p), " for ",
                     p.triangle_count, " triangles and flags ", p.flags));
  }
  const size_t t = p.triangle_count;
  *out = TriangleArrays{};
  out->indices.resize(3 * t);
  get_sequence(raw.data(), 3 * t, out->indices.data());
  for (size_t i = 0; i < 3 * t; ++i) {
    if (out->indices[i] >= p.vertex_count)
      return error(ErrorId::kMeshIndex, what,
                   cat("triangle ", i / 3, " vertex index ", out->indices[i], " of ",
                       p.vertex_count, " vertices"));
  }
  if (p.flags & kHasTriangleMaterials) {
    out->triangle_materials.resize(t);
    get_sequence(raw.data() + 12 * t, t, out->triangle_materials.data());
    for (size_t i = 0; i < t; ++i) {
      const uint32_t m = out->triangle_materials[i];
      if (m >= material_count && m != kObjectMaterial)
        return error(ErrorId::kMeshIndex, what,
                     cat("triangle ", i, " material ", m, " of ", material_count));
    }
  }
  return Status::Ok();
}

// ---- Visibility ----

uint64_t visibility_chunk_min_size(const ObjectRecord& o) {
  return 48 * uint64_t{o.transform_count} + ((o.flags & kAllTriangles) ? 0 : 4);
}

Expected<std::vector<uint8_t>> encode_visibility(const ObjectRecord& o, const PrototypeRecord& p,
                                                 const Visibility& v) {
  const size_t n = o.transform_count;
  if (v.transforms.size() != n)
    return Status(ErrorId::kContainerWriterMisuse,
                  cat("mesh visibility: ", v.transforms.size(), " transforms, not ", n));
  std::vector<uint8_t> out;
  // Element-planar deltas along the frames: a static element is a run of zero words.
  std::vector<uint32_t> words(12 * n);
  for (size_t e = 0; e < 12; ++e) {
    for (size_t f = 0; f < n; ++f)
      words[e * n + f] = bits(v.transforms[f][e]) - (f ? bits(v.transforms[f - 1][e]) : 0u);
  }
  put_planes(out, words);
  if (!(o.flags & kAllTriangles)) {
    // Runs of kept triangles: (gap before the run, its length), the first gap from triangle 0.
    std::vector<uint32_t> gaps, runs;
    uint64_t next = 0;  // first triangle after the previous run
    for (size_t i = 0; i < v.triangles.size();) {
      size_t j = i + 1;
      while (j < v.triangles.size() && v.triangles[j] == v.triangles[j - 1] + 1) ++j;
      gaps.push_back(static_cast<uint32_t>(v.triangles[i] - next));
      runs.push_back(static_cast<uint32_t>(j - i));
      next = uint64_t{v.triangles[j - 1]} + 1;
      i = j;
    }
    const size_t at = out.size();
    out.resize(at + 4);
    container::store_le(out.data() + at, gaps.size(), 4);
    put_planes(out, gaps);
    put_planes(out, runs);
  }
  Visibility check;
  if (Status st = decode_visibility(out, o, p, &check, "mesh visibility"); !st.ok())
    return Status(ErrorId::kContainerWriterMisuse, st.message());
  if (check.triangles != v.triangles)
    return Status(ErrorId::kContainerWriterMisuse, "mesh visibility: the subset is not sorted");
  return out;
}

Status decode_visibility(std::span<const uint8_t> raw, const ObjectRecord& o,
                         const PrototypeRecord& p, Visibility* out, const std::string& what) {
  const uint64_t min = visibility_chunk_min_size(o);
  const bool all = (o.flags & kAllTriangles) != 0;
  if (raw.size() < min || (all && raw.size() != min)) {
    return error(ErrorId::kMeshChunk, what,
                 cat(raw.size(), " bytes, expected ", all ? "" : "at least ", min, " for ",
                     o.transform_count, " transforms"));
  }
  const size_t n = o.transform_count;
  *out = Visibility{};
  std::vector<uint32_t> words(12 * n);
  get_planes(raw.data(), 12 * n, words.data());
  out->transforms.resize(n);
  for (size_t e = 0; e < 12; ++e) {
    uint32_t prev = 0;
    for (size_t f = 0; f < n; ++f) {
      prev += words[e * n + f];
      out->transforms[f][e] = from_bits(prev);
      if (!std::isfinite(out->transforms[f][e]))
        return error(
            ErrorId::kMeshValue, what,
            cat("transform ", f, " element ", e, " ", out->transforms[f][e], " is not finite"));
    }
  }
  if (all) return Status::Ok();
  const uint8_t* at = raw.data() + 48 * n;
  const uint64_t r = container::load_le(at, 4);
  const uint64_t rest = raw.size() - min;
  if (rest != 8 * r)
    return error(ErrorId::kMeshChunk, what,
                 cat(r, " runs need ", 8 * r, " bytes, the chunk has ", rest, " after the count"));
  std::vector<uint32_t> gaps(r), runs(r);
  get_planes(at + 4, r, gaps.data());
  get_planes(at + 4 + 4 * r, r, runs.data());
  uint64_t next = 0;
  for (size_t i = 0; i < r; ++i) {
    if (runs[i] == 0 || (i > 0 && gaps[i] == 0))
      return error(ErrorId::kMeshIndex, what,
                   cat("run ", i, " has gap ", gaps[i], " and length ", runs[i],
                       " (runs are non-empty and apart)"));
    const uint64_t first = next + gaps[i], end = first + runs[i];
    if (end > p.triangle_count || out->triangles.size() + runs[i] > o.triangle_count)
      return error(ErrorId::kMeshIndex, what,
                   cat("run ", i, " [", first, ", ", end, ") leaves the prototype's ",
                       p.triangle_count, " triangles or the object's ", o.triangle_count));
    for (uint64_t t = first; t < end; ++t) out->triangles.push_back(static_cast<uint32_t>(t));
    next = end;
  }
  if (out->triangles.size() != o.triangle_count)
    return error(
        ErrorId::kMeshIndex, what,
        cat("the runs hold ", out->triangles.size(), " triangles, the object ", o.triangle_count));
  return Status::Ok();
}

// ---- Textures ----

namespace {

// The MED predictor (LOCO-I / JPEG-LS) of a texel channel from its left (a), upper (b) and
// upper-left (c) neighbours: an edge-detecting choice between a, b and a + b - c.
uint8_t med(int a, int b, int c) {
  if (c >= std::max(a, b)) return static_cast<uint8_t>(std::min(a, b));
  if (c <= std::min(a, b)) return static_cast<uint8_t>(std::max(a, b));
  return static_cast<uint8_t>(a + b - c);
}

// The prediction of channel `ch` of texel (x, y) from already known texels of `rgba`: MED inside,
// the left texel on row 0, the upper texel in column 0, 0 at (0, 0).
uint8_t predict(const uint8_t* rgba, size_t w, size_t x, size_t y, size_t ch) {
  const auto at = [&](size_t xx, size_t yy) { return int{rgba[4 * (yy * w + xx) + ch]}; };
  if (y == 0) return x == 0 ? 0 : static_cast<uint8_t>(at(x - 1, 0));
  if (x == 0) return static_cast<uint8_t>(at(0, y - 1));
  return med(at(x - 1, y), at(x, y - 1), at(x - 1, y - 1));
}

}  // namespace

uint64_t texture_chunk_size(const TextureRecord& t) {
  return 4 * uint64_t{t.width} * t.height;
}

Expected<std::vector<uint8_t>> encode_texture(const TextureRecord& t, const TextureTexels& texels) {
  if (texels.width != t.width || texels.height != t.height ||
      texels.rgba.size() != texture_chunk_size(t)) {
    return Status(ErrorId::kContainerWriterMisuse,
                  cat("mesh texture: ", texels.width, " x ", texels.height, " texels of ",
                      texels.rgba.size(), " bytes for a ", t.width, " x ", t.height, " record"));
  }
  if (t.coding == kTextureSrgba8Plain) return texels.rgba;
  const size_t w = t.width, h = t.height, n = w * h;
  std::vector<uint8_t> out(4 * n);
  for (size_t ch = 0; ch < 4; ++ch) {
    for (size_t y = 0; y < h; ++y) {
      for (size_t x = 0; x < w; ++x) {
        out[ch * n + y * w + x] = static_cast<uint8_t>(texels.rgba[4 * (y * w + x) + ch] -
                                                       predict(texels.rgba.data(), w, x, y, ch));
      }
    }
  }
  return out;
}

Status decode_texture(std::span<const uint8_t> raw, const TextureRecord& t, TextureTexels* out,
                      const std::string& what) {
  if (raw.size() != texture_chunk_size(t)) {
    return error(ErrorId::kMeshChunk, what,
                 cat(raw.size(), " bytes, expected ", texture_chunk_size(t), " for ", t.width,
                     " x ", t.height, " texels"));
  }
  const size_t w = t.width, h = t.height, n = w * h;
  out->width = t.width;
  out->height = t.height;
  if (t.coding == kTextureSrgba8Plain) {
    out->rgba.assign(raw.begin(), raw.end());
    return Status::Ok();
  }
  out->rgba.assign(4 * n, 0);
  uint8_t* rgba = out->rgba.data();
  for (size_t y = 0; y < h; ++y) {
    for (size_t x = 0; x < w; ++x) {
      for (size_t ch = 0; ch < 4; ++ch) {
        rgba[4 * (y * w + x) + ch] =
            static_cast<uint8_t>(raw[ch * n + y * w + x] + predict(rgba, w, x, y, ch));
      }
    }
  }
  return Status::Ok();
}

}  // namespace calf::mesh
