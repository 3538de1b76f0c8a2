#include "calf/decoder/lightfield_reference.h"

#include <array>
#include <cmath>
#include <cstring>
#include <string>

#include "calf/format/bc.h"
#include "calf/format/colour.h"
#include "calf/format/grid.h"

namespace calf::decoder {
namespace {

using container::ChunkQuery;
using container::LightfieldStream;
using container::PixelFormat;

Status corrupt(const std::string& what) { return Status(ErrorId::kLightfieldChunk, what); }

// A bounds-checked little-endian cursor over one chunk's raw bytes.
class Cursor {
 public:
  Cursor(std::span<const uint8_t> bytes, std::string what) : b_(bytes), what_(std::move(what)) {}
  size_t left() const { return b_.size() - pos_; }
  size_t pos() const { return pos_; }
  Expected<uint32_t> u32() {
    if (left() < 4) return corrupt(what_ + ": ends inside a u32 at byte " + std::to_string(pos_));
    uint32_t v = 0;
    for (int i = 0; i < 4; ++i) v |= static_cast<uint32_t>(b_[pos_ + i]) << (8 * i);
    pos_ += 4;
    return v;
  }
  Expected<uint16_t> u16() {
    if (left() < 2) return corrupt(what_ + ": ends inside a u16 at byte " + std::to_string(pos_));
    const uint16_t v = static_cast<uint16_t>(b_[pos_] | b_[pos_ + 1] << 8);
    pos_ += 2;
    return v;
  }
  Expected<float> f32() {
    CALF_ASSIGN_OR_RETURN(uint32_t v, u32());
    float f;
    std::memcpy(&f, &v, 4);
    return f;
  }
  Expected<double> f64() {
    CALF_ASSIGN_OR_RETURN(uint32_t lo, u32());
    CALF_ASSIGN_OR_RETURN(uint32_t hi, u32());
    const uint64_t v = static_cast<uint64_t>(hi) << 32 | lo;
    double d;
    std::memcpy(&d, &v, 8);
    return d;
  }
  std::span<const uint8_t> rest() const { return b_.subspan(pos_); }

 private:
  std::span<const uint8_t> b_;
  size_t pos_ = 0;
  std::string what_;
};

std::string where(uint32_t view, uint32_t face, uint32_t region) {
  return "view " + std::to_string(view) + " face " + std::to_string(face) + " region " +
         std::to_string(region);
}

// The one chunk of (stream, view, face, region) serving `frame` whose first_frame is `first`
// (any first frame when `first` is negative).
Expected<uint32_t> find_one(const container::Reader& r, uint16_t track, LightfieldStream stream,
                            uint32_t view, uint32_t face, uint32_t region, uint32_t frame,
                            int64_t first) {
  ChunkQuery q;
  q.track = track;
  q.stream = static_cast<uint16_t>(stream);
  q.view = view;
  q.face = face;
  q.region = region;
  q.frame = frame;
  int64_t found = -1;
  for (uint32_t id : r.find_chunks(q)) {
    if (first >= 0 && r.chunks()[id].keys.first_frame != first) continue;
    if (found >= 0) {
      return corrupt(where(view, face, region) + ": two chunks of stream " +
                     std::to_string(static_cast<int>(stream)) + " serve frame " +
                     std::to_string(frame));
    }
    found = id;
  }
  if (found < 0) {
    return corrupt(where(view, face, region) + ": no chunk of stream " +
                   std::to_string(static_cast<int>(stream)) + " serves frame " +
                   std::to_string(frame));
  }
  return static_cast<uint32_t>(found);
}

bool colour_format_known(uint16_t f) {
  return f == static_cast<uint16_t>(PixelFormat::kBc1) || f == static_cast<uint16_t>(PixelFormat::kBc7) ||
         f == static_cast<uint16_t>(PixelFormat::kBc6h) ||
         f == static_cast<uint16_t>(PixelFormat::kRgba8) ||
         f == static_cast<uint16_t>(PixelFormat::kRgba16f);
}

size_t blocks_of(uint32_t w, uint32_t h) {
  return static_cast<size_t>(bc::blocks_along(w)) * bc::blocks_along(h);
}

// Decodes a keyframe payload of a w x h cell into linear RGB (SPEC §11.1 "Colour keyframe chunk").
Status decode_colour_payload(uint16_t format, std::span<const uint8_t> p, uint32_t w, uint32_t h,
                             std::vector<float>& rgb, const std::string& what) {
  const size_t n = static_cast<size_t>(w) * h;
  rgb.resize(n * 3);
  const size_t nb = blocks_of(w, h);
  auto wrong = [&](size_t expected) {
    return corrupt(what + ": colour payload of " + std::to_string(p.size()) + " bytes, expected " +
                   std::to_string(expected));
  };
  std::vector<uint8_t> rgba;
  if (format == static_cast<uint16_t>(PixelFormat::kBc1) ||
      format == static_cast<uint16_t>(PixelFormat::kBc7)) {
    const bool bc1 = format == static_cast<uint16_t>(PixelFormat::kBc1);
    const size_t bb = bc1 ? 8 : 16;
    if (p.size() != nb * bb) return wrong(nb * bb);
    std::vector<uint8_t> blocks(p.begin(), p.end());
    if (bc1) {
      for (size_t b = 0; b < nb; ++b) {
        std::memcpy(&blocks[b * 8], &p[b * 4], 4);
        std::memcpy(&blocks[b * 8 + 4], &p[nb * 4 + b * 4], 4);
      }
    }
    rgba.resize(n * 4);
    CALF_RETURN_IF_ERROR(bc::decode_image(bc1 ? bc::Format::kBc1 : bc::Format::kBc7, blocks.data(),
                                          blocks.size(), w, h, rgba.data(), rgba.size(),
                                          size_t{w} * 4));
    for (size_t i = 0; i < n; ++i) {
      for (int c = 0; c < 3; ++c) rgb[3 * i + c] = linear_from_srgb8(rgba[4 * i + c]);
    }
    return Status::Ok();
  }
  if (format == static_cast<uint16_t>(PixelFormat::kBc6h)) {
    if (p.size() != nb * 16) return wrong(nb * 16);
    std::vector<uint16_t> half(n * 3);
    CALF_RETURN_IF_ERROR(bc::decode_image(bc::Format::kBc6hUnsigned, p.data(), p.size(), w, h,
                                          half.data(), half.size() * 2, size_t{w} * 6));
    for (size_t i = 0; i < n * 3; ++i) rgb[i] = bc::half_to_float(half[i]);
    return Status::Ok();
  }
  if (format == static_cast<uint16_t>(PixelFormat::kRgba8)) {
    if (p.size() != n * 4) return wrong(n * 4);
    for (size_t i = 0; i < n; ++i) {
      for (int c = 0; c < 3; ++c) rgb[3 * i + c] = linear_from_srgb8(p[c * n + i]);
    }
    return Status::Ok();
  }
  if (format == static_cast<uint16_t>(PixelFormat::kRgba16f)) {
    if (p.size() != n * 8) return wrong(n * 8);
    const size_t values = n * 4;
    for (size_t i = 0; i < n; ++i) {
      for (int c = 0; c < 3; ++c) {
        const size_t k = 4 * i + c;
        rgb[3 * i + c] = bc::half_to_float(static_cast<uint16_t>(p[k] << 8 | p[values + k]));
      }
    }
    return Status::Ok();
  }
  return Status(ErrorId::kLightfieldFormat, what + ": colour format " + std::to_string(format));
}

enum class RegionCoding { kRaw, kBc5, kBc1 };

// Applies frames [0, upto] of a region chunk to `state` (tile texels, `bpt` bytes each,
// row-major): SPEC §11.1 "Region chunk".
Status apply_region_chunk(std::span<const uint8_t> raw, uint32_t frame_count, uint32_t upto,
                          uint32_t tw, uint32_t th, uint32_t bpt, RegionCoding coding,
                          std::vector<uint8_t>& state, const std::string& what) {
  Cursor c(raw, what);
  CALF_ASSIGN_OR_RETURN(uint32_t f_count, c.u32());
  if (f_count != frame_count || f_count == 0 || upto >= f_count) {
    return corrupt(what + ": frame count " + std::to_string(f_count) + ", index says " +
                   std::to_string(frame_count));
  }
  if (c.left() / 4 < f_count) return corrupt(what + ": rectangle counts run past the chunk");
  std::vector<uint32_t> counts(f_count);
  uint64_t total_rects = 0;
  for (uint32_t f = 0; f < f_count; ++f) {
    CALF_ASSIGN_OR_RETURN(counts[f], c.u32());
    total_rects += counts[f];
  }
  if (total_rects > c.left() / 8) return corrupt(what + ": rectangles run past the chunk");
  struct Rect { uint32_t x, y, w, h; };
  std::vector<Rect> rects(total_rects);
  uint64_t texels = 0, blocks = 0;
  for (Rect& r : rects) {
    CALF_ASSIGN_OR_RETURN(uint16_t x, c.u16());
    CALF_ASSIGN_OR_RETURN(uint16_t y, c.u16());
    CALF_ASSIGN_OR_RETURN(uint16_t w, c.u16());
    CALF_ASSIGN_OR_RETURN(uint16_t h, c.u16());
    r = {x, y, w, h};
    if (w == 0 || h == 0 || uint32_t{x} + w > tw || uint32_t{y} + h > th) {
      return corrupt(what + ": rectangle (" + std::to_string(x) + ", " + std::to_string(y) + ", " +
                     std::to_string(w) + ", " + std::to_string(h) + ") leaves the " +
                     std::to_string(tw) + "x" + std::to_string(th) + " tile");
    }
    if (coding != RegionCoding::kRaw && ((x % 4) != 0 || (y % 4) != 0)) {
      return corrupt(what + ": block-coded rectangle not 4-aligned");
    }
    texels += uint64_t{w} * h;
    blocks += blocks_of(w, h);
  }
  if (counts[0] != 1 || rects[0].x != 0 || rects[0].y != 0 || rects[0].w != tw || rects[0].h != th) {
    return corrupt(what + ": the first frame is not one whole-tile rectangle");
  }
  const std::span<const uint8_t> payload = c.rest();
  const size_t bb = coding == RegionCoding::kBc5 ? 16 : 8;
  const uint64_t expected = coding == RegionCoding::kRaw ? texels * bpt : blocks * bb;
  if (payload.size() != expected) {
    return corrupt(what + ": payload of " + std::to_string(payload.size()) + " bytes, expected " +
                   std::to_string(expected));
  }
  const size_t split = coding == RegionCoding::kBc5 ? blocks * 4 : blocks * 4;
  uint64_t texel_at = 0, block_at = 0;
  size_t rect_at = 0;
  std::array<uint8_t, 16> block{};
  std::array<uint8_t, 64> decoded{};
  for (uint32_t f = 0; f <= upto; ++f) {
    for (uint32_t i = 0; i < counts[f]; ++i) {
      const Rect& r = rects[rect_at++];
      if (coding == RegionCoding::kRaw) {
        for (uint32_t y = 0; y < r.h; ++y) {
          for (uint32_t x = 0; x < r.w; ++x, ++texel_at) {
            uint8_t* dst = &state[((size_t{r.y} + y) * tw + r.x + x) * bpt];
            for (uint32_t b = 0; b < bpt; ++b) dst[b] = payload[b * texels + texel_at];
          }
        }
        continue;
      }
      for (uint32_t by = 0; by < bc::blocks_along(r.h); ++by) {
        for (uint32_t bx = 0; bx < bc::blocks_along(r.w); ++bx, ++block_at) {
          if (coding == RegionCoding::kBc5) {
            const uint8_t* e = &payload[block_at * 4];
            const uint8_t* ix = &payload[split + block_at * 12];
            block = {e[0], e[1], ix[0], ix[1], ix[2], ix[3],  ix[4],  ix[5],
                     e[2], e[3], ix[6], ix[7], ix[8], ix[9], ix[10], ix[11]};
            bc::decode_block(bc::Format::kBc5, block.data(), decoded.data());
          } else {
            std::memcpy(block.data(), &payload[block_at * 4], 4);
            std::memcpy(block.data() + 4, &payload[split + block_at * 4], 4);
            bc::decode_block(bc::Format::kBc1, block.data(), decoded.data());
          }
          const int dbpt = coding == RegionCoding::kBc5 ? 2 : 4;
          for (uint32_t y = 0; y < 4; ++y) {
            for (uint32_t x = 0; x < 4; ++x) {
              const uint32_t tx = r.x + 4 * bx + x, ty = r.y + 4 * by + y;
              if (4 * bx + x >= r.w || 4 * by + y >= r.h) continue;
              std::memcpy(&state[(size_t{ty} * tw + tx) * bpt], &decoded[(4 * y + x) * dbpt], bpt);
            }
          }
        }
      }
    }
  }
  return Status::Ok();
}

}  // namespace

Expected<LightfieldReference> LightfieldReference::open(const container::Reader& reader,
                                                        uint16_t track) {
  if (track >= reader.tracks().size() ||
      !std::holds_alternative<container::LightfieldTrackHeader>(reader.tracks()[track].header)) {
    return Status(ErrorId::kInvalidArgument,
                  "track " + std::to_string(track) + " is not a lightfield track");
  }
  LightfieldReference d;
  d.reader_ = &reader;
  d.track_ = track;
  d.header_ = std::get<container::LightfieldTrackHeader>(reader.tracks()[track].header);
  const auto& h = d.header_;
  if (!colour_format_known(h.colour_format)) {
    return Status(ErrorId::kLightfieldFormat, "colour format " + std::to_string(h.colour_format));
  }
  if (h.depth_format != static_cast<uint16_t>(PixelFormat::kR16) &&
      h.depth_format != static_cast<uint16_t>(PixelFormat::kBc5)) {
    return Status(ErrorId::kLightfieldFormat, "depth format " + std::to_string(h.depth_format));
  }
  if (h.material_format != 0 && h.material_format != static_cast<uint16_t>(PixelFormat::kRgba8) &&
      h.material_format != static_cast<uint16_t>(PixelFormat::kBc1)) {
    return Status(ErrorId::kLightfieldFormat, "material format " + std::to_string(h.material_format));
  }
  if (h.view_count > reader.chunks().size()) {
    return corrupt(std::to_string(h.view_count) + " views but only " +
                   std::to_string(reader.chunks().size()) + " chunks");
  }
  d.views_.resize(h.view_count);
  for (uint32_t v = 0; v < h.view_count; ++v) {
    ChunkQuery q;
    q.track = track;
    q.stream = static_cast<uint16_t>(LightfieldStream::kIndex);
    q.view = v;
    const auto ids = reader.find_chunks(q);
    if (ids.size() != 1) {
      return corrupt("view " + std::to_string(v) + ": " + std::to_string(ids.size()) +
                     " index chunks, expected 1");
    }
    CALF_ASSIGN_OR_RETURN(std::vector<uint8_t> raw, reader.read_chunk(ids[0]));
    Cursor c(raw, "view " + std::to_string(v) + " index");
    CALF_ASSIGN_OR_RETURN(uint32_t version, c.u32());
    if (version != 1) return corrupt("view " + std::to_string(v) + ": index layout " + std::to_string(version));
    LightfieldViewInfo& info = d.views_[v];
    for (double& p : info.position) {
      CALF_ASSIGN_OR_RETURN(p, c.f64());
    }
    CALF_ASSIGN_OR_RETURN(info.z_near, c.f32());
    CALF_ASSIGN_OR_RETURN(info.z_far, c.f32());
    CALF_ASSIGN_OR_RETURN(uint32_t flags, c.u32());
    info.has_depth = (flags & 1) != 0;
    info.has_material = (flags & 2) != 0;
    CALF_ASSIGN_OR_RETURN(info.depth_keyframe_interval, c.u32());
    CALF_ASSIGN_OR_RETURN(info.depth_window, c.u32());
    CALF_ASSIGN_OR_RETURN(info.min_psnr_db, c.f32());
    if (info.has_material && h.material_format == 0) {
      return corrupt("view " + std::to_string(v) + ": material flagged but the track has none");
    }
  }
  return d;
}

Expected<LightfieldReference::CellTimeline> LightfieldReference::cell_timeline(
    uint32_t view, uint32_t face, uint32_t cell) const {
  CALF_ASSIGN_OR_RETURN(uint32_t id, find_one(*reader_, track_, LightfieldStream::kTParams, view,
                                              face, cell, 0, 0));
  CALF_ASSIGN_OR_RETURN(std::vector<uint8_t> raw, reader_->read_chunk(id));
  const std::string what = where(view, face, cell) + " t chunk";
  Cursor c(raw, what);
  CALF_ASSIGN_OR_RETURN(uint32_t k, c.u32());
  const uint32_t n = header_.frame_count;
  if (k == 0 || k > n || c.left() != size_t{k} * 4 + n) {
    return corrupt(what + ": " + std::to_string(k) + " keyframes in " + std::to_string(raw.size()) +
                   " bytes for " + std::to_string(n) + " frames");
  }
  CellTimeline tl;
  tl.keyframes.resize(k);
  for (uint32_t i = 0; i < k; ++i) {
    CALF_ASSIGN_OR_RETURN(tl.keyframes[i], c.u32());
    if ((i == 0 && tl.keyframes[i] != 0) || (i > 0 && tl.keyframes[i] <= tl.keyframes[i - 1]) ||
        tl.keyframes[i] >= n) {
      return corrupt(what + ": keyframes not increasing from 0 below the frame count");
    }
  }
  const auto rest = c.rest();
  tl.t.assign(rest.begin(), rest.end());
  return tl;
}

Expected<std::vector<uint32_t>> LightfieldReference::depth_rect_counts(uint32_t view, uint32_t face,
                                                                       uint32_t tile) const {
  std::vector<uint32_t> counts;
  for (uint32_t f = 0; f < header_.frame_count;) {
    CALF_ASSIGN_OR_RETURN(uint32_t id, find_one(*reader_, track_, LightfieldStream::kDepth, view,
                                                face, tile, f, f));
    CALF_ASSIGN_OR_RETURN(std::vector<uint8_t> raw, reader_->read_chunk(id));
    Cursor c(raw, where(view, face, tile) + " depth");
    CALF_ASSIGN_OR_RETURN(uint32_t fc, c.u32());
    if (fc == 0 || fc != reader_->chunks()[id].keys.frame_count) return corrupt("depth frame count");
    for (uint32_t i = 0; i < fc; ++i) {
      CALF_ASSIGN_OR_RETURN(uint32_t n, c.u32());
      counts.push_back(n);
    }
    f += fc;
  }
  return counts;
}

Status LightfieldReference::decode_face(uint32_t view, uint32_t face, uint32_t frame,
                                        LightfieldFace* out) const {
  const auto& h = header_;
  if (view >= h.view_count || face >= 6 || frame >= h.frame_count) {
    return Status(ErrorId::kInvalidArgument, "view " + std::to_string(view) + " face " +
                                                 std::to_string(face) + " frame " +
                                                 std::to_string(frame) + " is outside the track");
  }
  const uint32_t n = h.face_size;
  CALF_ASSIGN_OR_RETURN(FaceGrid cells, FaceGrid::with_cell_size(n, h.cell_size));
  CALF_ASSIGN_OR_RETURN(FaceGrid tiles, FaceGrid::with_cell_size(n, h.depth_tile_size));
  out->colour.assign(size_t{n} * n * 3, 0.0f);
  out->depth.assign(size_t{n} * n, 0);
  out->material.clear();

  // Colour: per cell, (1 - t) K_m + t K_n (SPEC §11.1 "Decoding a colour cell").
  std::vector<float> a, b;
  for (uint32_t cell = 0; cell < cells.cell_count(); ++cell) {
    const PixelRect r = cells.cell_rect(cell % cells.cells_per_side(), cell / cells.cells_per_side());
    CALF_ASSIGN_OR_RETURN(CellTimeline tl, cell_timeline(view, face, cell));
    size_t i = 0;
    while (i + 1 < tl.keyframes.size() && tl.keyframes[i + 1] <= frame) ++i;
    const std::string what = where(view, face, cell) + " colour";
    auto load = [&](uint32_t kf, std::vector<float>& dst) -> Status {
      CALF_ASSIGN_OR_RETURN(uint32_t id, find_one(*reader_, track_, LightfieldStream::kColour,
                                                  view, face, cell, kf, kf));
      CALF_ASSIGN_OR_RETURN(std::vector<uint8_t> raw, reader_->read_chunk(id));
      return decode_colour_payload(h.colour_format, raw, r.width, r.height, dst, what);
    };
    CALF_RETURN_IF_ERROR(load(tl.keyframes[i], a));
    const uint8_t t = tl.t[frame];
    if (i + 1 < tl.keyframes.size() && t != 0) {
      CALF_RETURN_IF_ERROR(load(tl.keyframes[i + 1], b));
      const float w = t / 255.0f;
      for (size_t k = 0; k < a.size(); ++k) a[k] = (1.0f - w) * a[k] + w * b[k];
    }
    for (uint32_t y = 0; y < r.height; ++y) {
      std::memcpy(&out->colour[((size_t{r.y} + y) * n + r.x) * 3], &a[size_t{y} * r.width * 3],
                  size_t{r.width} * 3 * sizeof(float));
    }
  }

  // Depth and material: the region chunk serving the frame, applied from its keyframe.
  const bool bc5 = h.depth_format == static_cast<uint16_t>(PixelFormat::kBc5);
  const bool with_material = views_[view].has_material;
  if (with_material) out->material.assign(size_t{n} * n * 3, 0);
  std::vector<uint8_t> state;
  for (int pass = 0; pass < (with_material ? 2 : 1); ++pass) {
    const bool depth = pass == 0;
    const uint32_t bpt = depth ? 2 : 3;
    const RegionCoding coding =
        depth ? (bc5 ? RegionCoding::kBc5 : RegionCoding::kRaw)
              : (h.material_format == static_cast<uint16_t>(PixelFormat::kBc1) ? RegionCoding::kBc1
                                                                               : RegionCoding::kRaw);
    for (uint32_t tile = 0; tile < tiles.cell_count(); ++tile) {
      const PixelRect r = tiles.cell_rect(tile % tiles.cells_per_side(), tile / tiles.cells_per_side());
      CALF_ASSIGN_OR_RETURN(
          uint32_t id, find_one(*reader_, track_, depth ? LightfieldStream::kDepth : LightfieldStream::kMaterial,
                                view, face, tile, frame, -1));
      const container::ChunkKeys& keys = reader_->chunks()[id].keys;
      CALF_ASSIGN_OR_RETURN(std::vector<uint8_t> raw, reader_->read_chunk(id));
      state.assign(size_t{r.width} * r.height * bpt, 0);
      CALF_RETURN_IF_ERROR(apply_region_chunk(raw, keys.frame_count, frame - keys.first_frame,
                                              r.width, r.height, bpt, coding, state,
                                              where(view, face, tile) + (depth ? " depth" : " material")));
      for (uint32_t y = 0; y < r.height; ++y) {
        for (uint32_t x = 0; x < r.width; ++x) {
          const uint8_t* s = &state[(size_t{y} * r.width + x) * bpt];
          const size_t o = (size_t{r.y} + y) * n + r.x + x;
          if (depth) {
            out->depth[o] = static_cast<uint16_t>(s[0] << 8 | s[1]);
          } else {
            std::memcpy(&out->material[o * 3], s, 3);
          }
        }
      }
    }
  }
  return Status::Ok();
}

}  // namespace calf::decoder
