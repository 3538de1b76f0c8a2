#include "calf/encoder/lightfield_encode.h"

#include "calf/format/colour.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <numeric>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "calf/encoder/bc_encode.h"
#include "calf/encoder/bc_rdo.h"
#include "calf/encoder/color_keyframes.h"
#include "calf/encoder/depth_aabb.h"
#include "calf/format/bc.h"
#include "calf/format/clip_metadata.h"
#include "calf/format/depth_predict.h"
#include "calf/format/files.h"
#include "calf/format/grid.h"
#include "calf/format/lightfield_layout.h"
#include "calf/format/log_depth.h"
#include "calf/format/version.h"
#include "colour_av1.h"
#include "lightfield_internal.h"

namespace calf {
namespace {

using container::ChunkKeys;
using container::Compression;
using container::LightfieldStream;
using container::PixelFormat;
using container::StoredChunk;

constexpr double kInf = std::numeric_limits<double>::infinity();

// ---- Colour conversions (SPEC §11.1: 8-bit colour formats hold sRGB-encoded values) ----

uint16_t half_from_colour(float v) {
  return bc::float_to_half(std::min(v, 65504.0f));  // input is validated finite and >= 0
}

// ---- One view in memory ----

struct ViewData {
  uint32_t frames = 0, face_size = 0;
  size_t texels = 0;                        // per frame, all six faces
  std::vector<uint16_t> colour;             // half RGB, [frame][texel][3]
  std::vector<uint16_t> depth;              // log-16 codes, [frame][texel]
  std::vector<uint8_t> material;            // [frame][texel][3] codes, empty without material
  std::vector<lf::CoverageTexel> coverage;  // [frame][texel], empty without a coverage stream
  std::optional<LogDepthRange> range;       // none when the view sees only sky
  bool has_material = false;                // some texel of some frame reflects or refracts

  size_t index(uint32_t frame, uint32_t face, uint32_t x, uint32_t y) const {
    return static_cast<size_t>(frame) * texels +
           (static_cast<size_t>(face) * face_size + y) * face_size + x;
  }
};

// Reads every frame of `view` and checks that the images still say what the analysis saw
// (`expected`): the depth codes are taken in the analysis's range.
// The coverage of view-frame `vf` as the stream codes it (SPEC §11.1.11): near and far shares
// whole sixteenths and near + far + the mask's cells = 16, else kEncoderCoverage.
Status coverage_texels(const capture::CaptureSetReader& input, uint32_t view, uint32_t frame,
                       const capture::ViewFrame& vf, lf::CoverageTexel* out) {
  const size_t n = vf.texel_count(), per_face = size_t{vf.face_size} * vf.face_size;
  for (size_t i = 0; i < n; ++i) {
    const float near = vf.coverage[3 * i] * 16, far = vf.coverage[3 * i + 1] * 16;
    const uint16_t mask = static_cast<uint16_t>(vf.coverage[3 * i + 2]);  // validated 0..65535
    // A sky texel has nothing farther than it (SPEC §11.1.11 "Coverage and depth").
    if (near != std::nearbyint(near) || far != std::nearbyint(far) ||
        near + far + static_cast<float>(std::popcount(mask)) != 16.0f ||
        (std::isinf(vf.depth[i]) && far != 0)) {
      const size_t texel = i % per_face;
      return Status(ErrorId::kEncoderCoverage,
                    input.image_path(view, frame).string() + ": face " +
                        std::to_string(i / per_face) + " texel (" +
                        std::to_string(texel % vf.face_size) + ", " +
                        std::to_string(texel / vf.face_size) + "): coverage near " +
                        std::to_string(vf.coverage[3 * i]) + ", far " +
                        std::to_string(vf.coverage[3 * i + 1]) + ", mask " + std::to_string(mask) +
                        " is not 16 cells of 1/16 (near + far + mask bits), or has cells "
                        "farther than its sky depth; --no-coverage drops coverage");
    }
    out[i] = {mask, static_cast<uint8_t>(near)};
  }
  return Status::Ok();
}

Status read_view(const capture::CaptureSetReader& input, uint32_t view,
                 const LightfieldViewFacts& expected, bool with_coverage, uint32_t first_frame,
                 uint32_t frame_count, ViewData* out) {
  const capture::CaptureManifest& m = input.manifest();
  out->frames = frame_count;
  out->face_size = m.face_size;
  out->texels = size_t{6} * m.face_size * m.face_size;
  out->colour.assign(out->texels * 3 * frame_count, 0);
  out->material.clear();
  if (m.material) out->material.assign(out->texels * 3 * frame_count, 0);
  out->coverage.clear();
  if (with_coverage) out->coverage.resize(out->texels * frame_count);
  std::vector<float> depth(out->texels * frame_count);
  lightfield_internal::ViewFactsBuilder facts;
  capture::ViewFrame vf;
  for (uint32_t f = 0; f < frame_count; ++f) {
    CALF_RETURN_IF_ERROR(lightfield_internal::read_frame(input, view, first_frame + f, &vf));
    facts.add(vf);
    uint16_t* c = &out->colour[f * out->texels * 3];
    for (size_t i = 0; i < out->texels * 3; ++i) c[i] = half_from_colour(vf.color[i]);
    std::copy(vf.depth.begin(), vf.depth.end(), &depth[f * out->texels]);
    if (with_coverage) {
      CALF_RETURN_IF_ERROR(
          coverage_texels(input, view, first_frame + f, vf, &out->coverage[f * out->texels]));
    }
    if (m.material) {
      uint8_t* mc = &out->material[f * out->texels * 3];
      for (size_t i = 0; i < out->texels; ++i) {
        mc[3 * i] = lf::material_weight_code(vf.material[3 * i]);
        mc[3 * i + 1] = lf::material_weight_code(vf.material[3 * i + 1]);
        mc[3 * i + 2] = lf::material_ior_code(vf.material[3 * i + 2]);
      }
    }
  }
  CALF_ASSIGN_OR_RETURN(const LightfieldViewFacts seen, facts.finish());
  // All frames must say exactly what the analysis saw; a range of them only what fits it.
  const bool whole = first_frame == 0 && frame_count == m.frame_count;
  if (whole ? !lightfield_internal::same_facts(seen, expected) : !facts.within(expected)) {
    return Status(ErrorId::kEncoderInput,
                  "view " + std::to_string(view) + " (" + input.image_path(view, 0).string() +
                      ", ...): its depth range, material or HDR colour changed since the analysis");
  }
  out->range = expected.depth_range;
  out->has_material = expected.has_material;
  out->depth.assign(depth.size(), kLog16Sky);
  if (out->range) {
    const LogDepthRange& r = *out->range;
    for (size_t i = 0; i < depth.size(); ++i) out->depth[i] = r.encode_unchecked(depth[i]);
  }
  if (!out->has_material) out->material.clear();
  return Status::Ok();
}

// ---- Per-task output ----

struct Pending {
  ChunkKeys keys;
  StoredChunk chunk;
};

struct TaskStats {
  StreamBytes colour, depth, material, coverage;
  uint64_t keyframes = 0, depth_keyframes = 0, pframes = 0, empty_pframes = 0;
  double min_quality = kInf;
  double max_rel = 0, sum_rel = 0;
  uint64_t finite_texels = 0, sky_mismatches = 0;
};

struct TaskOut {
  Status status;
  std::vector<Pending> chunks;
  TaskStats stats;
};

struct Context {
  const LightfieldEncodeOptions* options;
  const ViewData* view;
  uint32_t view_index;
  ColourCoding colour;  // resolved (never kAuto)
  bool hdr;
  FaceGrid cells, tiles;
  uint32_t first_frame;  // the clip frame of the view data's frame 0
  bool partial;          // a frame range short of the clip: t chunks stay raw for the merge
  uint32_t fps_numerator = 24, fps_denominator = 1;  // the track's (AV1 colour's timing)
};

Status add_chunk(const Context& ctx, TaskOut& out, ChunkKeys keys, const std::vector<uint8_t>& raw,
                 StreamBytes& bytes, bool uncompressed = false) {
  keys.view = ctx.view_index;  // keys.track: set by LightfieldTrackWriter
  CALF_ASSIGN_OR_RETURN(StoredChunk c,
                        container::compress_chunk(
                            raw, uncompressed ? Compression::kNone : ctx.options->supercompression,
                            ctx.options->levels));
  bytes.spatial += raw.size();
  bytes.stored += c.bytes.size();
  bytes.chunks += 1;
  out.chunks.push_back({keys, std::move(c)});
  return Status::Ok();
}

// ---- Colour ----

// One frame of a cell coded spatially: the bytes as the format stores them (before the block
// split) and what the decoder shows (linear RGB floats).
struct CodedFrame {
  std::vector<uint8_t> bytes;
  std::vector<float> shown;
};

// The cell `r` of one frame of the view as half RGB (the capture's values), rows packed.
void gather_cell_halves(const ViewData& v, uint32_t face, const PixelRect& r, uint32_t frame,
                        uint16_t* out) {
  for (uint32_t y = 0; y < r.height; ++y) {
    const uint16_t* src = &v.colour[v.index(frame, face, r.x, r.y + y) * 3];
    std::copy(src, src + r.width * 3, out + size_t{y} * r.width * 3);
  }
}

// Linear RGB as 8-bit sRGB RGBA (alpha 255): what the LDR formats code.
std::vector<uint8_t> srgb8_rgba_of(std::span<const float> rgb) {
  const size_t n = rgb.size() / 3;
  std::vector<uint8_t> rgba(n * 4);
  for (size_t i = 0; i < n; ++i) {
    for (int c = 0; c < 3; ++c) rgba[4 * i + c] = srgb8_from_linear(rgb[3 * i + c]);
    rgba[4 * i + 3] = 255;
  }
  return rgba;
}

bc::Bc1Options bc1_options(Bc1Fit fit) {
  bc::Bc1Options o;
  o.quality = fit == Bc1Fit::kCluster ? 1 : 0;
  o.refine = fit == Bc1Fit::kRefined;
  return o;
}

Status code_colour_frame(ColourCoding coding, Bc1Fit bc1_fit, std::span<const float> rgb,
                         uint32_t w, uint32_t h, CodedFrame* out) {
  const size_t n = static_cast<size_t>(w) * h;
  out->shown.resize(n * 3);
  switch (coding) {
    case ColourCoding::kBc1:
    case ColourCoding::kBc7:
    case ColourCoding::kRgba8: {
      std::vector<uint8_t> rgba = srgb8_rgba_of(rgb);
      if (coding == ColourCoding::kRgba8) {
        out->bytes = rgba;
      } else {
        const bc::Format f = coding == ColourCoding::kBc1 ? bc::Format::kBc1 : bc::Format::kBc7;
        const bc::Image8 img{rgba.data(), w, h, size_t{w} * 4, 4};
        out->bytes.assign(bc::encode_bound(f, w, h), 0);
        if (coding == ColourCoding::kBc1) {
          CALF_RETURN_IF_ERROR(
              bc::encode_bc1(img, out->bytes.data(), out->bytes.size(), bc1_options(bc1_fit)));
        } else {
          bc::Bc7Options o;
          o.quality = 0;
          CALF_RETURN_IF_ERROR(bc::encode_bc7(img, out->bytes.data(), out->bytes.size(), o));
        }
        CALF_RETURN_IF_ERROR(bc::decode_image(f, out->bytes.data(), out->bytes.size(), w, h,
                                              rgba.data(), rgba.size(), size_t{w} * 4));
      }
      for (size_t i = 0; i < n; ++i) {
        for (int c = 0; c < 3; ++c) out->shown[3 * i + c] = linear_from_srgb8(rgba[4 * i + c]);
      }
      return Status::Ok();
    }
    case ColourCoding::kBc6h: {
      const bc::ImageF img{rgb.data(), w, h, size_t{w} * 3, 3};
      out->bytes.assign(bc::encode_bound(bc::Format::kBc6hUnsigned, w, h), 0);
      bc::Bc6hOptions o;
      o.quality = 0;
      CALF_RETURN_IF_ERROR(bc::encode_bc6h(img, out->bytes.data(), out->bytes.size(), o));
      std::vector<uint16_t> half(n * 3);
      CALF_RETURN_IF_ERROR(bc::decode_image(bc::Format::kBc6hUnsigned, out->bytes.data(),
                                            out->bytes.size(), w, h, half.data(), half.size() * 2,
                                            size_t{w} * 6));
      for (size_t i = 0; i < n * 3; ++i) out->shown[i] = bc::half_to_float(half[i]);
      return Status::Ok();
    }
    case ColourCoding::kRgba16f: {
      out->bytes.resize(n * 8);
      for (size_t i = 0; i < n; ++i) {
        for (int c = 0; c < 4; ++c) {
          const uint16_t hv = c < 3 ? half_from_colour(rgb[3 * i + c]) : uint16_t{0x3C00};
          out->bytes[8 * i + 2 * c] = static_cast<uint8_t>(hv);
          out->bytes[8 * i + 2 * c + 1] = static_cast<uint8_t>(hv >> 8);
          if (c < 3) out->shown[3 * i + c] = bc::half_to_float(hv);
        }
      }
      return Status::Ok();
    }
    case ColourCoding::kAuto:
    case ColourCoding::kAv1:  // coded by colour_av1_task, never frame by frame
      break;
  }
  return Status(ErrorId::kInternal, "unresolved colour format");
}

// The chunk payload of one coded keyframe (SPEC §11.1 "Colour keyframe chunk").
void append_colour_payload(ColourCoding coding, const std::vector<uint8_t>& bytes,
                           std::vector<uint8_t>& out) {
  switch (coding) {
    case ColourCoding::kBc1:
      lf::append_block_split(out, bytes, 8, false);
      break;
    case ColourCoding::kRgba8:
      lf::append_planes(out, bytes, 4);
      break;
    case ColourCoding::kRgba16f: {
      // Little-endian halves -> high bytes of every value, then low bytes.
      std::vector<uint8_t> swapped(bytes.size());
      for (size_t i = 0; i + 1 < bytes.size(); i += 2) {
        swapped[i] = bytes[i + 1];
        swapped[i + 1] = bytes[i];
      }
      lf::append_planes(out, swapped, 2);
      break;
    }
    default:
      out.insert(out.end(), bytes.begin(), bytes.end());
      break;
  }
}

// Rewrites keyframe `frame`'s BC1 / BC6H / BC7 blocks towards cheaper supercompression
// (calf/encoder/bc_rdo.h), measured against the frame's texels as the BCn encoder saw them.
Status rdo_keyframe(const Context& ctx, uint32_t face, const PixelRect& r, uint32_t frame,
                    std::vector<uint8_t>& bytes) {
  const size_t n = static_cast<size_t>(r.width) * r.height;
  bc::BcRdoOptions o;
  o.lambda = colour_rdo_lambda(*ctx.options, ctx.colour);
  std::vector<uint16_t> half(n * 3);
  gather_cell_halves(*ctx.view, face, r, frame, half.data());
  if (ctx.colour == ColourCoding::kBc6h) {
    return bc::rdo_bc6h(half.data(), r.width, r.height, bytes.data(), bytes.size(), o);
  }
  std::vector<float> rgb(n * 3);
  for (size_t i = 0; i < n * 3; ++i) rgb[i] = bc::half_to_float(half[i]);
  const std::vector<uint8_t> rgba = srgb8_rgba_of(rgb);
  if (ctx.colour == ColourCoding::kBc1) {
    return bc::rdo_bc1(rgba.data(), r.width, r.height, bytes.data(), bytes.size(), o);
  }
  return bc::rdo_bc7(rgba.data(), r.width, r.height, bytes.data(), bytes.size(), o);
}

// AV1 colour (SPEC §11.1.12): the cell's frames as sRGB bytes, or for HDR as their half floats
// (format av1hdr, each chunk headed by the cell's curve), one chunk per GOP.
void colour_av1_task(const Context& ctx, uint32_t face, uint32_t cell, TaskOut& out) {
  const ViewData& v = *ctx.view;
  const PixelRect r =
      ctx.cells.cell_rect(cell % ctx.cells.cells_per_side(), cell / ctx.cells.cells_per_side());
  const size_t n = static_cast<size_t>(r.width) * r.height;
  std::vector<uint16_t> half(n * 3 * v.frames);
  for (uint32_t f = 0; f < v.frames; ++f) gather_cell_halves(v, face, r, f, &half[f * n * 3]);
  Expected<av1_internal::HdrCell> coded = av1_internal::HdrCell{};
  if (ctx.hdr) {
    coded = av1_internal::encode_cell_hdr(half, r.width, r.height, v.frames, ctx.fps_numerator,
                                          ctx.fps_denominator, ctx.options->av1);
  } else {
    std::vector<float> linear(n * 3);
    std::vector<uint8_t> rgba(n * 4 * v.frames);
    for (uint32_t f = 0; f < v.frames; ++f) {
      for (size_t i = 0; i < n * 3; ++i) linear[i] = bc::half_to_float(half[f * n * 3 + i]);
      const std::vector<uint8_t> frame = srgb8_rgba_of(linear);
      std::copy(frame.begin(), frame.end(), &rgba[f * n * 4]);
    }
    auto gops = av1_internal::encode_cell(rgba, r.width, r.height, v.frames, ctx.fps_numerator,
                                          ctx.fps_denominator, ctx.options->av1);
    if (gops.ok()) {
      coded->gops = std::move(*gops);
    } else {
      coded = gops.status();
    }
  }
  if (!coded.ok()) {
    out.status =
        coded.status().with_context("view " + std::to_string(ctx.view_index) + " face " +
                                    std::to_string(face) + " cell " + std::to_string(cell));
    return;
  }
  TaskStats& s = out.stats;
  const uint64_t raw_texel = ctx.hdr ? 8 : 4;
  s.colour.raw += n * raw_texel * v.frames;
  s.colour.temporal += n * raw_texel * v.frames;
  s.keyframes += coded->gops.size();
  ChunkKeys keys;
  keys.stream = static_cast<uint16_t>(LightfieldStream::kColour);
  keys.face = face;
  keys.region = cell;
  uint32_t first = 0;
  std::vector<uint8_t> raw;
  for (const av1_internal::Gop& gop : coded->gops) {
    raw.clear();
    if (ctx.hdr) lf::append_av1_hdr_curve(raw, coded->curve);
    lf::append_av1_gop(raw, gop);
    keys.first_frame = ctx.first_frame + first;
    keys.frame_count = static_cast<uint32_t>(gop.size());
    first += keys.frame_count;
    // Entropy-coded already: stored as is.
    out.status = add_chunk(ctx, out, keys, raw, s.colour, true);
    if (!out.status.ok()) return;
  }
}

void colour_task(const Context& ctx, uint32_t face, uint32_t cell, TaskOut& out) {
  if (ctx.colour == ColourCoding::kAv1) return colour_av1_task(ctx, face, cell, out);
  const ViewData& v = *ctx.view;
  const PixelRect r =
      ctx.cells.cell_rect(cell % ctx.cells.cells_per_side(), cell / ctx.cells.cells_per_side());
  const size_t n = static_cast<size_t>(r.width) * r.height;
  const uint32_t frames = v.frames;
  std::vector<float> original(n * 3);
  std::vector<uint16_t> previous_half, current_half(n * 3);
  std::vector<CodedFrame> coded(frames);
  std::vector<float> shown_all(n * 3 * frames);
  for (uint32_t f = 0; f < frames; ++f) {
    gather_cell_halves(v, face, r, f, current_half.data());
    if (f > 0 && current_half == previous_half) {
      coded[f] = coded[f - 1];  // static content: the same bytes, no second encode
    } else {
      for (size_t i = 0; i < n * 3; ++i) original[i] = bc::half_to_float(current_half[i]);
      out.status = code_colour_frame(ctx.colour, ctx.options->bc1_fit, original, r.width, r.height,
                                     &coded[f]);
      if (!out.status.ok()) return;
    }
    std::copy(coded[f].shown.begin(), coded[f].shown.end(), &shown_all[f * n * 3]);
    std::swap(previous_half, current_half);
    current_half.resize(n * 3);
  }
  // Alg. 2 against the frames as the spatial codec shows them (see the header: what Q means).
  const ShownKeyframeFn shown = [&](uint32_t f) -> Expected<std::span<const float>> {
    return std::span<const float>(coded[f].shown);
  };
  const CellQualityFn quality = ctx.hdr ? CellQualityFn(psnr_log2) : CellQualityFn(psnr_srgb);
  KeyframeOptions ko;
  ko.min_quality_db = ctx.options->min_psnr_db;
  // Closed segments: the search restarts at every segment's first frame (ctx.first_frame is a
  // segment boundary), so a segment's keyframes and t depend on its own frames only.
  const uint32_t segment = ctx.options->segment_frames ? ctx.options->segment_frames : frames;
  CellKeyframes all;
  all.min_quality_db = kInf;
  for (uint32_t s0 = 0; s0 < frames; s0 += segment) {
    const uint32_t len = std::min(segment, frames - s0);
    const ShownKeyframeFn shown_in = [&](uint32_t f) { return shown(s0 + f); };
    auto part = select_cell_keyframes(
        std::span<const float>(shown_all).subspan(s0 * n * 3, size_t{len} * n * 3), len,
        static_cast<uint32_t>(n), shown_in, quality, ko);
    if (!part.ok()) {
      out.status = part.status();
      return;
    }
    for (const uint32_t kf : part->keyframes) all.keyframes.push_back(s0 + kf);
    all.t.insert(all.t.end(), part->t.begin(), part->t.end());
    all.min_quality_db = std::min(all.min_quality_db, part->min_quality_db);
  }
  const CellKeyframes* k = &all;
  TaskStats& s = out.stats;
  s.keyframes += k->keyframes.size();
  s.min_quality = std::min(s.min_quality, k->min_quality_db);
  const uint64_t raw_texel = ctx.hdr ? 8 : 4;
  s.colour.raw += n * raw_texel * frames;

  std::vector<uint8_t> raw;
  out.status = container::write_fields(lf::CellTimeline{k->keyframes, k->t}, raw, "t chunk");
  if (!out.status.ok()) return;
  s.colour.temporal += raw.size() + k->keyframes.size() * n * raw_texel;
  ChunkKeys keys;
  keys.stream = static_cast<uint16_t>(LightfieldStream::kTParams);
  keys.face = face;
  keys.region = cell;
  keys.first_frame = ctx.first_frame;
  keys.frame_count = frames;
  out.status = add_chunk(ctx, out, keys, raw, s.colour, ctx.partial);
  if (!out.status.ok()) return;
  for (size_t i = 0; i < k->keyframes.size(); ++i) {
    const uint32_t kf = k->keyframes[i];
    const uint32_t end = i + 1 < k->keyframes.size() ? k->keyframes[i + 1] : frames;
    raw.clear();
    if ((ctx.colour == ColourCoding::kBc6h || ctx.colour == ColourCoding::kBc7 ||
         ctx.colour == ColourCoding::kBc1) &&
        colour_rdo_lambda(*ctx.options, ctx.colour) > 0) {
      out.status = rdo_keyframe(ctx, face, r, kf, coded[kf].bytes);
      if (!out.status.ok()) return;
    }
    append_colour_payload(ctx.colour, coded[kf].bytes, raw);
    keys.stream = static_cast<uint16_t>(LightfieldStream::kColour);
    keys.first_frame = ctx.first_frame + kf;
    keys.frame_count = end - kf;
    out.status = add_chunk(ctx, out, keys, raw, s.colour);
    if (!out.status.ok()) return;
  }
}

// ---- Depth and material: keyframes + rectangle P-frames (Alg. 3) ----

// A tile's frames as interleaved bytes: depth [hi, lo] per texel, material [reflect, refract,
// ior] per texel.
struct TileFrames {
  uint32_t width = 0, height = 0, bytes_per_texel = 0, frames = 0;
  std::vector<uint8_t> data;  // [frame][y][x][byte]
  const uint8_t* texel(uint32_t f, uint32_t x, uint32_t y) const {
    return &data[((static_cast<size_t>(f) * height + y) * width + x) * bytes_per_texel];
  }
};

ChangeMask material_change_mask(const TileFrames& t, uint32_t first, uint32_t current,
                                uint32_t window) {
  ChangeMask mask;
  mask.width = t.width;
  mask.height = t.height;
  mask.bits.assign(static_cast<size_t>(t.width) * t.height, 0);
  const uint32_t from = current - std::min(window, current - first);
  for (uint32_t y = 0; y < t.height; ++y) {
    for (uint32_t x = 0; x < t.width; ++x) {
      for (uint32_t j = from; j < current; ++j) {
        if (std::memcmp(t.texel(current, x, y), t.texel(j, x, y), t.bytes_per_texel) != 0) {
          mask.bits[static_cast<size_t>(y) * t.width + x] = 1;
          break;
        }
      }
    }
  }
  return mask;
}

// kRawPredicted: depth only, raw codes replaced by their prediction residuals per rectangle;
// kRawPredictedMasked: the same, but a P-frame rectangle keeps only its changed texels' residuals
// behind a change mask (SPEC §11.1.9).
// kCoverage: the coverage stream's edge bitmaps and planes (SPEC §11.1.11).
enum class RegionCoding : uint8_t {
  kRaw,
  kRawPredicted,
  kRawPredictedMasked,
  kBc5,
  kBc1,
  kCoverage
};

// Codes frames [first, first + count) of a tile into one chunk (SPEC §11.1 "Region chunk").
// `decoded` is the decoder's tile state (bytes_per_texel == 2 only), for the BC5 error report.
Status code_region_group(const Context& ctx, const TileFrames& t, bool is_depth,
                         RegionCoding coding, uint32_t first, uint32_t count,
                         std::vector<uint8_t>& raw, TaskStats& s, StreamBytes& bytes,
                         std::vector<uint16_t>* decoded) {
  const LightfieldEncodeOptions& o = *ctx.options;
  std::vector<std::vector<PixelRect>> rects(count);
  std::vector<std::span<const uint16_t>> depth_frames;
  std::vector<uint16_t> depth_codes;
  if (is_depth) {
    depth_codes.resize(static_cast<size_t>(count) * t.width * t.height);
    for (uint32_t f = 0; f < count; ++f) {
      for (size_t i = 0; i < static_cast<size_t>(t.width) * t.height; ++i) {
        const uint8_t* p = &t.data[((first + f) * static_cast<size_t>(t.width) * t.height + i) * 2];
        depth_codes[f * static_cast<size_t>(t.width) * t.height + i] =
            static_cast<uint16_t>(p[0] << 8 | p[1]);
      }
    }
    for (uint32_t f = 0; f < count; ++f) {
      depth_frames.push_back(std::span<const uint16_t>(depth_codes)
                                 .subspan(f * static_cast<size_t>(t.width) * t.height,
                                          static_cast<size_t>(t.width) * t.height));
    }
  }
  AabbOptions ao;
  ao.max_boxes = o.max_aabbs;
  const bool masked = coding == RegionCoding::kRawPredictedMasked;
  const bool coverage = coding == RegionCoding::kCoverage;
  const bool raw_texels =
      coding == RegionCoding::kRaw || coding == RegionCoding::kRawPredicted || masked;
  ao.alignment = raw_texels || coverage ? 1 : 4;
  rects[0].push_back({0, 0, t.width, t.height});
  std::vector<ChangeMask> masks(masked ? count : 0);
  for (uint32_t f = 1; f < count; ++f) {
    ChangeMask mask;
    if (is_depth) {
      // The window never reaches before the group's keyframe: the decoder starts there.
      CALF_ASSIGN_OR_RETURN(mask, depth_change_mask(std::span(depth_frames).first(f + 1), t.width,
                                                    t.height, f, o.depth_window, 0));
    } else {
      mask = material_change_mask(t, first, first + f, o.depth_window);
    }
    CALF_ASSIGN_OR_RETURN(rects[f], fit_change_boxes(mask, ao));
    if (masked) masks[f] = std::move(mask);
  }
  raw.clear();
  lf::RegionHead head;
  for (uint32_t f = 0; f < count; ++f) {
    head.rect_counts.push_back(static_cast<uint32_t>(rects[f].size()));
    for (const PixelRect& r : rects[f]) {
      lf::RegionRect& disk = head.rects.emplace_back();
      disk.x = static_cast<uint16_t>(r.x);
      disk.y = static_cast<uint16_t>(r.y);
      disk.w = static_cast<uint16_t>(r.width);
      disk.h = static_cast<uint16_t>(r.height);
    }
  }
  CALF_RETURN_IF_ERROR(container::write_fields(head, raw, "region chunk"));
  const size_t header = raw.size();
  uint64_t covered = 0;
  std::vector<uint8_t> texels, blocks, rect_bytes, decoded_rect, mask_bytes;

  std::vector<uint16_t> rect_codes, residuals;
  std::vector<lf::CoverageTexel> coverage_texels;  // kCoverage: every rectangle's, in order
  std::vector<std::pair<uint32_t, uint32_t>> coverage_sizes;
  for (uint32_t f = 0; f < count; ++f) {
    if (f == 0) {
      s.depth_keyframes += is_depth ? 1 : 0;
    } else if (is_depth) {
      s.pframes += 1;
      s.empty_pframes += rects[f].empty() ? 1 : 0;
    }
    for (const PixelRect& r : rects[f]) {
      covered += static_cast<uint64_t>(r.width) * r.height;
      rect_bytes.clear();
      for (uint32_t y = 0; y < r.height; ++y) {
        const uint8_t* p = t.texel(first + f, r.x, r.y + y);
        rect_bytes.insert(rect_bytes.end(), p, p + size_t{r.width} * t.bytes_per_texel);
      }
      if (coding == RegionCoding::kRaw) {
        texels.insert(texels.end(), rect_bytes.begin(), rect_bytes.end());
        continue;
      }
      if (coverage) {
        // Tile bytes per texel: mask high, mask low, near count.
        for (size_t i = 0; i + 2 < rect_bytes.size(); i += 3) {
          coverage_texels.push_back(
              {static_cast<uint16_t>(rect_bytes[i] << 8 | rect_bytes[i + 1]), rect_bytes[i + 2]});
        }
        coverage_sizes.emplace_back(r.width, r.height);
        continue;
      }
      if (coding == RegionCoding::kRawPredicted || masked) {
        const size_t n = size_t{r.width} * r.height, texels_before = texels.size();
        rect_codes.resize(n);
        residuals.resize(n);
        for (size_t i = 0; i < n; ++i)
          rect_codes[i] = static_cast<uint16_t>(rect_bytes[2 * i] << 8 | rect_bytes[2 * i + 1]);
        lf::predict_depth_rect(rect_codes.data(), r.width, r.height, r.width, residuals.data());
        if (masked && f > 0) {
          // §11.1.9: the rectangle's change mask (its own bytes, bit i = texel i, LSB first),
          // and only the changed texels' residuals. A texel outside the change mask equals its
          // code in every frame of the window, so any decoder there already holds it.
          const size_t at = mask_bytes.size();
          mask_bytes.resize(at + lf::mask_bytes_of(r.width, r.height), 0);
          size_t i = 0;
          for (uint32_t y = 0; y < r.height; ++y) {
            for (uint32_t x = 0; x < r.width; ++x, ++i) {
              if (!masks[f].at(r.x + x, r.y + y)) continue;
              mask_bytes[at + i / 8] |= static_cast<uint8_t>(1u << (i % 8));
              texels.push_back(static_cast<uint8_t>(residuals[i] >> 8));
              texels.push_back(static_cast<uint8_t>(residuals[i]));
            }
          }
          covered -= n - (texels.size() - texels_before) / 2;
          continue;
        }
        for (uint16_t e : residuals) {
          texels.push_back(static_cast<uint8_t>(e >> 8));
          texels.push_back(static_cast<uint8_t>(e));
        }
        continue;
      }
      const bc::Format bf = coding == RegionCoding::kBc5 ? bc::Format::kBc5 : bc::Format::kBc1;
      std::vector<uint8_t> rect_blocks(bc::encode_bound(bf, r.width, r.height));
      const bc::Image8 img{rect_bytes.data(), r.width, r.height,
                           size_t{r.width} * t.bytes_per_texel, t.bytes_per_texel};
      if (coding == RegionCoding::kBc5) {
        CALF_RETURN_IF_ERROR(bc::encode_bc5(img, rect_blocks.data(), rect_blocks.size(), {}));
      } else {
        CALF_RETURN_IF_ERROR(bc::encode_bc1(img, rect_blocks.data(), rect_blocks.size(), {}));
      }
      if (decoded != nullptr) {
        decoded_rect.resize(size_t{r.width} * r.height * 2);
        CALF_RETURN_IF_ERROR(bc::decode_image(bf, rect_blocks.data(), rect_blocks.size(), r.width,
                                              r.height, decoded_rect.data(), decoded_rect.size(),
                                              size_t{r.width} * 2));
        for (uint32_t y = 0; y < r.height; ++y) {
          for (uint32_t x = 0; x < r.width; ++x) {
            const uint8_t* p = &decoded_rect[(size_t{y} * r.width + x) * 2];
            (*decoded)[size_t{r.y + y} * t.width + r.x + x] =
                static_cast<uint16_t>(p[0] << 8 | p[1]);
          }
        }
      }
      blocks.insert(blocks.end(), rect_blocks.begin(), rect_blocks.end());
    }
    if (decoded != nullptr && ctx.view->range) {
      // BC5 error of this frame as the decoder reconstructs it.
      const double step = ctx.view->range->relative_step();
      const std::span<const uint16_t> truth = depth_frames[f];
      for (size_t i = 0; i < truth.size(); ++i) {
        const uint16_t a = truth[i], b = (*decoded)[i];
        if ((a == kLog16Sky) != (b == kLog16Sky)) {
          s.sky_mismatches += 1;
          continue;
        }
        if (a == kLog16Sky) continue;
        const double rel = std::abs(std::expm1((static_cast<double>(b) - a) * step));
        s.max_rel = std::max(s.max_rel, rel);
        s.sum_rel += rel;
        s.finite_texels += 1;
      }
    }
  }
  if (coverage) {
    std::vector<lf::CoverageRect> list;
    size_t at = 0;
    for (const auto& [w, h] : coverage_sizes) {
      list.push_back({w, h, std::span(coverage_texels).subspan(at, size_t{w} * h)});
      at += size_t{w} * h;
    }
    const size_t before = raw.size();
    lf::append_coverage_payload(raw, list);
    bytes.raw += static_cast<uint64_t>(count) * t.width * t.height * t.bytes_per_texel;
    bytes.temporal += raw.size() - before + header;
    return Status::Ok();
  }
  if (raw_texels) {
    // r16pm: every mask of the chunk before the planes (measured: a little smaller under zstd
    // than after them, or one byte per texel, or one bit string across rectangles).
    raw.insert(raw.end(), mask_bytes.begin(), mask_bytes.end());
    lf::append_planes(raw, texels, t.bytes_per_texel);
  } else {
    lf::append_block_split(raw, blocks, coding == RegionCoding::kBc5 ? 16 : 8,
                           coding == RegionCoding::kBc5);
  }
  bytes.raw += static_cast<uint64_t>(count) * t.width * t.height * t.bytes_per_texel;
  bytes.temporal += header + mask_bytes.size() + covered * t.bytes_per_texel;
  (void)bytes;
  return Status::Ok();
}

// The frames, from `first`, that one chunk of the tile serves: its group of `count` frames, and
// then every following whole group over which the tile does not change at all (each of its frames
// equals the frame before the group), up to a segment boundary. The chunk's P-frames there are
// empty but for the first W - 1, which re-send what changed in the W frames before the group. A
// seek anywhere in the span reads this one chunk, as it read one chunk before, and static content
// costs one keyframe instead of one every K frames.
uint32_t static_group_span(const Context& ctx, const TileFrames& t, uint32_t first,
                           uint32_t count) {
  const uint32_t k = ctx.options->depth_keyframe_interval;
  const uint32_t segment = ctx.options->segment_frames;
  const size_t frame_bytes = static_cast<size_t>(t.width) * t.height * t.bytes_per_texel;
  while (first + count < t.frames) {
    const uint32_t next = first + count;
    if (segment != 0 && (ctx.first_frame + next) % segment == 0) break;
    const uint32_t end = std::min(next + k, t.frames);
    const uint8_t* before = t.texel(next - 1, 0, 0);
    bool unchanged = true;
    for (uint32_t f = next; f < end && unchanged; ++f) {
      unchanged = std::memcmp(t.texel(f, 0, 0), before, frame_bytes) == 0;
    }
    if (!unchanged) break;
    count = end - first;
  }
  return count;
}

// The region streams a tile is coded in.
enum class TileStream : uint8_t { kDepth, kMaterial, kCoverage };

void region_task(const Context& ctx, uint32_t face, uint32_t tile, TileStream stream,
                 TaskOut& out) {
  const ViewData& v = *ctx.view;
  const bool is_depth = stream == TileStream::kDepth;
  const bool is_coverage = stream == TileStream::kCoverage;
  const PixelRect r =
      ctx.tiles.cell_rect(tile % ctx.tiles.cells_per_side(), tile / ctx.tiles.cells_per_side());
  TileFrames t;
  t.width = r.width;
  t.height = r.height;
  t.bytes_per_texel = is_depth ? 2 : 3;
  t.frames = v.frames;
  t.data.resize(static_cast<size_t>(v.frames) * r.width * r.height * t.bytes_per_texel);
  size_t o = 0;
  for (uint32_t f = 0; f < v.frames; ++f) {
    for (uint32_t y = 0; y < r.height; ++y) {
      for (uint32_t x = 0; x < r.width; ++x) {
        const size_t i = v.index(f, face, r.x + x, r.y + y);
        if (is_depth) {
          t.data[o++] = static_cast<uint8_t>(v.depth[i] >> 8);
          t.data[o++] = static_cast<uint8_t>(v.depth[i]);
        } else if (is_coverage) {
          t.data[o++] = static_cast<uint8_t>(v.coverage[i].mask >> 8);
          t.data[o++] = static_cast<uint8_t>(v.coverage[i].mask);
          t.data[o++] = v.coverage[i].near;
        } else {
          for (int c = 0; c < 3; ++c) t.data[o++] = v.material[i * 3 + c];
        }
      }
    }
  }
  const bool lossy = ctx.options->depth == DepthCoding::kBc5;
  const bool predicted = is_depth && ctx.options->depth == DepthCoding::kRaw16Predicted;
  const bool masked = is_depth && ctx.options->depth == DepthCoding::kRaw16PredictedMasked;
  const RegionCoding coding = is_coverage ? RegionCoding::kCoverage
                              : masked    ? RegionCoding::kRawPredictedMasked
                              : predicted ? RegionCoding::kRawPredicted
                              : !lossy    ? RegionCoding::kRaw
                              : is_depth  ? RegionCoding::kBc5
                                          : RegionCoding::kBc1;
  std::vector<uint16_t> decoded;
  if (is_depth && lossy) decoded.assign(static_cast<size_t>(r.width) * r.height, 0);
  StreamBytes& bytes = is_depth      ? out.stats.depth
                       : is_coverage ? out.stats.coverage
                                     : out.stats.material;
  std::vector<uint8_t> raw;
  const uint32_t k = ctx.options->depth_keyframe_interval;
  for (uint32_t first = 0, count = 0; first < v.frames; first += count) {
    count = std::min(k, v.frames - first);
    if (ctx.options->merge_static_groups) count = static_group_span(ctx, t, first, count);
    out.status = code_region_group(ctx, t, is_depth, coding, first, count, raw, out.stats, bytes,
                                   decoded.empty() ? nullptr : &decoded);
    if (!out.status.ok()) return;
    ChunkKeys keys;
    keys.stream = static_cast<uint16_t>(is_depth      ? LightfieldStream::kDepth
                                        : is_coverage ? LightfieldStream::kCoverage
                                                      : LightfieldStream::kMaterial);
    keys.face = face;
    keys.region = tile;
    keys.first_frame = ctx.first_frame + first;
    keys.frame_count = count;
    out.status = add_chunk(ctx, out, keys, raw, bytes);
    if (!out.status.ok()) return;
  }
}

void add_into(StreamBytes& a, const StreamBytes& b) {
  a.raw += b.raw;
  a.temporal += b.temporal;
  a.spatial += b.spatial;
  a.stored += b.stored;
  a.chunks += b.chunks;
}

// A task's figures in the track's terms, so that one merge (add_figures) serves tasks and views.
LightfieldEncodeStats figures_of(const TaskStats& task) {
  LightfieldEncodeStats f;
  f.colour = task.colour;
  f.depth = task.depth;
  f.material = task.material;
  f.coverage = task.coverage;
  f.colour_keyframes = task.keyframes;
  f.depth_keyframes = task.depth_keyframes;
  f.depth_pframes = task.pframes;
  f.depth_empty_pframes = task.empty_pframes;
  f.min_colour_quality_db = task.min_quality;
  f.depth_max_rel_error = task.max_rel;
  f.depth_sum_rel_error = task.sum_rel;
  f.depth_finite_texels = task.finite_texels;
  f.depth_sky_mismatches = task.sky_mismatches;
  return f;
}

// Adds the counts and bytes of `part` to `total` (formats and hdr are the track's, not summed).
void add_figures(LightfieldEncodeStats& total, const LightfieldEncodeStats& part) {
  add_into(total.colour, part.colour);
  add_into(total.depth, part.depth);
  add_into(total.material, part.material);
  add_into(total.coverage, part.coverage);
  total.index_bytes += part.index_bytes;
  total.colour_cells += part.colour_cells;
  total.colour_keyframes += part.colour_keyframes;
  total.depth_tiles += part.depth_tiles;
  total.depth_keyframes += part.depth_keyframes;
  total.depth_pframes += part.depth_pframes;
  total.depth_empty_pframes += part.depth_empty_pframes;
  total.material_views += part.material_views;
  total.min_colour_quality_db = std::min(total.min_colour_quality_db, part.min_colour_quality_db);
  total.depth_max_rel_error = std::max(total.depth_max_rel_error, part.depth_max_rel_error);
  total.depth_sum_rel_error += part.depth_sum_rel_error;
  total.depth_finite_texels += part.depth_finite_texels;
  total.depth_sky_mismatches += part.depth_sky_mismatches;
  total.depth_mean_rel_error =
      total.depth_finite_texels
          ? total.depth_sum_rel_error / static_cast<double>(total.depth_finite_texels)
          : 0;
}

}  // namespace

double psnr_log2(std::span<const float> reference, std::span<const float> test) {
  constexpr float kFloor = 1.0f / 16384.0f;  // 2^-14, the smallest normal half
  double sum = 0;
  for (size_t i = 0; i < reference.size(); ++i) {
    const double d =
        std::log2(std::max(reference[i], kFloor)) - std::log2(std::max(test[i], kFloor));
    sum += d * d;
  }
  if (sum == 0 || reference.empty()) return kInf;
  return 10.0 * std::log10(64.0 * static_cast<double>(reference.size()) / sum);
}

double colour_rdo_lambda(const LightfieldEncodeOptions& options, ColourCoding coding) {
  if (options.colour_rdo != kColourRdoAuto) return options.colour_rdo;
  return coding == ColourCoding::kBc1 ? 12.0 : 0.5;
}

Status spatial_colour_reference(ColourCoding coding, Bc1Fit bc1_fit, std::span<const float> rgb,
                                uint32_t w, uint32_t h, std::vector<float>* shown) {
  CodedFrame coded;
  CALF_RETURN_IF_ERROR(code_colour_frame(coding, bc1_fit, rgb, w, h, &coded));
  *shown = std::move(coded.shown);
  return Status::Ok();
}

Expected<LightfieldViewEncoding> encode_lightfield_view(const capture::CaptureSetReader& input,
                                                        const LightfieldAnalysis& analysis,
                                                        uint32_t v,
                                                        const LightfieldEncodeOptions& options) {
  return encode_lightfield_view_frames(input, analysis, v, 0, input.manifest().frame_count,
                                       options);
}

Expected<std::vector<uint8_t>> join_t_chunks(std::span<const std::vector<uint8_t>> parts,
                                             std::span<const uint32_t> frame_counts) {
  lf::CellTimeline all;
  uint32_t offset = 0;
  for (size_t i = 0; i < parts.size() && i < frame_counts.size(); ++i) {
    CALF_ASSIGN_OR_RETURN(const lf::CellTimeline part,
                          lf::parse_t_chunk(parts[i], frame_counts[i], "t chunk of a segment"));
    for (const uint32_t kf : part.keyframes) all.keyframes.push_back(offset + kf);
    all.t.insert(all.t.end(), part.t.begin(), part.t.end());
    offset += frame_counts[i];
  }
  std::vector<uint8_t> raw;
  CALF_RETURN_IF_ERROR(container::write_fields(all, raw, "t chunk"));
  return raw;
}

Expected<LightfieldViewEncoding> encode_lightfield_view_frames(
    const capture::CaptureSetReader& input, const LightfieldAnalysis& analysis, uint32_t v,
    uint32_t first_frame, uint32_t frame_count, const LightfieldEncodeOptions& options) {
  CALF_RETURN_IF_ERROR(lightfield_internal::validate_options(options));
  const capture::CaptureManifest& m = input.manifest();
  if (v >= m.viewpoints.size()) {
    return Status(ErrorId::kEncoderInput, "view " + std::to_string(v) + " of a capture set of " +
                                              std::to_string(m.viewpoints.size()) + " views");
  }
  const bool whole = first_frame == 0 && frame_count == m.frame_count;
  const uint32_t seg = options.segment_frames;
  if (!whole &&
      (seg == 0 || frame_count == 0 || first_frame % seg != 0 || first_frame > m.frame_count ||
       frame_count > m.frame_count - first_frame ||
       ((first_frame + frame_count) % seg != 0 && first_frame + frame_count != m.frame_count))) {
    return Status(ErrorId::kEncoderInput,
                  "frames " + std::to_string(first_frame) + "+" + std::to_string(frame_count) +
                      " of " + std::to_string(m.frame_count) +
                      " are not whole segments of --segment-frames " + std::to_string(seg));
  }
  // The analysis is a pure function of (manifest, facts, options): planning it again tells
  // whether it belongs to this capture set and these options.
  CALF_ASSIGN_OR_RETURN(const LightfieldAnalysis plan, plan_lightfield(m, analysis.views, options));
  CALF_ASSIGN_OR_RETURN(const std::vector<uint8_t> planned,
                        container::encode_track_header(plan.header));
  CALF_ASSIGN_OR_RETURN(const std::vector<uint8_t> given,
                        container::encode_track_header(analysis.header));
  if (planned != given || plan.colour != analysis.colour || plan.hdr != analysis.hdr ||
      plan.coverage != analysis.coverage) {
    return Status(ErrorId::kEncoderInput,
                  "the analysis was made for another capture set or other options");
  }
  CALF_ASSIGN_OR_RETURN(FaceGrid cells, FaceGrid::with_cell_size(m.face_size, options.cell_size));
  CALF_ASSIGN_OR_RETURN(FaceGrid tiles,
                        FaceGrid::with_tiles_per_side(m.face_size, options.depth_tiles_per_side));

  LightfieldViewEncoding out;
  out.view = v;
  LightfieldEncodeStats& stats = out.stats;
  stats.colour_format = analysis.header.colour_format;
  stats.depth_format = analysis.header.depth_format;
  stats.material_format = analysis.header.material_format;
  stats.hdr = analysis.hdr;
  stats.min_colour_quality_db = kInf;
  ViewData view;
  CALF_RETURN_IF_ERROR(
      read_view(input, v, analysis.views[v], analysis.coverage, first_frame, frame_count, &view));
  if (view.has_material) stats.material_views += 1;

  // The view's index chunk (SPEC §11.1 "View index chunk").
  lf::ViewIndex vi;
  vi.position = m.viewpoints[v].position;
  vi.z_near = view.range ? view.range->z_near() : 1.0f;
  vi.z_far = view.range ? view.range->z_far() : 2.0f;
  vi.has_depth = view.range.has_value();
  vi.has_material = view.has_material;
  vi.depth_keyframe_interval = options.depth_keyframe_interval;
  vi.depth_window = options.depth_window;
  vi.min_psnr_db = static_cast<float>(options.min_psnr_db);
  CALF_ASSIGN_OR_RETURN(const std::vector<uint8_t> index, lf::serialize_view_index(vi));
  ChunkKeys ikeys;
  ikeys.stream = static_cast<uint16_t>(LightfieldStream::kIndex);
  ikeys.view = v;
  CALF_ASSIGN_OR_RETURN(StoredChunk ic,
                        container::compress_chunk(index, Compression::kNone, options.levels));
  if (first_frame == 0) {  // one index chunk per view, with the range that starts the clip
    stats.index_bytes += ic.bytes.size();
    out.chunks.push_back({ikeys, std::move(ic)});
  }

  tbb::task_arena arena(options.threads == 0 ? tbb::task_arena::automatic
                                             : static_cast<int>(options.threads));
  const uint64_t total = uint64_t{6} * m.viewpoints.size();
  const Context ctx{&options,
                    &view,
                    v,
                    analysis.colour,
                    analysis.hdr,
                    cells,
                    tiles,
                    first_frame,
                    !whole,
                    analysis.header.fps_numerator,
                    analysis.header.fps_denominator};
  for (uint32_t face = 0; face < 6; ++face) {
    // Tasks of one face in file order: cells, depth tiles, material tiles, coverage tiles.
    const uint32_t nc = cells.cell_count(), nt = tiles.cell_count();
    const uint32_t nm = view.has_material ? nt : 0;
    const uint32_t nv = analysis.coverage ? nt : 0;
    std::vector<TaskOut> outs(nc + nt + nm + nv);
    arena.execute([&] {
      tbb::parallel_for(tbb::blocked_range<uint32_t>(0, nc + nt + nm + nv, 1),
                        [&](const tbb::blocked_range<uint32_t>& range) {
                          for (uint32_t i = range.begin(); i < range.end(); ++i) {
                            if (i < nc) {
                              colour_task(ctx, face, i, outs[i]);
                            } else if (i < nc + nt) {
                              region_task(ctx, face, i - nc, TileStream::kDepth, outs[i]);
                            } else if (i < nc + nt + nm) {
                              region_task(ctx, face, i - nc - nt, TileStream::kMaterial, outs[i]);
                            } else {
                              region_task(ctx, face, i - nc - nt - nm, TileStream::kCoverage,
                                          outs[i]);
                            }
                          }
                        });
    });
    for (TaskOut& o : outs) {
      CALF_RETURN_IF_ERROR(o.status);
      for (Pending& p : o.chunks) out.chunks.push_back({p.keys, std::move(p.chunk)});
      add_figures(stats, figures_of(o.stats));
    }
    stats.colour_cells += nc;
    stats.depth_tiles += nt;
    if (options.progress) options.progress(uint64_t{6} * v + face + 1, total);
  }
  return out;
}

Expected<LightfieldTrackWriter> LightfieldTrackWriter::begin(container::Writer& writer,
                                                             const LightfieldAnalysis& analysis) {
  CALF_ASSIGN_OR_RETURN(uint16_t track, writer.add_track(analysis.header));
  // A coverage stream is a 1.2 feature (SPEC §11.1.11): the file says so in its minor version.
  if (analysis.coverage) writer.require_minor_version(container::kVersionMinorCoverage);
  // So is AV1 colour (1.3, SPEC §11.1.12), which earlier decoders refuse as an unknown format.
  if (analysis.colour == ColourCoding::kAv1) {
    writer.require_minor_version(analysis.hdr ? container::kVersionMinorAv1Hdr
                                              : container::kVersionMinorAv1);
  }
  LightfieldEncodeStats stats;
  stats.colour_format = analysis.header.colour_format;
  stats.depth_format = analysis.header.depth_format;
  stats.material_format = analysis.header.material_format;
  stats.hdr = analysis.hdr;
  stats.min_colour_quality_db = kInf;
  return LightfieldTrackWriter(writer, track, analysis.header.view_count, stats);
}

Status LightfieldTrackWriter::append(const LightfieldViewEncoding& view) {
  if (view.view != next_view_ || next_view_ >= view_count_) {
    return Status(ErrorId::kEncoderInput, "view " + std::to_string(view.view) +
                                              " appended where view " + std::to_string(next_view_) +
                                              " of " + std::to_string(view_count_) + " comes next");
  }
  for (const LightfieldChunk& c : view.chunks) {
    ChunkKeys keys = c.keys;
    keys.track = track_;
    CALF_RETURN_IF_ERROR(writer_->add_stored_chunk(keys, c.chunk).status());
  }
  next_view_ += 1;
  add_figures(stats_, view.stats);
  return Status::Ok();
}

Expected<LightfieldEncodeStats> LightfieldTrackWriter::finish() const {
  if (next_view_ != view_count_) {
    return Status(ErrorId::kEncoderInput, "the track has " + std::to_string(next_view_) +
                                              " of its " + std::to_string(view_count_) + " views");
  }
  return stats_;
}

Expected<LightfieldEncodeStats> encode_lightfield(const capture::CaptureSetReader& input,
                                                  container::Writer& writer,
                                                  const LightfieldEncodeOptions& options) {
  CALF_ASSIGN_OR_RETURN(const LightfieldAnalysis analysis, analyse_lightfield(input, options));
  CALF_ASSIGN_OR_RETURN(LightfieldTrackWriter track,
                        LightfieldTrackWriter::begin(writer, analysis));
  for (uint32_t v = 0; v < analysis.header.view_count; ++v) {
    CALF_ASSIGN_OR_RETURN(const LightfieldViewEncoding view,
                          encode_lightfield_view(input, analysis, v, options));
    CALF_RETURN_IF_ERROR(track.append(view));
  }
  return track.finish();
}

Expected<LightfieldEncodeStats> encode_lightfield_file(const std::filesystem::path& capture_dir,
                                                       const std::string& out_path,
                                                       const LightfieldEncodeOptions& options) {
  CALF_RETURN_IF_ERROR(lightfield_internal::validate_options(options));
  CALF_ASSIGN_OR_RETURN(capture::CaptureSetReader input,
                        capture::CaptureSetReader::open(capture_dir, options.max_image_pixels));
  // The output must not be one of the inputs: renaming over the manifest or an image would
  // destroy the set the clip is made from (CALF-E007; the directory itself is E004's).
  std::vector<std::string> inputs = {capture_dir.string(),
                                     (capture_dir / capture::kManifestFileName).string()};
  for (uint32_t v = 0; v < input.manifest().viewpoints.size(); ++v) {
    for (uint32_t f = 0; f < input.manifest().frame_count; ++f)
      inputs.push_back(input.image_path(v, f).string());
  }
  CALF_RETURN_IF_ERROR(files::check_output_not_input(out_path, inputs));
  CALF_ASSIGN_OR_RETURN(container::Writer writer,
                        container::Writer::create(out_path, options.levels));
  CALF_ASSIGN_OR_RETURN(LightfieldEncodeStats stats, encode_lightfield(input, writer, options));
  CALF_RETURN_IF_ERROR(
      writer.set_metadata("encoder", std::string("calf-encode ") + kVersionString));
  if (!input.manifest().scene.empty()) {
    CALF_RETURN_IF_ERROR(writer.set_metadata("source_scene", input.manifest().scene));
  }
  // The box the eye may move in (format/CAPTURE.md view_volume): the player warns outside it.
  CALF_RETURN_IF_ERROR(
      writer.set_metadata(std::string(container::kViewVolumeKey),
                          container::format_view_volume(input.manifest().view_volume)));
  CALF_RETURN_IF_ERROR(writer.finish());
  return stats;
}

}  // namespace calf
