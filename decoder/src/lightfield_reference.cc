#include "calf/decoder/lightfield_reference.h"

#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>

#include "calf/decoder/cpu_textures.h"
#include "calf/format/grid.h"
#include "calf/format/lightfield_layout.h"
#include "calf/format/log_depth.h"
#include "colour_av1.h"

namespace calf::decoder {
namespace {

using container::ChunkQuery;
using container::LightfieldStream;
using container::PixelFormat;

Status corrupt(const std::string& what) {
  return Status(ErrorId::kLightfieldChunk, what);
}

std::string hex_text(uint16_t v) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "%04x", v);
  return buf;
}

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

}  // namespace

bool track_has_coverage(const container::Reader& reader, uint16_t track) {
  ChunkQuery q;
  q.track = track;
  q.stream = static_cast<uint16_t>(LightfieldStream::kCoverage);
  return !reader.find_chunks(q).empty();
}

Status LightfieldReference::read_view_index(uint32_t v) {
  ChunkQuery q;
  q.track = track_;
  q.stream = static_cast<uint16_t>(LightfieldStream::kIndex);
  q.view = v;
  const auto ids = reader_->find_chunks(q);
  const std::string what = "view " + std::to_string(v) + " index";
  if (ids.size() != 1) {
    return corrupt(what + ": " + std::to_string(ids.size()) + " index chunks, expected 1");
  }
  Expected<std::vector<uint8_t>> raw = reader_->read_chunk(ids[0]);
  if (!raw.ok()) return raw.status().with_context(what);
  CALF_ASSIGN_OR_RETURN(views_[v], lf::parse_view_index(*raw, what));
  if (views_[v].has_material && header_.material_format == 0) {
    return corrupt(what + ": material flagged but the track has none");
  }
  return Status::Ok();
}

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
  d.has_coverage_ = track_has_coverage(reader, track);
  const auto& h = d.header_;
  CALF_RETURN_IF_ERROR(lf::check_colour_format(h.colour_format));
  CALF_RETURN_IF_ERROR(lf::depth_coding(h.depth_format).status());
  if (h.material_format != 0) CALF_RETURN_IF_ERROR(lf::material_coding(h.material_format).status());
  if (h.view_count > reader.chunks().size()) {
    return corrupt(std::to_string(h.view_count) + " views but only " +
                   std::to_string(reader.chunks().size()) + " chunks");
  }
  d.views_.resize(h.view_count);
  d.view_problems_.resize(h.view_count);
  uint32_t usable = 0;
  for (uint32_t v = 0; v < h.view_count; ++v) {
    d.view_problems_[v] = d.read_view_index(v);
    if (d.view_problems_[v].ok()) {
      ++usable;
    } else {
      d.views_[v] = LightfieldViewInfo{};  // no half-read index
    }
  }
  if (h.view_count > 0 && usable == 0) return d.view_problems_[0];
  return d;
}

Expected<LightfieldReference::CellTimeline> LightfieldReference::cell_timeline(
    uint32_t view, uint32_t face, uint32_t cell) const {
  CALF_ASSIGN_OR_RETURN(
      uint32_t id, find_one(*reader_, track_, LightfieldStream::kTParams, view, face, cell, 0, 0));
  CALF_ASSIGN_OR_RETURN(std::vector<uint8_t> raw, reader_->read_chunk(id));
  return lf::parse_t_chunk(raw, header_.frame_count, where(view, face, cell) + " t chunk");
}

Expected<std::vector<uint32_t>> LightfieldReference::depth_rect_counts(uint32_t view, uint32_t face,
                                                                       uint32_t tile) const {
  CALF_ASSIGN_OR_RETURN(FaceGrid tiles,
                        FaceGrid::with_cell_size(header_.face_size, header_.depth_region_size));
  CALF_ASSIGN_OR_RETURN(PixelRect r, tiles.cell_rect(tile));
  CALF_ASSIGN_OR_RETURN(lf::RegionCoding coding, lf::depth_coding(header_.depth_format));
  std::vector<uint32_t> counts;
  for (uint32_t f = 0; f < header_.frame_count;) {
    CALF_ASSIGN_OR_RETURN(
        uint32_t id, find_one(*reader_, track_, LightfieldStream::kDepth, view, face, tile, f, f));
    CALF_ASSIGN_OR_RETURN(std::vector<uint8_t> raw, reader_->read_chunk(id));
    const uint32_t fc = reader_->chunks()[id].keys.frame_count;
    CALF_ASSIGN_OR_RETURN(lf::RegionChunk chunk,
                          lf::parse_region_chunk(raw, fc, r.width, r.height, coding,
                                                 where(view, face, tile) + " depth"));
    for (uint32_t i = 0; i < fc; ++i)
      counts.push_back(chunk.first_rect[i + 1] - chunk.first_rect[i]);
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
  if (!view_problems_[view].ok()) return view_problems_[view];
  const uint32_t n = h.face_size;
  CALF_ASSIGN_OR_RETURN(FaceGrid cells, FaceGrid::with_cell_size(n, h.cell_size));
  CALF_ASSIGN_OR_RETURN(FaceGrid tiles, FaceGrid::with_cell_size(n, h.depth_region_size));
  out->colour.assign(size_t{n} * n * 3, 0.0f);
  out->depth.assign(size_t{n} * n, 0);
  out->material.clear();
  out->coverage.clear();

  // Colour: per cell, (1 - w) K_m + w K_m+1 with w = t / 255 (SPEC §11.1.4).
  std::vector<float> a, b;
  std::vector<uint8_t> gpu;
  for (uint32_t cell = 0; cell < cells.cell_count(); ++cell) {
    const PixelRect r =
        cells.cell_rect(cell % cells.cells_per_side(), cell / cells.cells_per_side());
    const std::string what = where(view, face, cell) + " colour";
    if (lf::is_av1_colour(h.colour_format)) {
      // §11.1.12: the units of the chunk serving the frame, from its key frame to the frame.
      CALF_ASSIGN_OR_RETURN(uint32_t id, find_one(*reader_, track_, LightfieldStream::kColour, view,
                                                  face, cell, frame, -1));
      const container::ChunkKeys& keys = reader_->chunks()[id].keys;
      CALF_ASSIGN_OR_RETURN(std::vector<uint8_t> raw, reader_->read_chunk(id));
      lf::Av1HdrCurve curve;
      CALF_ASSIGN_OR_RETURN(lf::Av1Gop gop, lf::parse_av1_chunk(raw, keys.frame_count,
                                                                h.colour_format, &curve, what));
      CALF_ASSIGN_OR_RETURN(Av1CellDecoder av1, Av1CellDecoder::create());
      for (uint32_t u = 0; u <= frame - keys.first_frame; ++u) {
        CALF_RETURN_IF_ERROR(
            av1.decode(gop.units[u], what + " frame " + std::to_string(keys.first_frame + u)));
      }
      CALF_RETURN_IF_ERROR(av1.gpu_bytes(h.colour_format, r.width, r.height, curve, gpu, what));
      a.resize(size_t{r.width} * r.height * 3);
      CALF_RETURN_IF_ERROR(
          decode_gpu_colour(lf::colour_gpu_format(h.colour_format), gpu, r.width, r.height, a));
      for (uint32_t y = 0; y < r.height; ++y) {
        std::memcpy(&out->colour[((size_t{r.y} + y) * n + r.x) * 3], &a[size_t{y} * r.width * 3],
                    size_t{r.width} * 3 * sizeof(float));
      }
      continue;
    }
    CALF_ASSIGN_OR_RETURN(CellTimeline tl, cell_timeline(view, face, cell));
    const uint32_t i = tl.bracket(frame);
    auto load = [&](uint32_t kf, std::vector<float>& dst) -> Status {
      CALF_ASSIGN_OR_RETURN(uint32_t id, find_one(*reader_, track_, LightfieldStream::kColour, view,
                                                  face, cell, kf, kf));
      CALF_ASSIGN_OR_RETURN(std::vector<uint8_t> raw, reader_->read_chunk(id));
      CALF_RETURN_IF_ERROR(
          lf::colour_payload_gpu_bytes(h.colour_format, raw, r.width, r.height, gpu, what));
      dst.resize(size_t{r.width} * r.height * 3);
      return decode_gpu_colour(static_cast<PixelFormat>(h.colour_format), gpu, r.width, r.height,
                               dst);
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

  // Depth, material and coverage: the region chunk serving the frame, every frame of it applied
  // in order from its keyframe (no window jumps: the plain reading of §11.1.6).
  const bool with_material = views_[view].has_material;
  if (with_material) out->material.assign(size_t{n} * n * 3, 0);
  if (has_coverage_) out->coverage.assign(size_t{n} * n, lf::CoverageTexel{});
  std::vector<uint16_t> codes;
  std::vector<uint8_t> mat;
  for (const LightfieldStream stream :
       {LightfieldStream::kDepth, LightfieldStream::kMaterial, LightfieldStream::kCoverage}) {
    const bool depth = stream == LightfieldStream::kDepth;
    const bool coverage = stream == LightfieldStream::kCoverage;
    if ((stream == LightfieldStream::kMaterial && !with_material) || (coverage && !has_coverage_)) {
      continue;
    }
    CALF_ASSIGN_OR_RETURN(lf::RegionCoding coding,
                          depth      ? lf::depth_coding(h.depth_format)
                          : coverage ? Expected<lf::RegionCoding>(lf::RegionCoding::kCoverage)
                                     : lf::material_coding(h.material_format));
    for (uint32_t tile = 0; tile < tiles.cell_count(); ++tile) {
      const PixelRect r =
          tiles.cell_rect(tile % tiles.cells_per_side(), tile / tiles.cells_per_side());
      CALF_ASSIGN_OR_RETURN(uint32_t id,
                            find_one(*reader_, track_, stream, view, face, tile, frame, -1));
      const container::ChunkKeys& keys = reader_->chunks()[id].keys;
      CALF_ASSIGN_OR_RETURN(std::vector<uint8_t> raw, reader_->read_chunk(id));
      const std::string what = where(view, face, tile) + (depth      ? " depth"
                                                          : coverage ? " coverage"
                                                                     : " material");
      CALF_ASSIGN_OR_RETURN(
          lf::RegionChunk chunk,
          lf::parse_region_chunk(raw, keys.frame_count, r.width, r.height, coding, what));
      const PixelFormat format = lf::region_gpu_format(coding);
      for (uint32_t rect = 0; rect < chunk.first_rect[frame - keys.first_frame + 1]; ++rect) {
        const lf::RegionRect& rr = chunk.rects[rect];
        if (lf::region_rect_reads_state(chunk, rect)) {
          // r16pm: the rectangle's unchanged texels are the tile state, here the frame before.
          gpu.resize(size_t{rr.w} * rr.h * 2);
          for (uint32_t y = 0; y < rr.h; ++y) {
            for (uint32_t x = 0; x < rr.w; ++x) {
              const uint16_t c = out->depth[(size_t{r.y} + rr.y + y) * n + r.x + rr.x + x];
              gpu[(size_t{y} * rr.w + x) * 2] = static_cast<uint8_t>(c);
              gpu[(size_t{y} * rr.w + x) * 2 + 1] = static_cast<uint8_t>(c >> 8);
            }
          }
        }
        lf::region_rect_gpu_bytes(chunk, rect, gpu);
        const size_t texels = size_t{rr.w} * rr.h;
        if (coverage) {
          for (uint32_t y = 0; y < rr.h; ++y) {
            for (uint32_t x = 0; x < rr.w; ++x) {
              out->coverage[(size_t{r.y} + rr.y + y) * n + r.x + rr.x + x] =
                  lf::coverage_from_gpu(&gpu[(size_t{y} * rr.w + x) * lf::kCoverageGpuBytes]);
            }
          }
          continue;
        }
        if (depth) {
          codes.resize(texels);
          CALF_RETURN_IF_ERROR(decode_gpu_depth(format, gpu, rr.w, rr.h, codes));
        } else {
          mat.resize(texels * 3);
          CALF_RETURN_IF_ERROR(decode_gpu_material(format, gpu, rr.w, rr.h, mat));
        }
        for (uint32_t y = 0; y < rr.h; ++y) {
          const size_t o = (size_t{r.y} + rr.y + y) * n + r.x + rr.x;
          if (depth) {
            std::memcpy(&out->depth[o], &codes[size_t{y} * rr.w], size_t{rr.w} * 2);
          } else {
            std::memcpy(&out->material[o * 3], &mat[size_t{y} * rr.w * 3], size_t{rr.w} * 3);
          }
        }
      }
    }
  }
  // §11.1.11: with lossless depth, a sky texel has nothing farther than it.
  CALF_ASSIGN_OR_RETURN(lf::RegionCoding depth_coding, lf::depth_coding(h.depth_format));
  if (has_coverage_ && depth_coding != lf::RegionCoding::kBc5) {
    for (size_t i = 0; i < out->coverage.size(); ++i) {
      const lf::CoverageTexel& t = out->coverage[i];
      if (out->depth[i] == kLog16Sky && t.far() != 0) {
        return Status(ErrorId::kCoverageDepth,
                      "view " + std::to_string(view) + " face " + std::to_string(face) + " frame " +
                          std::to_string(frame) + " texel (" + std::to_string(i % n) + ", " +
                          std::to_string(i / n) + "): sky depth with coverage mask 0x" +
                          hex_text(t.mask) + " and near count " + std::to_string(t.near) + ", " +
                          std::to_string(t.far()) + " cells farther than sky");
      }
    }
  }
  return Status::Ok();
}

}  // namespace calf::decoder
