// Surfel-candidate files (surfel_candidates.h, format/SURFEL_CANDIDATES.md): the records are
// declared once with the fields visitor (container_fields.h), from which reading and writing
// derive; the reader walks records through a ByteSource so that one prototype is read at a time.
#include "calf/capture/surfel_candidates.h"

#include <cmath>
#include <cstring>

#include "calf/format/container_codec.h"
#include "calf/format/container_fields.h"
#include "calf/format/container_io.h"

namespace calf::capture {

namespace {

using container::cat;
using container::FieldReader;
using container::FieldWriter;
using container::FloatRule;
using container::Length;
using container::Range;

constexpr uint64_t kHashBytes = 8;

// The file header as stored, before its hash.
struct FileHead {
  std::array<uint8_t, 8> magic{};
  uint32_t version = 0, flags = 0, resolution = 0, direction_count = 0, corners = 0;
  uint32_t prototype_count = 0;
  std::string scene;
  template <class Self, class V>
  static constexpr void fields(Self& s, V& v) {
    v(s.magic, "magic");
    v(s.version, "version");
    v(s.flags, "flags");
    v(s.resolution, "resolution");
    v(s.direction_count, "direction_count");
    v(s.corners, "corners");
    v(s.prototype_count, "prototype_count");
    v(s.scene, "scene", Range{0, kSurfelMaxSceneName});
  }
};

// What every record starts with: its size and counts. The walk over a file reads this much of
// each record; decode_record reads it as the start of the record, with the limits that bound the
// counts (not stored; a walk reads without them).
struct RecordHead {
  uint64_t record_size = 0;
  uint32_t mesh = 0;
  uint64_t mesh_hash = 0;
  uint32_t candidate_count = 0, colour_set_count = 0;
  uint64_t max_candidates = UINT64_MAX, max_colour_sets = UINT64_MAX;
  template <class Self, class V>
  static constexpr void fields(Self& s, V& v) {
    v(s.record_size, "record_size");
    v(s.mesh, "mesh");
    v(s.mesh_hash, "mesh_hash");
    v(s.candidate_count, "candidate_count", Range{0, s.max_candidates});
    v(s.colour_set_count, "colour_set_count", Range{0, s.max_colour_sets});
  }
};

struct ViewFields {
  SurfelCandidateView* view;
  uint32_t max_count;
  template <class Self, class V>
  static constexpr void fields(Self& s, V& v) {
    v(s.view->direction, "direction", FloatRule::kFinite);
    v(s.view->pixel_size, "pixel_size", FloatRule::kFinite);
    v(s.view->candidate_count, "candidate_count", Range{0, s.max_count});
  }
};

// The start of one record as stored: its head, then its box. The views, materials and arrays
// whose lengths the head's counts give follow: a reader allocates nothing a count has not bounded.
struct RecordFields {
  SurfelCandidates* p;
  RecordHead head;
  template <class Self, class V>
  static constexpr void fields(Self& s, V& v) {
    v(s.head, "head");
    v(s.p->box_min, "box_min", FloatRule::kFinite);
    v(s.p->box_max, "box_max", FloatRule::kFinite);
  }
  // The limits of a file with `direction_count` directions at `resolution`.
  void bound(uint32_t direction_count, uint32_t resolution) {
    head.max_candidates = uint64_t{direction_count} * resolution * resolution;
    head.max_colour_sets = kSurfelMaxColourSets;
  }
};

constexpr uint64_t kRecordHeadBytes = container::fixed_size<RecordHead>();
constexpr uint64_t kRecordStartBytes = kRecordHeadBytes + 24;  // the head and the box
constexpr uint64_t kViewBytes = 20;
// A record without views, materials or candidates: its start and its hash.
constexpr uint64_t kMinRecordBytes = kRecordStartBytes + kHashBytes;

uint64_t record_bytes(uint64_t direction_count, uint64_t candidates, uint64_t sets) {
  return kRecordStartBytes + kViewBytes * direction_count + 4 * sets + 24 * candidates +
         3 * sets * candidates + kHashBytes;
}

std::string record_name(std::string_view source, uint32_t index) {
  return cat(source, ": record ", index);
}

Status header_checks(const FileHead& h, std::string_view source) {
  auto bad = [&](ErrorId id, const std::string& what) {
    return Status(id, cat(source, ": ", what));
  };
  if (h.magic != kSurfelCandidatesMagic) {
    return bad(ErrorId::kSurfelFileIdentifier, "does not start with \"calfcand\"");
  }
  if (h.version != kSurfelCandidatesVersion) {
    return bad(ErrorId::kSurfelFileVersion, cat("version ", h.version, " is not 1"));
  }
  if (h.flags != 0) return bad(ErrorId::kSurfelFileVersion, cat("flags ", h.flags, " are not 0"));
  if (h.resolution == 0) return bad(ErrorId::kSurfelFileField, "resolution is 0");
  if (h.resolution > kSurfelMaxResolution) {
    return bad(ErrorId::kSurfelFileLimit,
               cat("resolution ", h.resolution, " exceeds ", kSurfelMaxResolution));
  }
  if (h.direction_count != 8 && h.direction_count != 16) {
    return bad(ErrorId::kSurfelFileField,
               cat("direction_count ", h.direction_count, " is neither 8 nor 16"));
  }
  if (h.corners > 1)
    return bad(ErrorId::kSurfelFileField, cat("corners ", h.corners, " is not 0 or 1"));
  if (h.prototype_count > kSurfelMaxPrototypes) {
    return bad(ErrorId::kSurfelFileLimit,
               cat("prototype_count ", h.prototype_count, " exceeds ", kSurfelMaxPrototypes));
  }
  return Status::Ok();
}

FileHead head_of(const SurfelCandidateHeader& h) {
  FileHead f;
  f.magic = kSurfelCandidatesMagic;
  f.version = kSurfelCandidatesVersion;
  f.resolution = h.resolution;
  f.direction_count = h.direction_count;
  f.corners = static_cast<uint32_t>(h.corners);
  f.prototype_count = h.prototype_count;
  f.scene = h.scene;
  return f;
}

// Header bytes with their hash, or E187 for a header the reader would refuse.
Expected<std::vector<uint8_t>> encode_header(const SurfelCandidateHeader& h) {
  const FileHead f = head_of(h);
  if (h.scene.size() > kSurfelMaxSceneName) {
    return Status(ErrorId::kSurfelWriterMisuse,
                  cat("scene name of ", h.scene.size(), " bytes exceeds ", kSurfelMaxSceneName));
  }
  if (Status s = header_checks(f, "surfel-candidate header"); !s.ok()) {
    return Status(ErrorId::kSurfelWriterMisuse, s.message());
  }
  std::vector<uint8_t> out;
  if (!container::write_fields(f, out).ok()) return Status(ErrorId::kSurfelWriterMisuse, "header");
  const uint64_t hash = container::hash64(out);
  const size_t at = out.size();
  out.resize(at + kHashBytes);
  container::store_le(out.data() + at, hash, kHashBytes);
  return out;
}

Expected<std::vector<uint8_t>> encode_record(const SurfelCandidateHeader& h, uint32_t index,
                                             const SurfelCandidates& p) {
  if (Status s = validate_surfel_candidates(h, index, p); !s.ok()) {
    return Status(s.id(), cat("writing: ", s.message()));
  }
  const uint64_t n = p.candidate_count(), sets = p.colour_sets.size();
  RecordFields r{const_cast<SurfelCandidates*>(&p), {}};
  r.head.record_size = record_bytes(h.direction_count, n, sets);
  r.head.mesh = p.mesh;
  r.head.mesh_hash = p.mesh_hash;
  r.head.candidate_count = static_cast<uint32_t>(n);
  r.head.colour_set_count = static_cast<uint32_t>(sets);
  r.bound(h.direction_count, h.resolution);
  std::vector<uint8_t> out;
  out.reserve(r.head.record_size);
  FieldWriter w(out, record_name("surfel-candidate writer", index));
  RecordFields::fields(r, w);
  for (SurfelCandidateView view : p.views) {
    ViewFields vf{&view, h.resolution * h.resolution};
    ViewFields::fields(vf, w);
  }
  for (const SurfelColourSet& set : p.colour_sets) w(set.material, "material");
  w(p.positions, "positions", Length{3 * n}, FloatRule::kFinite);
  w(p.normals, "normals", Length{3 * n}, FloatRule::kFinite);
  for (const SurfelColourSet& set : p.colour_sets) w(set.colours, "colours", Length{3 * n});
  if (!w.ok()) return Status(ErrorId::kSurfelWriterMisuse, w.status().message());
  const uint64_t hash = container::hash64(out);
  const size_t at = out.size();
  out.resize(at + kHashBytes);
  container::store_le(out.data() + at, hash, kHashBytes);
  if (out.size() != r.head.record_size) {
    return Status(ErrorId::kInternal,
                  cat("record ", index, " size ", out.size(), " is not ", r.head.record_size));
  }
  return out;
}

// Decodes record `index` from its bytes (exactly record_size of them, hash included).
Expected<SurfelCandidates> decode_record(std::span<const uint8_t> bytes,
                                         const SurfelCandidateHeader& h, uint32_t index,
                                         std::string_view source) {
  const std::string where = record_name(source, index);
  const uint64_t stored = container::load_le(bytes.data() + bytes.size() - kHashBytes, kHashBytes);
  const uint64_t actual = container::hash64(bytes.first(bytes.size() - kHashBytes));
  if (stored != actual) {
    return Status(
        ErrorId::kSurfelFileHash,
        cat(where, ": hash ", stored, " does not match the record's bytes (", actual, ")"));
  }
  SurfelCandidates p;
  RecordFields r{&p, {}};
  r.bound(h.direction_count, h.resolution);
  FieldReader reader(bytes.first(bytes.size() - kHashBytes), ErrorId::kSurfelFileField,
                     ErrorId::kSurfelFileValue, where, ErrorId::kSurfelFileLimit);
  RecordFields::fields(r, reader);
  if (!reader.ok()) return reader.status();
  if (r.head.record_size != bytes.size()) {
    return Status(ErrorId::kSurfelFileField,
                  cat(where, ": record_size ", r.head.record_size, " is not ", bytes.size()));
  }
  p.mesh = r.head.mesh;
  p.mesh_hash = r.head.mesh_hash;
  const uint64_t n = r.head.candidate_count, sets = r.head.colour_set_count;
  // The counts must account for every byte before any array is allocated.
  if (record_bytes(h.direction_count, n, sets) != bytes.size()) {
    return Status(
        ErrorId::kSurfelFileField,
        cat(where, ": record_size ", bytes.size(), " does not hold ", n, " candidates in ", sets,
            " colour sets (", record_bytes(h.direction_count, n, sets), " bytes)"));
  }
  p.views.resize(h.direction_count);
  for (SurfelCandidateView& view : p.views) {
    ViewFields vf{&view, h.resolution * h.resolution};
    ViewFields::fields(vf, reader);
  }
  p.colour_sets.resize(sets);
  for (SurfelColourSet& set : p.colour_sets) reader(set.material, "material");
  reader(p.positions, "positions", Length{3 * n}, FloatRule::kFinite);
  reader(p.normals, "normals", Length{3 * n}, FloatRule::kFinite);
  for (SurfelColourSet& set : p.colour_sets) reader(set.colours, "colours", Length{3 * n});
  if (!reader.ok()) return reader.status();
  if (Status s = validate_surfel_candidates(h, index, p); !s.ok()) {
    return Status(s.id(), cat(source, ": ", s.message()));
  }
  return p;
}

// The walk of SurfelCandidateReader::open over any source.
struct Walk {
  SurfelCandidateHeader header;
  std::vector<SurfelCandidateEntry> entries;
};

Expected<Walk> walk(const container::ByteSource& src, std::string_view source) {
  const uint64_t size = src.size();
  // The header: at most 32 fixed bytes, the name and the hash.
  std::vector<uint8_t> head(
      std::min<uint64_t>(size, container::min_size<FileHead>() + kSurfelMaxSceneName + kHashBytes));
  CALF_RETURN_IF_ERROR(src.read_at(0, head));
  if (head.size() < 8 ||
      !std::equal(kSurfelCandidatesMagic.begin(), kSurfelCandidatesMagic.end(), head.begin())) {
    return Status(ErrorId::kSurfelFileIdentifier,
                  cat(source, ": does not start with \"calfcand\" (", size, " bytes)"));
  }
  FileHead f;
  FieldReader r(head, ErrorId::kSurfelFileTruncated, ErrorId::kSurfelFileField,
                cat(source, ": header"), ErrorId::kSurfelFileLimit);
  FileHead::fields(f, r);
  // Version and flags decide how to read the rest: checked before the reader's complaints.
  if (f.version != kSurfelCandidatesVersion || (r.ok() && f.flags != 0)) {
    CALF_RETURN_IF_ERROR(header_checks(f, source));
  }
  if (!r.ok()) return r.status();
  const size_t head_bytes = r.position();
  if (head.size() < head_bytes + kHashBytes) {
    return Status(ErrorId::kSurfelFileTruncated, cat(source, ": ends inside the header's hash"));
  }
  const uint64_t stored = container::load_le(head.data() + head_bytes, kHashBytes);
  if (stored != container::hash64(std::span(head).first(head_bytes))) {
    return Status(ErrorId::kSurfelFileHash, cat(source, ": the header's hash does not match"));
  }
  CALF_RETURN_IF_ERROR(header_checks(f, source));
  Walk w;
  w.header.scene = f.scene;
  w.header.resolution = f.resolution;
  w.header.direction_count = f.direction_count;
  w.header.corners = static_cast<SurfelCorners>(f.corners);
  w.header.prototype_count = f.prototype_count;
  uint64_t offset = head_bytes + kHashBytes;
  // Every record takes at least kMinRecordBytes: more records than that fit are a short file.
  if (f.prototype_count > (size - offset) / kMinRecordBytes) {
    return Status(ErrorId::kSurfelFileTruncated,
                  cat(source, ": ", size - offset, " bytes after the header cannot hold ",
                      f.prototype_count, " records"));
  }
  w.entries.reserve(f.prototype_count);
  for (uint32_t i = 0; i < f.prototype_count; ++i) {
    const std::string where = record_name(source, i);
    if (size - offset < kRecordStartBytes) {
      return Status(ErrorId::kSurfelFileTruncated,
                    cat(where, ": the file ends at byte ", size, " inside its head"));
    }
    uint8_t bytes[kRecordHeadBytes];
    CALF_RETURN_IF_ERROR(src.read_at(offset, bytes));
    RecordHead record;  // without limits: reading the head's bytes cannot fail
    FieldReader record_reader(bytes, ErrorId::kSurfelFileTruncated, ErrorId::kSurfelFileField,
                              where);
    RecordHead::fields(record, record_reader);
    if (!record_reader.ok()) return record_reader.status();
    SurfelCandidateEntry e;
    const uint64_t record_size = record.record_size;
    e.mesh = record.mesh;
    e.mesh_hash = record.mesh_hash;
    e.candidate_count = record.candidate_count;
    e.colour_set_count = record.colour_set_count;
    e.offset = offset;
    e.size = record_size;
    if (record_size < kMinRecordBytes) {
      return Status(ErrorId::kSurfelFileField,
                    cat(where, ": record_size ", record_size, " is below ", kMinRecordBytes));
    }
    if (record_size > size - offset) {
      return Status(ErrorId::kSurfelFileTruncated,
                    cat(where, ": record_size ", record_size, " runs past the file's end (",
                        size - offset, " bytes left)"));
    }
    // The last material, for check_surfel_candidates_match; a record too short to hold its
    // materials is read() 's E183.
    const uint64_t materials_end =
        kRecordStartBytes + kViewBytes * f.direction_count + 4 * uint64_t{e.colour_set_count};
    if (e.colour_set_count > 0 && materials_end + kHashBytes <= record_size) {
      uint8_t last[4];
      CALF_RETURN_IF_ERROR(src.read_at(offset + materials_end - 4, last));
      e.last_material = static_cast<uint32_t>(container::load_le(last, 4));
    }
    w.entries.push_back(e);
    offset += record_size;
  }
  if (offset != size) {
    return Status(ErrorId::kSurfelFileField,
                  cat(source, ": ", size - offset, " bytes follow the last record"));
  }
  return w;
}

Expected<SurfelCandidates> read_entry(const container::ByteSource& src, const Walk& w,
                                      uint32_t index, std::string_view source) {
  if (index >= w.entries.size()) {
    return Status(ErrorId::kInvalidArgument,
                  cat(source, ": no record ", index, " of ", w.entries.size()));
  }
  const SurfelCandidateEntry& e = w.entries[index];
  std::vector<uint8_t> bytes(e.size);
  CALF_RETURN_IF_ERROR(src.read_at(e.offset, bytes));
  return decode_record(bytes, w.header, index, source);
}

bool unit(const float* v) {
  const float l = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  return std::fabs(l - 1) <= kSurfelUnitTolerance;
}

}  // namespace

uint64_t surfel_mesh_hash(const SceneMesh& mesh) {
  // Little-endian bytes of each array (the host's, checked: calf builds only little-endian).
  static_assert(std::endian::native == std::endian::little);
  std::vector<uint8_t> bytes;
  auto add = [&](const void* data, size_t n) {
    const size_t at = bytes.size();
    bytes.resize(at + n);
    if (n) std::memcpy(bytes.data() + at, data, n);
  };
  add(mesh.positions.data(), mesh.positions.size() * 4);
  add(mesh.indices.data(), mesh.indices.size() * 4);
  for (const SceneSphere& s : mesh.spheres) {
    add(s.center.data(), 12);
    add(&s.radius, 4);
  }
  add(mesh.colors.data(), mesh.colors.size() * 4);
  add(mesh.uvs.data(), mesh.uvs.size() * 4);
  add(mesh.triangle_materials.data(), mesh.triangle_materials.size() * 4);
  return container::hash64(bytes);
}

Status validate_surfel_candidates(const SurfelCandidateHeader& h, uint32_t index,
                                  const SurfelCandidates& p) {
  const std::string where = cat("record ", index);
  auto fail = [&](ErrorId id, const std::string& what) { return Status(id, where + ": " + what); };
  if (p.mesh != index)
    return fail(ErrorId::kSurfelFileField, cat("mesh ", p.mesh, " is not ", index));
  const size_t n = p.positions.size() / 3;
  if (p.positions.size() % 3 != 0 || p.normals.size() != p.positions.size()) {
    return fail(ErrorId::kSurfelWriterMisuse,
                cat(p.positions.size(), " position and ", p.normals.size(),
                    " normal floats are not 3 per candidate each"));
  }
  if (p.views.size() != h.direction_count) {
    return fail(ErrorId::kSurfelWriterMisuse,
                cat(p.views.size(), " views for ", h.direction_count, " directions"));
  }
  for (size_t s = 0; s < p.colour_sets.size(); ++s) {
    if (p.colour_sets[s].colours.size() != 3 * n) {
      return fail(ErrorId::kSurfelWriterMisuse,
                  cat("colour set ", s, " has ", p.colour_sets[s].colours.size(), " bytes for ", n,
                      " candidates"));
    }
  }
  const uint64_t max = uint64_t{h.direction_count} * h.resolution * h.resolution;
  if (n > max) {
    return fail(ErrorId::kSurfelFileLimit,
                cat(n, " candidates exceed ", max, " (directions x resolution^2)"));
  }
  if (p.colour_sets.size() > kSurfelMaxColourSets) {
    return fail(ErrorId::kSurfelFileLimit,
                cat(p.colour_sets.size(), " colour sets exceed ", kSurfelMaxColourSets));
  }
  float extent = 0;
  for (int a = 0; a < 3; ++a) {
    if (!std::isfinite(p.box_min[a]) || !std::isfinite(p.box_max[a]) ||
        !(p.box_min[a] <= p.box_max[a])) {
      return fail(ErrorId::kSurfelFileValue, cat("box axis ", a, " [", p.box_min[a], ", ",
                                                 p.box_max[a], "] is not finite and ordered"));
    }
    extent = std::max(extent, p.box_max[a] - p.box_min[a]);
  }
  uint64_t sum = 0;
  for (size_t v = 0; v < p.views.size(); ++v) {
    const SurfelCandidateView& view = p.views[v];
    if (!unit(view.direction.data())) {
      return fail(ErrorId::kSurfelFileValue, cat("views[", v, "].direction is not a unit vector"));
    }
    if (!std::isfinite(view.pixel_size) || !(view.pixel_size > 0)) {
      return fail(ErrorId::kSurfelFileValue,
                  cat("views[", v, "].pixel_size ", view.pixel_size, " is not finite and > 0"));
    }
    if (view.candidate_count > uint64_t{h.resolution} * h.resolution) {
      return fail(ErrorId::kSurfelFileLimit,
                  cat("views[", v, "].candidate_count ", view.candidate_count, " exceeds ",
                      uint64_t{h.resolution} * h.resolution));
    }
    sum += view.candidate_count;
  }
  if (sum != n) {
    return fail(ErrorId::kSurfelFileField,
                cat("the views' candidate counts add up to ", sum, ", not ", n));
  }
  for (size_t s = 1; s < p.colour_sets.size(); ++s) {
    if (!(p.colour_sets[s].material > p.colour_sets[s - 1].material)) {
      return fail(ErrorId::kSurfelFileField,
                  cat("colour set ", s, "'s material ", p.colour_sets[s].material,
                      " does not follow ", p.colour_sets[s - 1].material));
    }
  }
  const float tolerance = kSurfelBoxTolerance * extent + 1e-6f;
  for (size_t i = 0; i < n; ++i) {
    const float* q = &p.positions[3 * i];
    for (int a = 0; a < 3; ++a) {
      if (!(q[a] >= p.box_min[a] - tolerance && q[a] <= p.box_max[a] + tolerance)) {
        return fail(ErrorId::kSurfelFileValue, cat("candidate ", i, " position ", q[a], " on axis ",
                                                   a, " is outside the box"));
      }
    }
    if (!unit(&p.normals[3 * i])) {
      return fail(ErrorId::kSurfelFileValue, cat("candidate ", i, " normal is not a unit vector"));
    }
  }
  return Status::Ok();
}

Status check_surfel_candidates_match(std::span<const SurfelCandidateEntry> entries,
                                     const SceneFile& scene, std::string_view source) {
  if (entries.size() != scene.meshes.size()) {
    return Status(ErrorId::kSurfelSceneMismatch,
                  cat(source, ": ", entries.size(), " records for a scene of ", scene.meshes.size(),
                      " meshes"));
  }
  for (size_t i = 0; i < entries.size(); ++i) {
    const uint64_t expected = surfel_mesh_hash(scene.meshes[i]);
    if (entries[i].mesh_hash != expected) {
      return Status(
          ErrorId::kSurfelSceneMismatch,
          cat(source, ": record ", i, " was made from another mesh than the scene's mesh ", i, " '",
              scene.meshes[i].name, "' (mesh hash differs)"));
    }
    if (entries[i].colour_set_count > 0 && entries[i].last_material >= scene.materials.size()) {
      return Status(
          ErrorId::kSurfelSceneMismatch,
          cat(source, ": record ", i, " has a colour set of material ", entries[i].last_material,
              "; the scene has ", scene.materials.size(), " materials"));
    }
  }
  return Status::Ok();
}

std::vector<SurfelCandidateEntry> surfel_candidate_entries(const SurfelCandidateFile& file) {
  std::vector<SurfelCandidateEntry> out;
  uint64_t offset = container::min_size<FileHead>() + file.header.scene.size() + kHashBytes;
  for (const SurfelCandidates& p : file.prototypes) {
    SurfelCandidateEntry e;
    e.mesh = p.mesh;
    e.mesh_hash = p.mesh_hash;
    e.candidate_count = static_cast<uint32_t>(p.candidate_count());
    e.colour_set_count = static_cast<uint32_t>(p.colour_sets.size());
    if (!p.colour_sets.empty()) e.last_material = p.colour_sets.back().material;
    e.offset = offset;
    e.size = record_bytes(file.header.direction_count, e.candidate_count, e.colour_set_count);
    offset += e.size;
    out.push_back(e);
  }
  return out;
}

Expected<std::vector<uint8_t>> encode_surfel_candidates(const SurfelCandidateFile& file) {
  if (file.prototypes.size() != file.header.prototype_count) {
    return Status(
        ErrorId::kSurfelWriterMisuse,
        cat(file.prototypes.size(), " records for a header of ", file.header.prototype_count));
  }
  auto out = encode_header(file.header);
  if (!out.ok()) return out.status();
  for (uint32_t i = 0; i < file.prototypes.size(); ++i) {
    auto record = encode_record(file.header, i, file.prototypes[i]);
    if (!record.ok()) return record.status();
    out->insert(out->end(), record->begin(), record->end());
  }
  return out;
}

Expected<SurfelCandidateFile> parse_surfel_candidates(std::span<const uint8_t> bytes,
                                                      std::string_view source) {
  const auto src = container::memory_source(bytes);
  auto w = walk(*src, source);
  if (!w.ok()) return w.status();
  SurfelCandidateFile file;
  file.header = w->header;
  file.prototypes.reserve(w->entries.size());
  for (uint32_t i = 0; i < w->entries.size(); ++i) {
    auto p = read_entry(*src, *w, i, source);
    if (!p.ok()) return p.status();
    file.prototypes.push_back(std::move(*p));
  }
  return file;
}

// ---- writer ------------------------------------------------------------------------------------

struct SurfelCandidateWriter::Impl {
  SurfelCandidateHeader header;
  std::unique_ptr<container::ByteSink> sink;
  uint32_t next = 0;
  uint64_t bytes = 0;
  bool failed = false;
};

SurfelCandidateWriter::SurfelCandidateWriter(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
SurfelCandidateWriter::SurfelCandidateWriter(SurfelCandidateWriter&&) noexcept = default;
SurfelCandidateWriter& SurfelCandidateWriter::operator=(SurfelCandidateWriter&&) noexcept = default;
SurfelCandidateWriter::~SurfelCandidateWriter() = default;

Expected<SurfelCandidateWriter> SurfelCandidateWriter::create(const std::string& path,
                                                              const SurfelCandidateHeader& header) {
  auto head = encode_header(header);
  if (!head.ok()) return head.status();
  auto sink = container::create_file_sink(path);
  if (!sink.ok()) return sink.status();
  auto impl = std::make_unique<Impl>();
  impl->header = header;
  impl->sink = std::move(*sink);
  CALF_RETURN_IF_ERROR(impl->sink->append(*head));
  impl->bytes = head->size();
  return SurfelCandidateWriter(std::move(impl));
}

Status SurfelCandidateWriter::add(const SurfelCandidates& prototype) {
  if (impl_->next >= impl_->header.prototype_count) {
    return Status(
        ErrorId::kSurfelWriterMisuse,
        cat("record ", impl_->next, " is beyond the header's ", impl_->header.prototype_count));
  }
  if (prototype.mesh != impl_->next) {
    impl_->failed = true;
    return Status(ErrorId::kSurfelWriterMisuse,
                  cat("record ", impl_->next, " given for mesh ", prototype.mesh));
  }
  auto record = encode_record(impl_->header, impl_->next, prototype);
  if (!record.ok()) {
    impl_->failed = true;
    return record.status();
  }
  if (Status s = impl_->sink->append(*record); !s.ok()) {
    impl_->failed = true;
    return s;
  }
  impl_->bytes += record->size();
  ++impl_->next;
  return Status::Ok();
}

Status SurfelCandidateWriter::commit() {
  if (impl_->failed || impl_->next != impl_->header.prototype_count) {
    return Status(ErrorId::kSurfelWriterMisuse,
                  cat("commit after ", impl_->next, " of ", impl_->header.prototype_count,
                      " records", impl_->failed ? " and a failed add" : ""));
  }
  return impl_->sink->commit();
}

uint64_t SurfelCandidateWriter::bytes_written() const {
  return impl_->bytes;
}

Status write_surfel_candidates(const std::string& path, const SurfelCandidateFile& file) {
  if (file.prototypes.size() != file.header.prototype_count) {
    return Status(
        ErrorId::kSurfelWriterMisuse,
        cat(file.prototypes.size(), " records for a header of ", file.header.prototype_count));
  }
  auto writer = SurfelCandidateWriter::create(path, file.header);
  if (!writer.ok()) return writer.status();
  for (const SurfelCandidates& p : file.prototypes) CALF_RETURN_IF_ERROR(writer->add(p));
  return writer->commit();
}

// ---- reader ------------------------------------------------------------------------------------

struct SurfelCandidateReader::Impl {
  std::string path;
  std::unique_ptr<container::ByteSource> src;
  Walk walk;
};

SurfelCandidateReader::SurfelCandidateReader(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
SurfelCandidateReader::SurfelCandidateReader(SurfelCandidateReader&&) noexcept = default;
SurfelCandidateReader& SurfelCandidateReader::operator=(SurfelCandidateReader&&) noexcept = default;
SurfelCandidateReader::~SurfelCandidateReader() = default;

Expected<SurfelCandidateReader> SurfelCandidateReader::open(const std::string& path) {
  auto src = container::open_file_source(path);
  if (!src.ok()) return src.status();
  auto w = walk(**src, path);
  if (!w.ok()) return w.status();
  auto impl = std::make_unique<Impl>();
  impl->path = path;
  impl->src = std::move(*src);
  impl->walk = std::move(*w);
  return SurfelCandidateReader(std::move(impl));
}

const SurfelCandidateHeader& SurfelCandidateReader::header() const {
  return impl_->walk.header;
}

const std::vector<SurfelCandidateEntry>& SurfelCandidateReader::entries() const {
  return impl_->walk.entries;
}

Expected<SurfelCandidates> SurfelCandidateReader::read(uint32_t index) const {
  return read_entry(*impl_->src, impl_->walk, index, impl_->path);
}

Expected<SurfelCandidateFile> read_surfel_candidates(const std::string& path) {
  auto reader = SurfelCandidateReader::open(path);
  if (!reader.ok()) return reader.status();
  SurfelCandidateFile file;
  file.header = reader->header();
  for (uint32_t i = 0; i < reader->entries().size(); ++i) {
    auto p = reader->read(i);
    if (!p.ok()) return p.status();
    file.prototypes.push_back(std::move(*p));
  }
  return file;
}

}  // namespace calf::capture
