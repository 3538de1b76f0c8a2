// The surfels track encoder: validate, plan, independent level parts, ordered assembly (rules
// in surfels_encode.h).
#include "calf/encoder/surfels_encode.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <utility>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "calf/format/colour.h"
#include "calf/format/coordinates.h"

namespace calf::encoder {
namespace {

using container::cat;
using container::ChunkKeys;
using container::StoredChunk;
using container::SurfelsStream;

Status input_error(size_t p, const std::string& message) {
  return Status(ErrorId::kSurfelsInput, cat("surfels of prototype ", p, ": ", message));
}

// The tight float box of a prototype's positions (the quantisation box, SPEC §11.3.2).
surfels::PrototypeRecord make_record(const SurfelPrototypeInput& in) {
  surfels::PrototypeRecord r;
  r.surfel_count = static_cast<uint32_t>(in.size());
  r.flags = in.colour_is_base ? surfels::kColourIsBase : 0u;
  r.prefix_count = in.prefix_count;
  r.prefix_radius = in.prefix_radius;
  for (size_t i = 0; i < in.size(); ++i) {
    for (int c = 0; c < 3; ++c) {
      const float x = in.positions[3 * i + c];
      r.box_min[c] = i ? std::min(r.box_min[c], x) : x;
      r.box_max[c] = i ? std::max(r.box_max[c], x) : x;
    }
  }
  return r;
}

uint16_t quantise_position(float x, float lo, float hi) {
  const double extent = static_cast<double>(hi) - static_cast<double>(lo);
  if (!(extent > 0)) return 0;
  const double q = std::round((static_cast<double>(x) - lo) / extent * surfels::kPositionSteps);
  return static_cast<uint16_t>(std::clamp(q, 0.0, double{surfels::kPositionSteps}));
}

// Octahedral codes of a non-zero normal: the projection onto the octahedron, folded below the
// equator, then the best (largest cosine to the input after decoding) of the four codes around
// it. Rounding alone would lose up to twice the error near the fold.
std::array<uint16_t, 2> quantise_normal(const float* n) {
  const double x = n[0], y = n[1], z = n[2];
  const double l1 = std::fabs(x) + std::fabs(y) + std::fabs(z);
  double a = x / l1, b = y / l1;
  if (z < 0) {
    const double fa = (1.0 - std::fabs(b)) * (a >= 0 ? 1.0 : -1.0);
    const double fb = (1.0 - std::fabs(a)) * (b >= 0 ? 1.0 : -1.0);
    a = fa;
    b = fb;
  }
  const double steps = surfels::kNormalSteps;
  const double fu = std::clamp((a + 1.0) * 0.5 * steps, 0.0, steps);
  const double fv = std::clamp((b + 1.0) * 0.5 * steps, 0.0, steps);
  // Candidates are compared by the sine of their angle to the input, |d x n| / |d| (n fixed):
  // well conditioned for small angles, where a cosine near 1 would drown in the float rounding
  // of the decoded normal. A candidate on the far side (cosine < 0) never wins.
  std::array<uint16_t, 2> best = {0, 0};
  double best_sine = 4;
  for (const double u : {std::floor(fu), std::ceil(fu)}) {
    for (const double v : {std::floor(fv), std::ceil(fv)}) {
      float f[3];
      surfels::decode_normal(static_cast<uint16_t>(u), static_cast<uint16_t>(v), f);
      const double d[3] = {f[0], f[1], f[2]};
      if (d[0] * x + d[1] * y + d[2] * z <= 0) continue;
      const double c[3] = {d[1] * z - d[2] * y, d[2] * x - d[0] * z, d[0] * y - d[1] * x};
      const double sine = std::sqrt((c[0] * c[0] + c[1] * c[1] + c[2] * c[2]) /
                                    (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]));
      if (sine < best_sine) {
        best_sine = sine;
        best = {static_cast<uint16_t>(u), static_cast<uint16_t>(v)};
      }
    }
  }
  return best;
}

// The sRGB byte whose decoded linear value is nearest to `linear` (ties to the lower byte): a
// value that is itself a decoded byte comes back as that byte.
uint8_t quantise_colour(float linear) {
  static const std::array<float, 256> table = [] {
    std::array<float, 256> t{};
    for (int i = 0; i < 256; ++i) t[i] = surfels::decode_colour(static_cast<uint8_t>(i));
    return t;
  }();
  const auto it = std::lower_bound(table.begin(), table.end(), linear);
  if (it == table.begin()) return 0;
  if (it == table.end()) return 255;
  const auto hi = static_cast<size_t>(it - table.begin());
  return static_cast<uint8_t>(linear - table[hi - 1] <= table[hi] - linear ? hi - 1 : hi);
}

// One chunk ready to add, or the error of the task that made it.
struct Part {
  Status status;
  ChunkKeys keys;
  StoredChunk chunk;
};

}  // namespace

Status validate_surfels_input(const SurfelsTrackInput& input) {
  if (input.mesh_track >= container::kMaxTracks)
    return Status(ErrorId::kSurfelsInput,
                  cat("mesh track ", input.mesh_track, " is above the container's tracks"));
  if (input.prototypes.size() > surfels::kMaxPrototypes)
    return Status(ErrorId::kSurfelsLimit, cat(input.prototypes.size(), " prototypes, above ",
                                              surfels::kMaxPrototypes, " (SPEC §11.3)"));
  for (size_t p = 0; p < input.prototypes.size(); ++p) {
    const SurfelPrototypeInput& in = input.prototypes[p];
    const size_t n = in.size();
    if (in.positions.size() != 3 * n || in.normals.size() != 3 * n || in.colours.size() != 3 * n)
      return input_error(p,
                         cat(in.positions.size(), " position, ", in.normals.size(), " normal and ",
                             in.colours.size(), " colour floats (3 per surfel each)"));
    if (n > surfels::kMaxSurfels)
      return Status(ErrorId::kSurfelsLimit, cat("surfels of prototype ", p, ": ", n,
                                                " surfels, above ", surfels::kMaxSurfels));
    if (n == 0 ? (in.prefix_count != 0 || in.prefix_radius != 0.0f)
               : (in.prefix_count < 1 || in.prefix_count > n || !std::isfinite(in.prefix_radius) ||
                  !(in.prefix_radius > 0.0f))) {
      return input_error(p, cat("prefix_count ", in.prefix_count, " and prefix_radius ",
                                in.prefix_radius, " for ", n,
                                " surfels (want 1 <= p_m <= N and r_m > 0, or both 0 without "
                                "surfels)"));
    }
    for (size_t i = 0; i < n; ++i) {
      const float* x = &in.positions[3 * i];
      const float* nv = &in.normals[3 * i];
      const float* c = &in.colours[3 * i];
      if (!coordinate_ok(x[0]) || !coordinate_ok(x[1]) || !coordinate_ok(x[2]))
        return input_error(p, cat("surfel ", i, " position (", x[0], ", ", x[1], ", ", x[2],
                                  ") is not finite within +-1e12"));
      if (!std::isfinite(nv[0]) || !std::isfinite(nv[1]) || !std::isfinite(nv[2]) ||
          (nv[0] == 0 && nv[1] == 0 && nv[2] == 0))
        return input_error(p, cat("surfel ", i, " normal (", nv[0], ", ", nv[1], ", ", nv[2],
                                  ") is zero or not finite"));
      for (int k = 0; k < 3; ++k) {
        if (!(c[k] >= 0.0f && c[k] <= 1.0f))
          return input_error(p, cat("surfel ", i, " colour ", c[k], " is outside [0, 1]"));
      }
    }
  }
  return Status::Ok();
}

surfels::SurfelCodes quantise_surfels(const SurfelPrototypeInput& in,
                                      const surfels::PrototypeRecord& r) {
  const size_t n = in.size();
  surfels::SurfelCodes codes;
  codes.positions.resize(3 * n);
  codes.normals.resize(2 * n);
  codes.colours.resize(3 * n);
  for (size_t i = 0; i < n; ++i) {
    for (int c = 0; c < 3; ++c) {
      codes.positions[3 * i + c] =
          quantise_position(in.positions[3 * i + c], r.box_min[c], r.box_max[c]);
      codes.colours[3 * i + c] = quantise_colour(in.colours[3 * i + c]);
    }
    const auto uv = quantise_normal(&in.normals[3 * i]);
    codes.normals[2 * i] = uv[0];
    codes.normals[2 * i + 1] = uv[1];
  }
  return codes;
}

Status encode_surfels_track(const SurfelsTrackInput& input, const SurfelsEncodeOptions& options,
                            container::Writer* writer, SurfelsEncodeStats* stats) {
  if (options.threads > 256)
    return Status(ErrorId::kEncoderOption, cat("threads ", options.threads, " is above 256"));
  if (static_cast<uint16_t>(options.supercompression) >= container::kCompressionCount)
    return Status(ErrorId::kEncoderOption, "unknown supercompression");
  CALF_RETURN_IF_ERROR(validate_surfels_input(input));

  // The plan: records, index, header, and the list of level parts.
  container::SurfelsTrackHeader header;
  header.frame_count = input.frame_count;
  header.fps_numerator = input.fps_numerator;
  header.fps_denominator = input.fps_denominator;
  surfels::IndexChunk index;
  index.mesh_track = input.mesh_track;
  struct Level {
    uint32_t prototype, level;
  };
  std::vector<Level> levels;
  for (size_t p = 0; p < input.prototypes.size(); ++p) {
    index.prototypes.push_back(make_record(input.prototypes[p]));
    header.surfel_count += input.prototypes[p].size();
    for (uint32_t k = 0; k < surfels::level_count(input.prototypes[p].size()); ++k)
      levels.push_back({static_cast<uint32_t>(p), k});
  }
  header.object_count = static_cast<uint32_t>(input.prototypes.size());
  CALF_ASSIGN_OR_RETURN(const std::vector<uint8_t> index_raw, surfels::serialize_index(index));
  CALF_ASSIGN_OR_RETURN(
      const StoredChunk index_chunk,
      container::compress_chunk(index_raw, options.supercompression, options.levels));

  // Independent parts: every level of every prototype, quantised and coded into its own slot.
  // Quantising per level (not per prototype) keeps a 100k-surfel prototype from serialising the
  // work; a surfel's codes depend on its prototype's box only.
  std::vector<Part> parts(levels.size());
  tbb::task_arena arena(options.threads == 0 ? tbb::task_arena::automatic
                                             : static_cast<int>(options.threads));
  arena.execute([&] {
    tbb::parallel_for(
        tbb::blocked_range<size_t>(0, levels.size(), 1),
        [&](const tbb::blocked_range<size_t>& range) {
          for (size_t i = range.begin(); i < range.end(); ++i) {
            const Level& l = levels[i];
            const SurfelPrototypeInput& in = input.prototypes[l.prototype];
            const uint64_t b = surfels::level_begin(l.level);
            const uint64_t e = surfels::level_end(l.level, in.size());
            SurfelPrototypeInput slice;
            slice.positions.assign(in.positions.begin() + 3 * b, in.positions.begin() + 3 * e);
            slice.normals.assign(in.normals.begin() + 3 * b, in.normals.begin() + 3 * e);
            slice.colours.assign(in.colours.begin() + 3 * b, in.colours.begin() + 3 * e);
            const surfels::SurfelCodes codes =
                quantise_surfels(slice, index.prototypes[l.prototype]);
            Part& part = parts[i];
            Expected<std::vector<uint8_t>> raw = surfels::encode_level(codes, 0, codes.size());
            if (!raw.ok()) {
              part.status = raw.status();
              continue;
            }
            Expected<StoredChunk> c =
                container::compress_chunk(*raw, options.supercompression, options.levels);
            if (!c.ok()) {
              part.status = c.status();
              continue;
            }
            part.chunk = std::move(*c);
            part.keys.stream = static_cast<uint16_t>(SurfelsStream::kSurfels);
            part.keys.region = l.prototype;
            part.keys.layer = l.level;
          }
        });
  });

  // A surfels track adds to what the mesh track already plays: optional (SPEC §11 item 3).
  CALF_ASSIGN_OR_RETURN(const uint16_t track, writer->add_track(header, 0));
  SurfelsEncodeStats s;
  s.prototypes = header.object_count;
  s.surfels = header.surfel_count;
  for (const auto& in : input.prototypes) s.prototypes_with_surfels += in.size() ? 1 : 0;
  s.plain_bytes = 36 * s.surfels;
  ChunkKeys keys;
  keys.track = track;
  keys.stream = static_cast<uint16_t>(SurfelsStream::kIndex);
  CALF_RETURN_IF_ERROR(writer->add_stored_chunk(keys, index_chunk).status());
  s.index_stored = index_chunk.bytes.size();
  for (Part& part : parts) {
    CALF_RETURN_IF_ERROR(part.status);
    part.keys.track = track;
    CALF_RETURN_IF_ERROR(writer->add_stored_chunk(part.keys, part.chunk).status());
    s.level_chunks += 1;
    s.surfels_raw += part.chunk.raw_size;
    s.surfels_stored += part.chunk.bytes.size();
  }
  if (stats) *stats = s;
  return Status::Ok();
}

}  // namespace calf::encoder
