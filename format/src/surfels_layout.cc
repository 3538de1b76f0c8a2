// The surfels track's chunk layouts (format/SPEC.md §11.3); the rules are in surfels_layout.h.
#include "calf/format/surfels_layout.h"

#include <algorithm>
#include <bit>
#include <cmath>

#include "calf/format/colour.h"
#include "calf/format/coordinates.h"

namespace calf::surfels {
namespace {

using container::cat;

Status error(ErrorId id, const std::string& what, const std::string& message) {
  return Status(id, what + ": " + message);
}

Status check_record(const PrototypeRecord& r, size_t i, const std::string& what) {
  const std::string name = cat("prototypes[", i, "]");
  if (r.flags & ~kPrototypeFlags)
    return error(ErrorId::kSurfelsUnsupported, what, cat(name, ": reserved flags in ", r.flags));
  for (int c = 0; c < 3; ++c) {
    if (!coordinate_ok(r.box_min[c]) || !coordinate_ok(r.box_max[c]) ||
        !(r.box_min[c] <= r.box_max[c])) {
      return error(ErrorId::kSurfelsValue, what,
                   cat(name, ".box axis ", c, " [", r.box_min[c], ", ", r.box_max[c],
                       "] is inverted or beyond +-1e12"));
    }
  }
  if (r.surfel_count == 0) {
    if (r.prefix_count != 0 || r.prefix_radius != 0.0f)
      return error(ErrorId::kSurfelsValue, what,
                   cat(name, " has no surfels but prefix_count ", r.prefix_count,
                       " and prefix_radius ", r.prefix_radius, " (both must be 0)"));
    return Status::Ok();
  }
  if (r.prefix_count < 1 || r.prefix_count > r.surfel_count)
    return error(
        ErrorId::kSurfelsValue, what,
        cat(name, ".prefix_count ", r.prefix_count, " is not in [1, ", r.surfel_count, "]"));
  if (!(r.prefix_radius > 0.0f))
    return error(ErrorId::kSurfelsValue, what,
                 cat(name, ".prefix_radius ", r.prefix_radius, " is not positive"));
  return Status::Ok();
}

// Appends `n` 16-bit words as two byte planes: the low byte of every word, then the high bytes.
// Blue-noise order leaves neighbouring surfels far apart, so no prediction helps; the planes
// keep the low-entropy high bytes together for zstd / LZMA2.
void put_planes16(std::vector<uint8_t>& out, const uint16_t* words, size_t n) {
  const size_t at = out.size();
  out.resize(at + 2 * n);
  for (size_t i = 0; i < n; ++i) {
    out[at + i] = static_cast<uint8_t>(words[i]);
    out[at + n + i] = static_cast<uint8_t>(words[i] >> 8);
  }
}

uint16_t get16(const uint8_t* planes, size_t n, size_t i) {
  return static_cast<uint16_t>(planes[i] | planes[n + i] << 8);
}

}  // namespace

// ---- Index ----

Expected<std::vector<uint8_t>> serialize_index(const IndexChunk& index) {
  std::vector<uint8_t> out;
  CALF_RETURN_IF_ERROR(container::write_fields(index, out, "surfels index"));
  Expected<IndexChunk> back = parse_index(out, "surfels index");
  if (!back.ok()) return Status(ErrorId::kContainerWriterMisuse, back.status().message());
  return out;
}

Expected<IndexChunk> parse_index(std::span<const uint8_t> raw, const std::string& what) {
  // The layout version comes first and alone: a later layout may change everything after it.
  if (raw.size() < 4)
    return error(ErrorId::kSurfelsChunk, what, cat(raw.size(), " bytes, too short for a version"));
  const uint32_t version = static_cast<uint32_t>(container::load_le(raw.data(), 4));
  if (version != kLayoutVersion)
    return error(ErrorId::kSurfelsUnsupported, what,
                 cat("layout version ", version, ", expected 1"));
  IndexChunk x;
  container::FieldReader r(raw, ErrorId::kSurfelsChunk, ErrorId::kSurfelsValue, what,
                           ErrorId::kSurfelsLimit);
  CALF_RETURN_IF_ERROR(container::read_fields(x, r));
  if (r.remaining() != 0)
    return error(ErrorId::kSurfelsChunk, what, cat(r.remaining(), " bytes after the prototypes"));
  if (x.flags != 0)
    return error(ErrorId::kSurfelsUnsupported, what, cat("reserved flags ", x.flags, " set"));
  for (size_t i = 0; i < x.prototypes.size(); ++i)
    CALF_RETURN_IF_ERROR(check_record(x.prototypes[i], i, what));
  return x;
}

// ---- Levels ----

uint32_t level_count(uint64_t n) {
  uint32_t k = 0;
  while (level_begin(k) < n) ++k;
  return k;
}

// Levels past 2^64 surfels do not exist; their bounds saturate instead of overflowing the shift.
uint64_t level_begin(uint32_t k) {
  if (k == 0) return 0;
  return k - 1 < 54 ? uint64_t{kFirstLevelSurfels} << (k - 1) : UINT64_MAX;
}

uint64_t level_end(uint32_t k, uint64_t n) {
  return std::min(n, k < 54 ? uint64_t{kFirstLevelSurfels} << k : UINT64_MAX);
}

uint64_t level_chunk_size(uint32_t k, uint64_t n) {
  const uint64_t b = level_begin(k), e = level_end(k, n);
  return e > b ? kSurfelBytes * (e - b) : 0;
}

// ---- Values ----

float decode_position(uint16_t q, float lo, float hi) {
  // Both products are exact in binary64 (24 + 16 bits); codes 0 and 65535 give lo and hi
  // exactly, so a decoded buffer keeps its box and re-encodes to the same codes.
  const double sum = static_cast<double>(kPositionSteps - q) * lo + static_cast<double>(q) * hi;
  return static_cast<float>(sum / kPositionSteps);
}

void decode_normal(uint16_t u, uint16_t v, float* out) {
  double a = u / static_cast<double>(kNormalSteps) * 2.0 - 1.0;
  double b = v / static_cast<double>(kNormalSteps) * 2.0 - 1.0;
  const double z = 1.0 - std::fabs(a) - std::fabs(b);
  if (z < 0) {
    // The lower hemisphere is folded over the square's diagonals.
    const double fa = (1.0 - std::fabs(b)) * (a >= 0 ? 1.0 : -1.0);
    const double fb = (1.0 - std::fabs(a)) * (b >= 0 ? 1.0 : -1.0);
    a = fa;
    b = fb;
  }
  const double len = std::sqrt(a * a + b * b + z * z);
  out[0] = static_cast<float>(a / len);
  out[1] = static_cast<float>(b / len);
  out[2] = static_cast<float>(z / len);
}

float decode_colour(uint8_t c) {
  return linear_from_srgb8(c);
}

Expected<std::vector<uint8_t>> encode_level(const SurfelCodes& codes, uint64_t begin,
                                            uint64_t end) {
  const size_t n = codes.size();
  if (codes.positions.size() != 3 * n || codes.normals.size() != 2 * n || begin > end || end > n) {
    return Status(
        ErrorId::kContainerWriterMisuse,
        cat("surfels level: ", codes.positions.size(), " position, ", codes.normals.size(),
            " normal and ", codes.colours.size(), " colour codes, range [", begin, ", ", end, ")"));
  }
  const size_t m = end - begin;
  std::vector<uint16_t> words(3 * m);
  std::vector<uint8_t> out;
  out.reserve(kSurfelBytes * m);
  for (size_t c = 0; c < 3; ++c) {
    for (size_t i = 0; i < m; ++i) words[c * m + i] = codes.positions[3 * (begin + i) + c];
  }
  put_planes16(out, words.data(), 3 * m);
  words.resize(2 * m);
  for (size_t c = 0; c < 2; ++c) {
    for (size_t i = 0; i < m; ++i) words[c * m + i] = codes.normals[2 * (begin + i) + c];
  }
  put_planes16(out, words.data(), 2 * m);
  for (size_t c = 0; c < 3; ++c) {
    for (size_t i = 0; i < m; ++i) out.push_back(codes.colours[3 * (begin + i) + c]);
  }
  return out;
}

Status decode_level(std::span<const uint8_t> raw, const PrototypeRecord& p, uint32_t k,
                    SurfelArrays* out, const std::string& what) {
  const uint64_t n = p.surfel_count;
  if (k >= level_count(n) || out->size() != level_begin(k) ||
      out->normals.size() != out->positions.size() ||
      out->colours.size() != out->positions.size()) {
    return Status(ErrorId::kInvalidArgument, cat(what, ": level ", k, " of ", level_count(n),
                                                 " appended to ", out->size(), " surfels"));
  }
  const uint64_t want = level_chunk_size(k, n);
  if (raw.size() != want) {
    return error(ErrorId::kSurfelsChunk, what,
                 cat(raw.size(), " bytes, expected ", want, " for surfels [", level_begin(k), ", ",
                     level_end(k, n), ")"));
  }
  const size_t m = static_cast<size_t>(level_end(k, n) - level_begin(k));
  const size_t at = out->positions.size();
  out->positions.resize(at + 3 * m);
  out->normals.resize(at + 3 * m);
  out->colours.resize(at + 3 * m);
  const uint8_t* pos = raw.data();
  const uint8_t* nrm = pos + 6 * m;
  const uint8_t* col = nrm + 4 * m;
  for (size_t i = 0; i < m; ++i) {
    float* x = &out->positions[at + 3 * i];
    for (size_t c = 0; c < 3; ++c)
      x[c] = decode_position(get16(pos, 3 * m, c * m + i), p.box_min[c], p.box_max[c]);
    decode_normal(get16(nrm, 2 * m, i), get16(nrm, 2 * m, m + i), &out->normals[at + 3 * i]);
    float* rgb = &out->colours[at + 3 * i];
    for (size_t c = 0; c < 3; ++c) rgb[c] = decode_colour(col[c * m + i]);
  }
  return Status::Ok();
}

// ---- Prefix size ----

uint32_t prefix_for_radius(const PrototypeRecord& p, double r) {
  const uint32_t n = p.surfel_count;
  if (n == 0) return 0;
  if (!(r > 0)) return n;
  const double ratio = static_cast<double>(p.prefix_radius) / r;
  const double want = std::ceil(p.prefix_count * ratio * ratio);
  if (!(want < n)) return n;  // also catches +inf
  return std::max<uint32_t>(1, static_cast<uint32_t>(want));
}

}  // namespace calf::surfels
