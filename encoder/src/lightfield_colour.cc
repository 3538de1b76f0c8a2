#include <algorithm>
#include <cmath>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "calf/encoder/bc_encode.h"
#include "calf/encoder/bc_rdo.h"
#include "calf/encoder/colour_keyframes.h"
#include "calf/format/bc.h"
#include "calf/format/colour.h"
#include "calf/format/lightfield_layout.h"
#include "colour_av1.h"
#include "lightfield_view_pass.h"

namespace calf::encoder {
namespace lightfield_internal {
namespace {

using container::ChunkKeys;
using container::LightfieldStream;

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

}  // namespace

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
  // The noise-aware test: each segment's blocks' own noise, at most kNoiseBlockCap times the
  // capture's.
  const bool noise_aware = ctx.options->noise_psnr_db > 0 && ctx.options->noise_factor > 0;
  CellNoise noise;
  if (noise_aware) ko.noise = &noise;
  CellKeyframes all;
  all.min_quality_db = kInf;
  for (uint32_t s0 = 0; s0 < frames; s0 += segment) {
    const uint32_t len = std::min(segment, frames - s0);
    const ShownKeyframeFn shown_in = [&](uint32_t f) { return shown(s0 + f); };
    const std::span<const float> cell_frames =
        std::span<const float>(shown_all).subspan(s0 * n * 3, size_t{len} * n * 3);
    if (noise_aware) {
      noise = measure_cell_noise(
          cell_frames, len, r.width, r.height, ctx.hdr, ctx.options->noise_factor,
          kNoiseBlockCap * std::pow(10.0, -ctx.options->noise_psnr_db / 10.0));
    }
    auto part =
        select_cell_keyframes(cell_frames, len, static_cast<uint32_t>(n), shown_in, quality, ko);
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

}  // namespace lightfield_internal

using lightfield_internal::code_colour_frame;
using lightfield_internal::CodedFrame;
using lightfield_internal::kInf;

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
  if (coding == ColourCoding::kBc6h && options.noise_psnr_db > 0 && options.denoise_window > 1)
    return kDenoisedBc6hRdo;
  return coding == ColourCoding::kBc1 ? 12.0 : 0.5;
}

Status spatial_colour_reference(ColourCoding coding, Bc1Fit bc1_fit, std::span<const float> rgb,
                                uint32_t w, uint32_t h, std::vector<float>* shown) {
  CodedFrame coded;
  CALF_RETURN_IF_ERROR(code_colour_frame(coding, bc1_fit, rgb, w, h, &coded));
  *shown = std::move(coded.shown);
  return Status::Ok();
}

}  // namespace calf::encoder
