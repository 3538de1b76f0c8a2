#include "calf/format/lightfield_layout.h"

#include <algorithm>
#include <bit>
#include <cstdio>

#include "calf/format/av1_hdr_colour.h"
#include "calf/format/bc.h"
#include "calf/format/depth_predict.h"

namespace calf::lf {
namespace {

using container::PixelFormat;

Status corrupt(const std::string& what) {
  return Status(ErrorId::kLightfieldChunk, what);
}

uint64_t blocks_of(uint32_t w, uint32_t h) {
  return uint64_t{bc::blocks_along(w)} * bc::blocks_along(h);
}

bool is(uint16_t format, PixelFormat f) {
  return format == static_cast<uint16_t>(f);
}

}  // namespace

void append_block_split(std::vector<uint8_t>& out, std::span<const uint8_t> blocks,
                        size_t block_bytes, bool is_bc5) {
  if (block_bytes == 8) {
    const size_t n = blocks.size() / 8;
    for (size_t b = 0; b < n; ++b) out.insert(out.end(), &blocks[b * 8], &blocks[b * 8] + 4);
    for (size_t b = 0; b < n; ++b) out.insert(out.end(), &blocks[b * 8 + 4], &blocks[b * 8] + 8);
  } else if (is_bc5) {
    const size_t n = blocks.size() / 16;
    for (size_t b = 0; b < n; ++b) {
      const uint8_t* p = &blocks[b * 16];
      out.insert(out.end(), {p[0], p[1], p[8], p[9]});
    }
    for (size_t b = 0; b < n; ++b) {
      const uint8_t* p = &blocks[b * 16];
      out.insert(out.end(), p + 2, p + 8);
      out.insert(out.end(), p + 10, p + 16);
    }
  } else {
    out.insert(out.end(), blocks.begin(), blocks.end());
  }
}

void append_planes(std::vector<uint8_t>& out, std::span<const uint8_t> texels,
                   size_t bytes_per_texel) {
  const size_t n = texels.size() / bytes_per_texel;
  for (size_t c = 0; c < bytes_per_texel; ++c) {
    for (size_t i = 0; i < n; ++i) out.push_back(texels[i * bytes_per_texel + c]);
  }
}

uint8_t material_weight_code(float weight) {
  // NaN compares false with everything: clamp it to 0 explicitly.
  const float w = weight >= 0.0f ? std::min(weight, 1.0f) : 0.0f;
  return static_cast<uint8_t>(std::lround(w * 255.0f));
}

uint8_t material_ior_code(float ior) {
  return material_weight_code((ior - 1.0f) / 2.0f);
}

// ---- View index ----

namespace {

// Every layout field reads as one error id: a chunk's contradiction is "corrupt chunk", whether a
// count runs past its end, falls below its minimum or exceeds its limit.
container::FieldReader chunk_reader(std::span<const uint8_t> raw, const std::string& what) {
  return container::FieldReader(raw, ErrorId::kLightfieldChunk, ErrorId::kLightfieldChunk, what,
                                ErrorId::kLightfieldChunk);
}

// The rule the field rules cannot state: a depth range 0 < z_near < z_far.
bool depth_range_ok(float z_near, float z_far) {
  return z_near > 0.0f && z_far > z_near;
}

std::string depth_range_text(float z_near, float z_far) {
  return "depth range [" + container::float_text(z_near) + ", " + container::float_text(z_far) +
         "] is not 0 < z_near < z_far < inf";
}

}  // namespace

Expected<std::vector<uint8_t>> serialize_view_index(const ViewIndex& index) {
  ViewIndexRecord r;
  r.position[0] = index.position.x;
  r.position[1] = index.position.y;
  r.position[2] = index.position.z;
  r.z_near = index.z_near;
  r.z_far = index.z_far;
  r.flags = (index.has_depth ? 1u : 0u) | (index.has_material ? 2u : 0u);
  r.depth_keyframe_interval = index.depth_keyframe_interval;
  r.depth_window = index.depth_window;
  r.min_psnr_db = index.min_psnr_db;
  std::vector<uint8_t> out;
  out.reserve(kViewIndexBytes);
  CALF_RETURN_IF_ERROR(container::write_fields(r, out, "view index"));
  if (!depth_range_ok(r.z_near, r.z_far))
    return Status(ErrorId::kContainerWriterMisuse,
                  "view index: " + depth_range_text(r.z_near, r.z_far));
  return out;
}

Expected<ViewIndex> parse_view_index(std::span<const uint8_t> raw, const std::string& what) {
  if (raw.size() != kViewIndexBytes) {
    return corrupt(what + ": " + std::to_string(raw.size()) + " bytes, expected " +
                   std::to_string(kViewIndexBytes));
  }
  ViewIndexRecord r;
  container::FieldReader reader = chunk_reader(raw, what);
  CALF_RETURN_IF_ERROR(container::read_fields(r, reader));
  if (!depth_range_ok(r.z_near, r.z_far))
    return corrupt(what + ": " + depth_range_text(r.z_near, r.z_far));
  ViewIndex v;
  v.position = {r.position[0], r.position[1], r.position[2]};
  v.z_near = r.z_near;
  v.z_far = r.z_far;
  v.has_depth = (r.flags & 1) != 0;
  v.has_material = (r.flags & 2) != 0;
  v.depth_keyframe_interval = r.depth_keyframe_interval;
  v.depth_window = r.depth_window;
  v.min_psnr_db = r.min_psnr_db;
  return v;
}

// ---- t chunk ----

uint32_t CellTimeline::bracket(uint32_t frame) const {
  // keyframes[0] == 0 <= frame, so the result is at least 0.
  const auto it = std::upper_bound(keyframes.begin(), keyframes.end(), frame);
  return static_cast<uint32_t>(it - keyframes.begin()) - 1;
}

Expected<CellTimeline> parse_t_chunk(std::span<const uint8_t> raw, uint32_t frame_count,
                                     const std::string& what) {
  CellTimeline tl;
  Status st = Status::Ok();
  container::FieldReader reader = chunk_reader(raw, what);
  // The number of t values is the chunk key's frame count; sized only once the chunk can hold
  // them, so a hostile key allocates nothing.
  if (raw.size() >= uint64_t{frame_count} + 4) {
    tl.t.resize(frame_count);
    st = container::read_fields(tl, reader);
  }
  const uint64_t k = tl.keyframes.size();
  if (raw.size() < uint64_t{frame_count} + 4 || !st.ok() || k > frame_count ||
      reader.remaining() != 0) {
    return corrupt(what + ": " + std::to_string(k) + " keyframes in " + std::to_string(raw.size()) +
                   " bytes for " + std::to_string(frame_count) + " frames" +
                   (st.ok() ? "" : " (" + st.message() + ")"));
  }
  for (uint32_t i = 0; i < k; ++i) {
    if ((i == 0 && tl.keyframes[i] != 0) || (i > 0 && tl.keyframes[i] <= tl.keyframes[i - 1]) ||
        tl.keyframes[i] >= frame_count) {
      return corrupt(what + ": keyframes not increasing from 0 below the frame count");
    }
  }
  return tl;
}

// ---- Region chunks ----

Expected<RegionCoding> depth_coding(uint16_t depth_format) {
  if (is(depth_format, PixelFormat::kR16)) return RegionCoding::kR16;
  if (is(depth_format, PixelFormat::kR16Predicted)) return RegionCoding::kR16Predicted;
  if (is(depth_format, PixelFormat::kR16PredictedMasked)) return RegionCoding::kR16PredictedMasked;
  if (is(depth_format, PixelFormat::kBc5)) return RegionCoding::kBc5;
  return Status(ErrorId::kLightfieldFormat, "depth format " + std::to_string(depth_format) + " (" +
                                                container::pixel_format_name(depth_format) + ")");
}

Expected<RegionCoding> material_coding(uint16_t material_format) {
  if (is(material_format, PixelFormat::kRgba8)) return RegionCoding::kRgb8;
  if (is(material_format, PixelFormat::kBc1)) return RegionCoding::kBc1;
  return Status(ErrorId::kLightfieldFormat,
                "material format " + std::to_string(material_format) + " (" +
                    container::pixel_format_name(material_format) + ")");
}

bool region_coding_is_block(RegionCoding coding) {
  return coding == RegionCoding::kBc5 || coding == RegionCoding::kBc1;
}

container::PixelFormat region_gpu_format(RegionCoding coding) {
  switch (coding) {
    case RegionCoding::kR16:
    case RegionCoding::kR16Predicted:
    case RegionCoding::kR16PredictedMasked:
      return PixelFormat::kR16;
    case RegionCoding::kBc5:
      return PixelFormat::kBc5;
    case RegionCoding::kRgb8:
    case RegionCoding::kCoverage:
      return PixelFormat::kRgba8;
    case RegionCoding::kBc1:
      return PixelFormat::kBc1;
  }
  return PixelFormat::kNone;
}

// region_rect_gpu_bytes() stores 16-bit codes as the host writes them.
static_assert(std::endian::native == std::endian::little, "GPU bytes are little-endian");

namespace {
size_t unit_bytes(RegionCoding coding) {
  switch (coding) {
    case RegionCoding::kR16:
    case RegionCoding::kR16Predicted:
    case RegionCoding::kR16PredictedMasked:
      return 2;
    case RegionCoding::kBc5:
      return 16;
    case RegionCoding::kRgb8:
    case RegionCoding::kCoverage:
      return 3;
    case RegionCoding::kBc1:
      return 8;
  }
  return 0;
}
}  // namespace

namespace {

std::string hex16(uint16_t v) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "%04x", v);
  return buf;
}

Status coverage_corrupt(const std::string& what) {
  return Status(ErrorId::kCoverageChunk, what);
}

// The per-rectangle bitmaps that lead a payload (§11.1.9's change masks from rectangle `first`,
// §11.1.11's edge bitmaps of every rectangle): lays out their offsets, checks that they fit,
// counts their set bits into chunk.units after `units`, and refuses bits past a rectangle's
// texels with `past_end`.
Status read_rect_bitmaps(RegionChunk& chunk, size_t first, uint64_t units, const char* name,
                         ErrorId past_end, const std::string& what) {
  for (size_t k = first; k < chunk.rects.size(); ++k) {
    chunk.rects[k].mask_offset = chunk.mask_bytes;
    chunk.mask_bytes += mask_bytes_of(chunk.rects[k].w, chunk.rects[k].h);
  }
  if (chunk.payload.size() < chunk.mask_bytes) {
    return corrupt(what + ": payload of " + std::to_string(chunk.payload.size()) +
                   " bytes, shorter than its " + std::to_string(chunk.mask_bytes) + " bytes of " +
                   name + "s");
  }
  chunk.units = units;
  for (size_t k = first; k < chunk.rects.size(); ++k) {
    RegionRect& r = chunk.rects[k];
    r.first_unit = chunk.units;
    const uint8_t* m = &chunk.payload[r.mask_offset];
    const uint64_t bits = uint64_t{r.w} * r.h, bytes = mask_bytes_of(r.w, r.h);
    for (uint64_t b = 0; b < bytes; ++b) chunk.units += std::popcount(m[b]);
    if (bits % 8 != 0 && (m[bytes - 1] >> (bits % 8)) != 0) {
      return Status(past_end, what + ": " + name + " of rectangle " + std::to_string(k) +
                                  " has bits set past its " + std::to_string(bits) + " texels");
    }
  }
  return Status::Ok();
}

// §11.1.11: the bitmaps of every rectangle before the planes; counts the edge texels and checks
// each one (near <= 16, near + popcount(mask) <= 16, not the plain texel).
Status parse_coverage(RegionChunk& chunk, const std::string& what) {
  CALF_RETURN_IF_ERROR(
      read_rect_bitmaps(chunk, 0, 0, "edge bitmap", ErrorId::kCoverageChunk, what));
  const uint64_t e = chunk.units;
  if (chunk.payload.size() != chunk.mask_bytes + 3 * e) return Status::Ok();  // size: caller
  const uint8_t* hi = chunk.payload.data() + chunk.mask_bytes;
  for (uint64_t i = 0; i < e; ++i) {
    const CoverageTexel t{static_cast<uint16_t>(hi[i] << 8 | hi[e + i]), hi[2 * e + i]};
    if (!t.valid() || t.plain()) {
      return coverage_corrupt(
          what + ": edge texel " + std::to_string(i) + " has mask 0x" + hex16(t.mask) +
          " and near count " + std::to_string(t.near) +
          (t.plain() ? " (a plain texel, not an edge)" : " (more than 16 cells)"));
    }
  }
  return Status::Ok();
}

}  // namespace

bool CoverageTexel::valid() const {
  return near <= 16 && near + std::popcount(mask) <= 16;
}

uint8_t CoverageTexel::far() const {
  return static_cast<uint8_t>(16 - near - std::popcount(mask));
}

void coverage_to_gpu(const CoverageTexel& t, uint8_t* p) {
  p[0] = static_cast<uint8_t>(t.mask);
  p[1] = static_cast<uint8_t>(t.mask >> 8);
  p[2] = t.near;
  p[3] = t.valid() ? t.far() : 0;
}

void append_coverage_payload(std::vector<uint8_t>& out, std::span<const CoverageRect> rects) {
  std::vector<uint8_t> planes[3];
  for (const CoverageRect& r : rects) {
    const size_t n = size_t{r.width} * r.height, at = out.size();
    out.resize(at + mask_bytes_of(r.width, r.height), 0);
    for (size_t i = 0; i < n; ++i) {
      const CoverageTexel& t = r.texels[i];
      if (t.plain()) continue;
      out[at + i / 8] |= static_cast<uint8_t>(1u << (i % 8));
      planes[0].push_back(static_cast<uint8_t>(t.mask >> 8));
      planes[1].push_back(static_cast<uint8_t>(t.mask));
      planes[2].push_back(t.near);
    }
  }
  for (const auto& plane : planes) out.insert(out.end(), plane.begin(), plane.end());
}

Expected<RegionChunk> parse_region_chunk(std::span<const uint8_t> raw, uint32_t frame_count,
                                         uint32_t tile_width, uint32_t tile_height,
                                         RegionCoding coding, const std::string& what) {
  RegionHead head;
  container::FieldReader reader = chunk_reader(raw, what);
  CALF_RETURN_IF_ERROR(container::read_fields(head, reader));
  RegionChunk chunk;
  chunk.coding = coding;
  chunk.tile_width = tile_width;
  chunk.tile_height = tile_height;
  chunk.frame_count = static_cast<uint32_t>(head.rect_counts.size());
  if (chunk.frame_count != frame_count || frame_count == 0) {
    return corrupt(what + ": frame count " + std::to_string(chunk.frame_count) +
                   ", the chunk's key says " + std::to_string(frame_count));
  }
  chunk.first_rect.resize(size_t{frame_count} + 1);
  uint64_t total = 0;
  for (uint32_t f = 0; f < frame_count; ++f) {
    chunk.first_rect[f] = static_cast<uint32_t>(total);
    total += head.rect_counts[f];
  }
  // The rectangles were read, so total * 8 bytes exist: total fits a u32 for any real chunk.
  chunk.first_rect[frame_count] = static_cast<uint32_t>(total);
  chunk.rects = std::move(head.rects);
  const bool block = region_coding_is_block(coding);
  for (RegionRect& r : chunk.rects) {
    if (r.w == 0 || r.h == 0 || uint32_t{r.x} + r.w > tile_width ||
        uint32_t{r.y} + r.h > tile_height) {
      return corrupt(what + ": rectangle (" + std::to_string(r.x) + ", " + std::to_string(r.y) +
                     ", " + std::to_string(r.w) + ", " + std::to_string(r.h) + ") leaves the " +
                     std::to_string(tile_width) + "x" + std::to_string(tile_height) + " tile");
    }
    if (block && (r.x % 4 != 0 || r.y % 4 != 0)) {
      return corrupt(what + ": block-coded rectangle at (" + std::to_string(r.x) + ", " +
                     std::to_string(r.y) + ") is not 4-aligned");
    }
    r.first_unit = chunk.units;
    chunk.units += block ? blocks_of(r.w, r.h) : uint64_t{r.w} * r.h;
  }
  const RegionRect* first = chunk.rects.empty() ? nullptr : &chunk.rects[0];
  if (chunk.first_rect[1] != 1 || first->x != 0 || first->y != 0 || first->w != tile_width ||
      first->h != tile_height) {
    return corrupt(what + ": the first frame is not one whole-tile rectangle");
  }
  chunk.payload = reader.rest();
  if (coding == RegionCoding::kR16PredictedMasked) {
    // §11.1.9: the masks of every P-frame rectangle, then the two planes of the keyframe's texels
    // and every set mask bit's texel.
    CALF_RETURN_IF_ERROR(read_rect_bitmaps(chunk, 1, uint64_t{tile_width} * tile_height,
                                           "change mask", ErrorId::kLightfieldChunk, what));
  }
  if (coding == RegionCoding::kCoverage) CALF_RETURN_IF_ERROR(parse_coverage(chunk, what));
  const uint64_t expected = chunk.mask_bytes + chunk.units * unit_bytes(coding);
  if (chunk.payload.size() != expected) {
    return corrupt(what + ": payload of " + std::to_string(chunk.payload.size()) +
                   " bytes, expected " + std::to_string(expected));
  }
  return chunk;
}

void region_rect_gpu_bytes(const RegionChunk& chunk, size_t index, std::vector<uint8_t>& out) {
  const RegionRect& r = chunk.rects[index];
  const std::span<const uint8_t> p = chunk.payload;
  const uint64_t units = chunk.units;
  switch (chunk.coding) {
    case RegionCoding::kR16: {
      const size_t n = size_t{r.w} * r.h;
      out.resize(n * 2);
      // Planes hold the high byte, then the low byte; GPU bytes are little-endian. Through local
      // pointers and 16-bit stores (a little-endian host: asserted above), so that the compiler can
      // vectorise the interleave (byte stores through the vector could alias the payload, which
      // kept it a byte loop: a quarter of a moving eye's decode time on raw16 depth).
      const uint8_t* hi = p.data() + r.first_unit;
      const uint8_t* lo = p.data() + units + r.first_unit;
      uint8_t* dst = out.data();
      for (size_t i = 0; i < n; ++i) {
        const uint16_t code = static_cast<uint16_t>(hi[i] << 8 | lo[i]);
        std::memcpy(dst + 2 * i, &code, 2);
      }
      return;
    }
    case RegionCoding::kR16Predicted:
      out.resize(size_t{r.w} * r.h * 2);
      reconstruct_depth_rect(&p[r.first_unit], &p[units + r.first_unit], r.w, r.h, out.data());
      return;
    case RegionCoding::kR16PredictedMasked: {
      // Pointer arithmetic, not p[...]: a last rectangle with an empty mask starts at the end.
      const uint8_t* hi = p.data() + chunk.mask_bytes + r.first_unit;
      const uint8_t* lo = p.data() + chunk.mask_bytes + units + r.first_unit;
      out.resize(size_t{r.w} * r.h * 2);  // a no-op for a P-frame rectangle, which reads `out`
      if (r.mask_offset == RegionRect::kNoMask) {
        reconstruct_depth_rect(hi, lo, r.w, r.h, out.data());
      } else {
        reconstruct_depth_rect_masked(p.data() + r.mask_offset, hi, lo, r.w, r.h, out.data());
      }
      return;
    }
    case RegionCoding::kRgb8: {
      const size_t n = size_t{r.w} * r.h;
      out.resize(n * 4);
      for (size_t i = 0; i < n; ++i) {
        for (size_t c = 0; c < 3; ++c) out[4 * i + c] = p[c * units + r.first_unit + i];
        out[4 * i + 3] = 255;
      }
      return;
    }
    case RegionCoding::kBc5: {
      const size_t n = blocks_of(r.w, r.h);
      out.resize(n * 16);
      for (size_t b = 0; b < n; ++b) {
        const uint8_t* e = &p[(r.first_unit + b) * 4];
        const uint8_t* ix = &p[units * 4 + (r.first_unit + b) * 12];
        uint8_t* d = &out[b * 16];
        d[0] = e[0];
        d[1] = e[1];
        std::memcpy(d + 2, ix, 6);
        d[8] = e[2];
        d[9] = e[3];
        std::memcpy(d + 10, ix + 6, 6);
      }
      return;
    }
    case RegionCoding::kCoverage: {
      // §11.1.11: a texel whose bitmap bit is clear is plain; the others take the next texel of
      // the three planes (mask high byte, mask low byte, near count).
      const size_t n = size_t{r.w} * r.h;
      out.resize(n * kCoverageGpuBytes);
      const uint8_t* bits = p.data() + r.mask_offset;
      const uint8_t* hi = p.data() + chunk.mask_bytes + r.first_unit;
      const uint8_t* lo = hi + units;
      const uint8_t* nr = lo + units;
      size_t e = 0;
      for (size_t i = 0; i < n; ++i) {
        CoverageTexel t;
        if ((bits[i / 8] >> (i % 8)) & 1) {
          t.mask = static_cast<uint16_t>(hi[e] << 8 | lo[e]);
          t.near = nr[e];
          ++e;
        }
        coverage_to_gpu(t, &out[i * kCoverageGpuBytes]);
      }
      return;
    }
    case RegionCoding::kBc1: {
      const size_t n = blocks_of(r.w, r.h);
      out.resize(n * 8);
      for (size_t b = 0; b < n; ++b) {
        std::memcpy(&out[b * 8], &p[(r.first_unit + b) * 4], 4);
        std::memcpy(&out[b * 8 + 4], &p[units * 4 + (r.first_unit + b) * 4], 4);
      }
      return;
    }
  }
}

// ---- Colour keyframes ----

Status check_colour_format(uint16_t colour_format) {
  for (PixelFormat f :
       {PixelFormat::kBc1, PixelFormat::kBc7, PixelFormat::kBc6h, PixelFormat::kRgba8,
        PixelFormat::kRgba16f, PixelFormat::kAv1, PixelFormat::kAv1Hdr, PixelFormat::kAv1Chroma444,
        PixelFormat::kAv1HdrChroma444}) {
    if (is(colour_format, f)) return Status::Ok();
  }
  return Status(ErrorId::kLightfieldFormat, "colour format " + std::to_string(colour_format) +
                                                " (" + container::pixel_format_name(colour_format) +
                                                ")");
}

Status colour_payload_gpu_bytes(uint16_t colour_format, std::span<const uint8_t> payload,
                                uint32_t width, uint32_t height, std::vector<uint8_t>& out,
                                const std::string& what) {
  const size_t n = size_t{width} * height;
  const size_t nb = blocks_of(width, height);
  auto check = [&](size_t expected) -> Status {
    if (payload.size() == expected) return Status::Ok();
    return corrupt(what + ": colour payload of " + std::to_string(payload.size()) +
                   " bytes, expected " + std::to_string(expected));
  };
  if (is(colour_format, PixelFormat::kBc1)) {
    CALF_RETURN_IF_ERROR(check(nb * 8));
    out.resize(nb * 8);
    for (size_t b = 0; b < nb; ++b) {
      std::memcpy(&out[b * 8], &payload[b * 4], 4);
      std::memcpy(&out[b * 8 + 4], &payload[nb * 4 + b * 4], 4);
    }
    return Status::Ok();
  }
  if (is(colour_format, PixelFormat::kBc7) || is(colour_format, PixelFormat::kBc6h)) {
    CALF_RETURN_IF_ERROR(check(nb * 16));
    out.assign(payload.begin(), payload.end());
    return Status::Ok();
  }
  if (is(colour_format, PixelFormat::kRgba8)) {
    CALF_RETURN_IF_ERROR(check(n * 4));
    out.resize(n * 4);
    for (size_t i = 0; i < n; ++i) {
      for (size_t c = 0; c < 4; ++c) out[4 * i + c] = payload[c * n + i];
    }
    return Status::Ok();
  }
  if (is(colour_format, PixelFormat::kRgba16f)) {
    CALF_RETURN_IF_ERROR(check(n * 8));
    const size_t values = n * 4;
    out.resize(n * 8);
    for (size_t k = 0; k < values; ++k) {
      out[2 * k] = payload[values + k];  // low byte plane
      out[2 * k + 1] = payload[k];       // high byte plane
    }
    return Status::Ok();
  }
  // AV1 colour has no keyframe payloads: its chunks are GOPs (parse_av1_gop).
  return Status(ErrorId::kLightfieldFormat,
                what + ": colour format " + std::to_string(colour_format) + " (" +
                    container::pixel_format_name(colour_format) + ") has no keyframe payload");
}

container::PixelFormat colour_gpu_format(uint16_t colour_format) {
  if (is(colour_format, PixelFormat::kAv1) || is(colour_format, PixelFormat::kAv1Chroma444)) {
    return PixelFormat::kRgba8;
  }
  if (is(colour_format, PixelFormat::kAv1Hdr) || is(colour_format, PixelFormat::kAv1HdrChroma444)) {
    return PixelFormat::kRgba16f;
  }
  return static_cast<PixelFormat>(colour_format);
}

Expected<Av1Gop> parse_av1_gop(std::span<const uint8_t> raw, uint32_t frame_count,
                               const std::string& what) {
  auto bad = [&](const std::string& why) { return Status(ErrorId::kAv1Chunk, what + ": " + why); };
  if (raw.size() < 4) return bad("AV1 chunk of " + std::to_string(raw.size()) + " bytes");
  uint32_t f = 0;
  std::memcpy(&f, raw.data(), 4);
  if (f != frame_count || f == 0) {
    return bad("AV1 chunk of " + std::to_string(f) + " frames, its keys say " +
               std::to_string(frame_count));
  }
  const uint64_t head = 4 + uint64_t{f} * 4;
  if (head > raw.size()) {
    return bad("AV1 chunk of " + std::to_string(raw.size()) +
               " bytes is shorter than its head of " + std::to_string(head));
  }
  Av1Gop gop;
  gop.units.reserve(f);
  uint64_t at = head;
  for (uint32_t i = 0; i < f; ++i) {
    uint32_t size = 0;
    std::memcpy(&size, raw.data() + 4 + size_t{i} * 4, 4);
    if (size == 0 || size > raw.size() - at) {
      return bad("temporal unit " + std::to_string(i) + " of " + std::to_string(size) +
                 " bytes at offset " + std::to_string(at) + " of " + std::to_string(raw.size()));
    }
    gop.units.push_back(raw.subspan(at, size));
    at += size;
  }
  if (at != raw.size()) {
    return bad(std::to_string(raw.size() - at) + " bytes after the last temporal unit");
  }
  return gop;
}

void append_av1_gop(std::vector<uint8_t>& out, std::span<const std::vector<uint8_t>> units) {
  auto put = [&](uint32_t v) {
    for (int b = 0; b < 4; ++b) out.push_back(static_cast<uint8_t>(v >> (8 * b)));
  };
  put(static_cast<uint32_t>(units.size()));
  for (const auto& u : units) put(static_cast<uint32_t>(u.size()));
  for (const auto& u : units) out.insert(out.end(), u.begin(), u.end());
}

}  // namespace calf::lf
