#include <algorithm>
#include <cstring>
#include <vector>

#include "calf/encoder/bc_encode.h"
#include "calf/encoder/depth_aabb.h"
#include "calf/format/bc.h"
#include "calf/format/depth_predict.h"
#include "calf/format/lightfield_layout.h"
#include "calf/format/log_depth.h"
#include "lightfield_view_pass.h"

namespace calf::encoder::lightfield_internal {
namespace {

using container::ChunkKeys;
using container::LightfieldStream;

// A tile's frames as interleaved bytes: depth [hi, lo] per texel, material [reflect, refract,
// ior] per texel.
struct RegionFrames {
  uint32_t width = 0, height = 0, bytes_per_texel = 0, frames = 0;
  std::vector<uint8_t> data;  // [frame][y][x][byte]
  const uint8_t* texel(uint32_t f, uint32_t x, uint32_t y) const {
    return &data[((static_cast<size_t>(f) * height + y) * width + x) * bytes_per_texel];
  }
};

ChangeMask material_change_mask(const RegionFrames& t, uint32_t first, uint32_t current,
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
Status code_region_group(const Context& ctx, const RegionFrames& t, bool is_depth,
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
uint32_t static_group_span(const Context& ctx, const RegionFrames& t, uint32_t first,
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

}  // namespace

void region_task(const Context& ctx, uint32_t face, uint32_t tile, RegionStream stream,
                 TaskOut& out) {
  const ViewData& v = *ctx.view;
  const bool is_depth = stream == RegionStream::kDepth;
  const bool is_coverage = stream == RegionStream::kCoverage;
  const PixelRect r =
      ctx.tiles.cell_rect(tile % ctx.tiles.cells_per_side(), tile / ctx.tiles.cells_per_side());
  RegionFrames t;
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

}  // namespace calf::encoder::lightfield_internal
