#include "calf/encoder/lightfield_encode.h"

#include <cmath>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "calf/encoder/colour_denoise.h"
#include "calf/format/grid.h"
#include "calf/format/lightfield_layout.h"
#include "lightfield_internal.h"
#include "lightfield_view_pass.h"

namespace calf::encoder {
namespace lightfield_internal {
namespace {

void add_into(StreamBytes& a, const StreamBytes& b) {
  a.raw += b.raw;
  a.temporal += b.temporal;
  a.spatial += b.spatial;
  a.stored += b.stored;
  a.chunks += b.chunks;
}

}  // namespace

Status add_chunk(const Context& ctx, TaskOut& out, container::ChunkKeys keys,
                 const std::vector<uint8_t>& raw, StreamBytes& bytes, bool uncompressed) {
  keys.view = ctx.view_index;  // keys.track: set by LightfieldTrackWriter
  CALF_ASSIGN_OR_RETURN(
      container::StoredChunk c,
      container::compress_chunk(
          raw, uncompressed ? container::Compression::kNone : ctx.options->supercompression,
          ctx.options->levels));
  bytes.spatial += raw.size();
  bytes.stored += c.bytes.size();
  bytes.chunks += 1;
  out.chunks.push_back({keys, std::move(c)});
  return Status::Ok();
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
  total.depth_regions += part.depth_regions;
  total.depth_keyframes += part.depth_keyframes;
  total.depth_pframes += part.depth_pframes;
  total.depth_empty_pframes += part.depth_empty_pframes;
  total.material_views += part.material_views;
  total.min_colour_quality_db = std::min(total.min_colour_quality_db, part.min_colour_quality_db);
  total.colour_denoised += part.colour_denoised;
  total.colour_unmixed += part.colour_unmixed;
  total.depth_max_rel_error = std::max(total.depth_max_rel_error, part.depth_max_rel_error);
  total.depth_sum_rel_error += part.depth_sum_rel_error;
  total.depth_finite_texels += part.depth_finite_texels;
  total.depth_sky_mismatches += part.depth_sky_mismatches;
  total.depth_mean_rel_error =
      total.depth_finite_texels
          ? total.depth_sum_rel_error / static_cast<double>(total.depth_finite_texels)
          : 0;
}

}  // namespace lightfield_internal

namespace {

using container::ChunkKeys;
using container::Compression;
using container::LightfieldStream;
using container::StoredChunk;
using lightfield_internal::add_figures;
using lightfield_internal::Context;
using lightfield_internal::figures_of;
using lightfield_internal::kInf;
using lightfield_internal::kNoiseBlockCap;
using lightfield_internal::Pending;
using lightfield_internal::read_view;
using lightfield_internal::RegionStream;
using lightfield_internal::TaskOut;
using lightfield_internal::ViewData;

}  // namespace

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
  CALF_ASSIGN_OR_RETURN(
      FaceGrid tiles, FaceGrid::with_regions_per_side(m.face_size, options.depth_regions_per_side));

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
  if (options.denoise_window > 1) {
    // The pre-filter sees the frames of this range only: the range is whole segments, and no
    // window crosses a segment, so a shard filters its frames as one encode does.
    StaticDenoiseOptions d;
    d.window = options.denoise_window;
    d.log2 = analysis.hdr;
    if (options.noise_psnr_db > 0)
      d.max_variance = kNoiseBlockCap * std::pow(10.0, -options.noise_psnr_db / 10.0);
    d.segment_frames = options.segment_frames;
    d.threads = options.threads;
    CALF_ASSIGN_OR_RETURN(const StaticDenoiseStats ds,
                          denoise_static_colour(view.colour, view.depth, view.material, view.frames,
                                                view.face_size, d));
    stats.colour_denoised += ds.averaged;
  }
  if (options.coverage_unmix && analysis.coverage && view.range) {
    CALF_ASSIGN_OR_RETURN(stats.colour_unmixed, unmix_view_colour(*options.coverage_unmix, &view));
  }

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
    // Tasks of one face in file order: cells, depth regions, material tiles, coverage tiles.
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
                              region_task(ctx, face, i - nc, RegionStream::kDepth, outs[i]);
                            } else if (i < nc + nt + nm) {
                              region_task(ctx, face, i - nc - nt, RegionStream::kMaterial, outs[i]);
                            } else {
                              region_task(ctx, face, i - nc - nt - nm, RegionStream::kCoverage,
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
    stats.depth_regions += nt;
    if (options.progress) options.progress(uint64_t{6} * v + face + 1, total);
  }
  return out;
}

}  // namespace calf::encoder
