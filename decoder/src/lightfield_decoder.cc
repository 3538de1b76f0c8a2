#include "calf/decoder/lightfield_decoder.h"

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstring>
#include <iterator>
#include <numbers>
#include <optional>
#include <string>
#include <unordered_set>

#include "calf/format/lightfield_layout.h"
#include "chunk_cache.h"
#include "colour_av1.h"

namespace calf::decoder {

// r16pm tile state is kept as host u16 and copied to and from little-endian GPU bytes by memcpy.
static_assert(std::endian::native == std::endian::little);

namespace {

using container::LightfieldStream;
using container::PixelFormat;

Status bad_argument(const std::string& what) {
  return Status(ErrorId::kDecoderArgument, what);
}
Status corrupt(const std::string& what) {
  return Status(ErrorId::kLightfieldChunk, what);
}

std::string where(uint32_t view, uint32_t face, uint32_t region) {
  return "view " + std::to_string(view) + " face " + std::to_string(face) + " region " +
         std::to_string(region);
}

Status check_eye(const EyeView& e, size_t i) {
  const char* problem = eye_view_problem(e);
  if (problem) return bad_argument("eye " + std::to_string(i) + ": " + problem);
  return Status::Ok();
}

// A chunk of one (stream, view, face, region) and the frames it serves.
struct ChunkRef {
  uint32_t first_frame = 0, frame_count = 0, id = 0;
};

}  // namespace

struct LightfieldDecoder::Impl {
  const container::Reader* reader = nullptr;
  uint16_t track = 0;
  container::LightfieldTrackHeader header;
  std::vector<LightfieldViewInfo> views;
  std::vector<Status> view_problems;  // Ok, or why the view was dropped at open
  LightfieldDecoderOptions options;
  FaceGrid cells = *FaceGrid::with_cell_size(1, 1);
  FaceGrid tiles = *FaceGrid::with_cell_size(1, 1);
  lf::RegionCoding depth_coding = lf::RegionCoding::kR16;
  std::optional<lf::RegionCoding> material_coding;
  bool has_coverage = false;  // the track holds a coverage stream
  std::unique_ptr<ChunkCache> cache;
  // Node directions of the colour-cell and depth-tile quadtrees, computed once (culling.h).
  std::optional<GridCuller> cell_culler, region_culler;

  // Chunks by (stream, view, face, region), sorted by first frame; a flat table because it is
  // consulted per visible cell and tile every frame.
  uint32_t regions_per_face = 1;
  std::vector<std::vector<ChunkRef>> chunks;
  size_t slot(uint32_t stream, uint32_t v, uint32_t f, uint32_t r) const {
    return ((size_t{stream} * header.view_count + v) * 6 + f) * regions_per_face + r;
  }

  struct CellState {
    std::optional<lf::CellTimeline> timeline;
    int64_t slot_keyframe[2] = {-1, -1};  // the keyframe ordinal each slot holds
    // AV1 colour (SPEC §11.1.12): the cell's dav1d context, created when first visible, the
    // chunk and frame it has decoded up to, and the frame the renderer's slot 0 holds.
    std::shared_ptr<Av1CellDecoder> av1;
    uint32_t av1_chunk = UINT32_MAX;
    int64_t av1_decoded = -1, av1_uploaded = -1;
  };
  struct RegionState {
    int64_t frame = -1;  // the frame the renderer's texels of the tile hold
    // r16pm depth only: a copy of the codes the renderer holds (row-major, the tile's size), for
    // the unchanged texels of P-frame rectangles (SPEC §11.1.9); empty until the tile's first
    // keyframe and for every other coding.
    std::vector<uint16_t> codes;
  };
  // Indexed [view][face * count + index].
  std::vector<std::vector<CellState>> cell_state;
  std::vector<std::vector<RegionState>> depth_state, material_state, coverage_state;

  // The frame being built: update payloads in one arena, spans fixed at the end.
  std::vector<uint8_t> arena;
  std::vector<std::pair<size_t, size_t>> spans;
  std::vector<ChunkBytes> in_use;  // keeps this frame's chunks alive
  std::vector<uint32_t> prefetch_ids;

  // The visible cells and tiles of each view, per face, for the viewers and options below.
  struct VisibleSets {
    bool valid = false;
    std::array<std::vector<uint32_t>, 6> cells, tiles;
  };
  std::vector<VisibleSets> visible_cache;  // per view
  // GridCuller's memory of its decisions (a moving eye is culled mostly from them), indexed
  // [eye][view, then the sky pass][face][cells, tiles].
  std::vector<CullMemory> cull_memory;
  std::vector<EyeView> cache_eyes;
  LightfieldDecoderOptions cache_options;
  bool same_viewers(std::span<const EyeView> eyes) const {
    auto same = [](const EyeView& a, const EyeView& b) {
      return a.position == b.position && a.forward == b.forward && a.up == b.up &&
             a.fov_y == b.fov_y && a.aspect == b.aspect && a.near == b.near && a.far == b.far;
    };
    if (eyes.size() != cache_eyes.size() ||
        options.view_dependent != cache_options.view_dependent ||
        options.quadtree_levels != cache_options.quadtree_levels ||
        options.brute_force_culling != cache_options.brute_force_culling) {
      return false;
    }
    for (size_t i = 0; i < eyes.size(); ++i) {
      if (!same(eyes[i], cache_eyes[i])) return false;
    }
    return true;
  }

  const std::vector<ChunkRef>* find(LightfieldStream s, uint32_t v, uint32_t f, uint32_t r) const {
    return &chunks[slot(static_cast<uint32_t>(s), v, f, r)];
  }

  // The one chunk of the list starting at `first` (exact) or serving `frame`.
  Expected<uint32_t> chunk_serving(LightfieldStream s, uint32_t v, uint32_t f, uint32_t r,
                                   uint32_t frame, bool exact_start) const {
    const std::vector<ChunkRef>* list = find(s, v, f, r);
    if (list != nullptr) {
      auto it = std::upper_bound(list->begin(), list->end(), frame,
                                 [](uint32_t fr, const ChunkRef& c) { return fr < c.first_frame; });
      if (it != list->begin()) {
        const ChunkRef& c = *std::prev(it);
        const bool serves = exact_start ? c.first_frame == frame
                                        : frame - c.first_frame < std::max(c.frame_count, 1u);
        if (serves) return c.id;
      }
    }
    return corrupt(where(v, f, r) + ": no chunk of stream " + std::to_string(static_cast<int>(s)) +
                   (exact_start ? " starts at frame " : " serves frame ") + std::to_string(frame));
  }

  Expected<ChunkBytes> fetch(uint32_t id, LightfieldFrameUpdates* out) {
    FrameStats& stats = out->stats;
    bool here = false;
    CALF_ASSIGN_OR_RETURN(ChunkBytes bytes, cache->get(id, &here));
    out->chunks.push_back(id);
    stats.chunks_needed += 1;
    stats.chunks_read_on_demand += here ? 1 : 0;
    in_use.push_back(bytes);
    return bytes;
  }

  void emit(LightfieldFrameUpdates* out, UpdateTarget target, uint32_t view, uint32_t face,
            uint32_t slot, PixelRect rect, PixelFormat format, const std::vector<uint8_t>& bytes) {
    TextureUpdate u;
    u.target = target;
    u.view = view;
    u.face = static_cast<CubeFace>(face);
    u.slot = slot;
    u.rect = rect;
    u.format = format;
    spans.emplace_back(arena.size(), bytes.size());
    arena.insert(arena.end(), bytes.begin(), bytes.end());
    out->updates.push_back(u);
    uint64_t& counter = target == UpdateTarget::kColour     ? out->stats.colour_bytes
                        : target == UpdateTarget::kDepth    ? out->stats.depth_bytes
                        : target == UpdateTarget::kCoverage ? out->stats.coverage_bytes
                                                            : out->stats.material_bytes;
    counter += bytes.size();
  }

  Status open_tables();
  Status update_cell(uint32_t view, uint32_t face, uint32_t cell, uint32_t frame,
                     LightfieldFrameUpdates* out);
  Status update_cell_av1(uint32_t view, uint32_t face, uint32_t cell, uint32_t frame,
                         LightfieldFrameUpdates* out);
  bool av1 = false;  // the track's colour is AV1
  // `stream`: kDepth, kMaterial or kCoverage.
  Status update_region(LightfieldStream stream, uint32_t view, uint32_t face, uint32_t tile,
                       uint32_t frame, LightfieldFrameUpdates* out);
  void queue_prefetch(bool depth_like, uint32_t view, uint32_t face, uint32_t index,
                      uint32_t frame);
};

Status LightfieldDecoder::Impl::open_tables() {
  const uint32_t cell_count = cells.cell_count(), tile_count = tiles.cell_count();
  const auto& all = reader->chunks();
  regions_per_face = std::max(cell_count, tile_count);
  // A valid track has a t chunk per cell and a depth chunk per tile of every face of every view;
  // checking that first also bounds the table below by the file's own size.
  const uint64_t regions = uint64_t{header.view_count} * 6 * regions_per_face;
  if (regions > all.size()) {
    return corrupt(std::to_string(header.view_count) + " views of 6 x " +
                   std::to_string(regions_per_face) + " regions need more than the file's " +
                   std::to_string(all.size()) + " chunks");
  }
  constexpr uint32_t kStreams = 6;  // index, colour, depth, material, t, coverage (SPEC §11.1)
  chunks.assign(size_t{kStreams} * header.view_count * 6 * regions_per_face, {});
  for (uint32_t id = 0; id < all.size(); ++id) {
    const container::ChunkKeys& k = all[id].keys;
    if (k.track != track || k.stream == static_cast<uint16_t>(LightfieldStream::kIndex)) continue;
    const bool cell_stream = k.stream == static_cast<uint16_t>(LightfieldStream::kColour) ||
                             k.stream == static_cast<uint16_t>(LightfieldStream::kTParams);
    const bool known = cell_stream || k.stream == static_cast<uint16_t>(LightfieldStream::kDepth) ||
                       k.stream == static_cast<uint16_t>(LightfieldStream::kMaterial) ||
                       k.stream == static_cast<uint16_t>(LightfieldStream::kCoverage);
    if (!known) continue;  // streams of later minor versions are skipped
    if (k.view >= header.view_count || k.face >= 6 ||
        k.region >= (cell_stream ? cell_count : tile_count)) {
      return corrupt("chunk " + std::to_string(id) + ": " + where(k.view, k.face, k.region) +
                     " lies outside the track's grid");
    }
    chunks[slot(k.stream, k.view, k.face, k.region)].push_back({k.first_frame, k.frame_count, id});
  }
  for (size_t at = 0; at < chunks.size(); ++at) {
    std::vector<ChunkRef>& list = chunks[at];
    std::sort(list.begin(), list.end(),
              [](const ChunkRef& a, const ChunkRef& b) { return a.first_frame < b.first_frame; });
    for (size_t i = 1; i < list.size(); ++i) {
      if (list[i].first_frame == list[i - 1].first_frame) {
        return corrupt("chunks " + std::to_string(list[i - 1].id) + " and " +
                       std::to_string(list[i].id) + " have the same keys and start at frame " +
                       std::to_string(list[i].first_frame));
      }
    }
  }
  cell_state.assign(header.view_count, std::vector<CellState>(size_t{6} * cell_count));
  depth_state.assign(header.view_count, std::vector<RegionState>(size_t{6} * tile_count));
  material_state.assign(header.view_count, std::vector<RegionState>(size_t{6} * tile_count));
  coverage_state.assign(header.view_count, std::vector<RegionState>(size_t{6} * tile_count));
  visible_cache.assign(header.view_count, {});
  return Status::Ok();
}

Status LightfieldDecoder::Impl::update_cell(uint32_t view, uint32_t face, uint32_t cell,
                                            uint32_t frame, LightfieldFrameUpdates* out) {
  CellState& s = cell_state[view][size_t{face} * cells.cell_count() + cell];
  if (!s.timeline) {
    CALF_ASSIGN_OR_RETURN(uint32_t id,
                          chunk_serving(LightfieldStream::kTParams, view, face, cell, 0, true));
    CALF_ASSIGN_OR_RETURN(ChunkBytes raw, fetch(id, out));
    CALF_ASSIGN_OR_RETURN(lf::CellTimeline tl, lf::parse_t_chunk(*raw, header.frame_count,
                                                                 where(view, face, cell) + " t"));
    s.timeline = std::move(tl);
  }
  const lf::CellTimeline& tl = *s.timeline;
  const uint32_t i = tl.bracket(frame);
  const bool has_next = i + 1 < tl.keyframes.size();
  // Frames after the last keyframe hold it (SPEC §11.1.4), whatever their t byte says.
  const uint8_t t = has_next ? tl.t[frame] : 0;
  const PixelRect rect =
      cells.cell_rect(cell % cells.cells_per_side(), cell / cells.cells_per_side());
  std::vector<uint8_t> gpu[2];
  bool load[2] = {false, false};
  for (uint32_t k = i; k <= i + 1; ++k) {
    if (k > i && (t == 0 || !has_next)) break;
    const uint32_t slot = k % 2;
    if (s.slot_keyframe[slot] == k) continue;
    CALF_ASSIGN_OR_RETURN(uint32_t id, chunk_serving(LightfieldStream::kColour, view, face, cell,
                                                     tl.keyframes[k], true));
    CALF_ASSIGN_OR_RETURN(ChunkBytes raw, fetch(id, out));
    CALF_RETURN_IF_ERROR(lf::colour_payload_gpu_bytes(header.colour_format, *raw, rect.width,
                                                      rect.height, gpu[slot],
                                                      where(view, face, cell) + " colour"));
    load[slot] = true;
  }
  // Only now that every chunk the cell needs is good does its state change.
  for (uint32_t k = i; k <= i + 1; ++k) {
    const uint32_t slot = k % 2;
    if (!load[slot]) continue;
    emit(out, UpdateTarget::kColour, view, face, slot, rect,
         static_cast<PixelFormat>(header.colour_format), gpu[slot]);
    s.slot_keyframe[slot] = k;
  }
  CellParams p;
  p.view = view;
  p.face = static_cast<CubeFace>(face);
  p.cell = cell;
  p.t = t;
  p.a_slot = static_cast<uint8_t>(i % 2);
  out->cells.push_back(p);
  return Status::Ok();
}

// AV1 colour: slot 0 always holds the frame, t = 0. Within the chunk serving the frame, decoding
// goes on from the frame the cell's context holds when that lies before it (playback: one unit per
// frame), else restarts at the chunk's key frame (a seek: at most the keyframe interval of units).
Status LightfieldDecoder::Impl::update_cell_av1(uint32_t view, uint32_t face, uint32_t cell,
                                                uint32_t frame, LightfieldFrameUpdates* out) {
  CellState& s = cell_state[view][size_t{face} * cells.cell_count() + cell];
  const PixelRect rect =
      cells.cell_rect(cell % cells.cells_per_side(), cell / cells.cells_per_side());
  if (s.av1_uploaded != frame) {
    CALF_ASSIGN_OR_RETURN(uint32_t id,
                          chunk_serving(LightfieldStream::kColour, view, face, cell, frame, false));
    const container::ChunkKeys& keys = reader->chunks()[id].keys;
    CALF_ASSIGN_OR_RETURN(ChunkBytes raw, fetch(id, out));
    const std::string what = where(view, face, cell) + " colour";
    lf::Av1HdrCurve curve;
    CALF_ASSIGN_OR_RETURN(lf::Av1Gop gop, lf::parse_av1_chunk(*raw, keys.frame_count,
                                                              header.colour_format, &curve, what));
    if (!s.av1) {
      CALF_ASSIGN_OR_RETURN(Av1CellDecoder d, Av1CellDecoder::create());
      s.av1 = std::make_shared<Av1CellDecoder>(std::move(d));
    }
    uint32_t next = 0;
    if (s.av1_chunk == id && s.av1_decoded >= keys.first_frame && s.av1_decoded <= frame) {
      next = static_cast<uint32_t>(s.av1_decoded) - keys.first_frame + 1;
    } else {
      s.av1->reset();
      s.av1_chunk = id;
      s.av1_decoded = -1;
    }
    for (uint32_t u = next; u <= frame - keys.first_frame; ++u) {
      const Status st =
          s.av1->decode(gop.units[u], what + " frame " + std::to_string(keys.first_frame + u));
      if (!st.ok()) {
        s.av1->reset();
        s.av1_chunk = UINT32_MAX;
        s.av1_decoded = -1;
        return st;
      }
      s.av1_decoded = keys.first_frame + u;
    }
    const uint32_t pictures = frame - keys.first_frame + 1 - next;
    out->stats.av1_pictures += pictures;
    out->stats.av1_max_pictures_per_cell = std::max(out->stats.av1_max_pictures_per_cell, pictures);
    std::vector<uint8_t> gpu;
    CALF_RETURN_IF_ERROR(
        s.av1->gpu_bytes(header.colour_format, rect.width, rect.height, curve, gpu, what));
    emit(out, UpdateTarget::kColour, view, face, 0, rect,
         lf::colour_gpu_format(header.colour_format), gpu);
    s.av1_uploaded = frame;
  }
  CellParams p;
  p.view = view;
  p.face = static_cast<CubeFace>(face);
  p.cell = cell;
  out->cells.push_back(p);
  return Status::Ok();
}

Status LightfieldDecoder::Impl::update_region(LightfieldStream stream, uint32_t view, uint32_t face,
                                              uint32_t tile, uint32_t frame,
                                              LightfieldFrameUpdates* out) {
  const bool depth = stream == LightfieldStream::kDepth;
  const bool coverage = stream == LightfieldStream::kCoverage;
  RegionState& s = (depth      ? depth_state
                    : coverage ? coverage_state
                               : material_state)[view][size_t{face} * tiles.cell_count() + tile];
  if (s.frame == frame) return Status::Ok();
  CALF_ASSIGN_OR_RETURN(uint32_t id, chunk_serving(stream, view, face, tile, frame, false));
  const container::ChunkKeys& keys = reader->chunks()[id].keys;
  CALF_ASSIGN_OR_RETURN(ChunkBytes raw, fetch(id, out));
  const PixelRect r = tiles.cell_rect(tile % tiles.cells_per_side(), tile / tiles.cells_per_side());
  const lf::RegionCoding coding = depth      ? depth_coding
                                  : coverage ? lf::RegionCoding::kCoverage
                                             : *material_coding;
  CALF_ASSIGN_OR_RETURN(
      lf::RegionChunk chunk,
      lf::parse_region_chunk(*raw, keys.frame_count, r.width, r.height, coding,
                             where(view, face, tile) + (depth      ? " depth"
                                                        : coverage ? " coverage"
                                                                   : " material")));
  // Sec. 7.1: from the tile's current frame when it lies in this chunk's group and before the
  // target, else from the group keyframe; then P-frames at most W apart, each valid on top of any
  // frame of the W before it (SPEC §11.1.3 depth_window).
  const uint32_t first = keys.first_frame, target = frame - first;
  const uint32_t window = views[view].depth_window;
  std::vector<uint32_t> steps;
  uint32_t at;
  if (s.frame >= first && s.frame < frame) {
    at = static_cast<uint32_t>(s.frame) - first;
  } else {
    steps.push_back(0);
    at = 0;
  }
  while (at < target) {
    at = target - at > window ? at + window : target;
    steps.push_back(at);
  }
  const UpdateTarget which = depth      ? UpdateTarget::kDepth
                             : coverage ? UpdateTarget::kCoverage
                                        : UpdateTarget::kMaterial;
  const PixelFormat format = lf::region_gpu_format(coding);
  const bool shadow = depth && coding == lf::RegionCoding::kR16PredictedMasked;
  if (shadow) s.codes.resize(size_t{r.width} * r.height);
  std::vector<uint8_t> gpu;
  for (uint32_t step : steps) {
    for (uint32_t k = chunk.first_rect[step]; k < chunk.first_rect[step + 1]; ++k) {
      const lf::RegionRect& rr = chunk.rects[k];
      if (shadow && lf::region_rect_reads_state(chunk, k)) {
        // Whole rows by memcpy: the GPU bytes are little-endian u16, the host's order (asserted
        // at the top of the file).
        gpu.resize(size_t{rr.w} * rr.h * 2);
        for (uint32_t y = 0; y < rr.h; ++y) {
          std::memcpy(gpu.data() + size_t{y} * rr.w * 2,
                      s.codes.data() + size_t{rr.y + y} * r.width + rr.x, size_t{rr.w} * 2);
        }
      }
      lf::region_rect_gpu_bytes(chunk, k, gpu);
      if (shadow) {
        for (uint32_t y = 0; y < rr.h; ++y) {
          std::memcpy(s.codes.data() + size_t{rr.y + y} * r.width + rr.x,
                      gpu.data() + size_t{y} * rr.w * 2, size_t{rr.w} * 2);
        }
      }
      emit(out, which, view, face, 0, PixelRect{r.x + rr.x, r.y + rr.y, rr.w, rr.h}, format, gpu);
    }
  }
  s.frame = frame;
  return Status::Ok();
}

void LightfieldDecoder::Impl::queue_prefetch(bool cell, uint32_t view, uint32_t face,
                                             uint32_t index, uint32_t frame) {
  if (cell && av1) {
    auto id = chunk_serving(LightfieldStream::kColour, view, face, index, frame, false);
    if (id.ok()) prefetch_ids.push_back(*id);
    return;
  }
  if (cell) {
    const CellState& s = cell_state[view][size_t{face} * cells.cell_count() + index];
    if (!s.timeline) return;
    const lf::CellTimeline& tl = *s.timeline;
    const uint32_t i = tl.bracket(frame);
    for (uint32_t k = i; k < std::min<size_t>(i + 2, tl.keyframes.size()); ++k) {
      if (s.slot_keyframe[k % 2] == k) continue;
      auto id = chunk_serving(LightfieldStream::kColour, view, face, index, tl.keyframes[k], true);
      if (id.ok()) prefetch_ids.push_back(*id);
    }
    return;
  }
  for (LightfieldStream st :
       {LightfieldStream::kDepth, LightfieldStream::kMaterial, LightfieldStream::kCoverage}) {
    if (st == LightfieldStream::kCoverage && !(has_coverage && options.coverage)) continue;
    auto id = chunk_serving(st, view, face, index, frame, false);
    if (id.ok()) prefetch_ids.push_back(*id);
  }
}

LightfieldDecoder::LightfieldDecoder(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
LightfieldDecoder::LightfieldDecoder(LightfieldDecoder&&) noexcept = default;
LightfieldDecoder& LightfieldDecoder::operator=(LightfieldDecoder&&) noexcept = default;
LightfieldDecoder::~LightfieldDecoder() = default;

const container::LightfieldTrackHeader& LightfieldDecoder::header() const {
  return impl_->header;
}
const LightfieldViewInfo& LightfieldDecoder::view(uint32_t v) const {
  return impl_->views[v];
}
bool LightfieldDecoder::has_coverage() const {
  return impl_->has_coverage;
}

const Status& LightfieldDecoder::view_problem(uint32_t v) const {
  return impl_->view_problems[v];
}
const LightfieldDecoderOptions& LightfieldDecoder::options() const {
  return impl_->options;
}

Expected<LightfieldDecoder> LightfieldDecoder::open(const container::Reader& reader, uint16_t track,
                                                    const LightfieldDecoderOptions& options) {
  if (options.cache_bytes < (size_t{1} << 20)) return bad_argument("cache_bytes below 1 MiB");
  if (options.prefetch_frames > 64) return bad_argument("prefetch_frames above 64");
  CALF_ASSIGN_OR_RETURN(LightfieldReference ref, LightfieldReference::open(reader, track));
  auto impl = std::make_unique<Impl>();
  impl->reader = &reader;
  impl->track = track;
  impl->header = ref.header();
  impl->has_coverage = ref.has_coverage();
  impl->av1 = lf::is_av1_colour(impl->header.colour_format);
  impl->options = options;
  for (uint32_t v = 0; v < impl->header.view_count; ++v) {
    impl->views.push_back(ref.view(v));
    impl->view_problems.push_back(ref.view_problem(v));
  }
  CALF_ASSIGN_OR_RETURN(impl->cells,
                        FaceGrid::with_cell_size(impl->header.face_size, impl->header.cell_size));
  CALF_ASSIGN_OR_RETURN(impl->tiles, FaceGrid::with_cell_size(impl->header.face_size,
                                                              impl->header.depth_region_size));
  CALF_ASSIGN_OR_RETURN(impl->depth_coding, lf::depth_coding(impl->header.depth_format));
  if (impl->header.material_format != 0) {
    CALF_ASSIGN_OR_RETURN(impl->material_coding, lf::material_coding(impl->header.material_format));
  }
  CALF_RETURN_IF_ERROR(impl->open_tables());
  impl->cell_culler.emplace(impl->cells);
  impl->region_culler.emplace(impl->tiles);
  impl->cache =
      std::make_unique<ChunkCache>(reader, options.cache_bytes, options.background_thread);
  return LightfieldDecoder(std::move(impl));
}

void LightfieldDecoder::set_view_dependent(bool on) {
  impl_->options.view_dependent = on;
}

void LightfieldDecoder::reset() {
  Impl& d = *impl_;
  for (auto& view : d.cell_state) {
    for (auto& c : view) {
      c.slot_keyframe[0] = c.slot_keyframe[1] = -1;
      c.av1_uploaded = -1;
    }
  }
  for (auto* states : {&d.depth_state, &d.material_state, &d.coverage_state}) {
    for (auto& view : *states) {
      for (auto& t : view) t.frame = -1;
    }
  }
}

Status LightfieldDecoder::advance(uint32_t frame, std::span<const EyeView> eyes,
                                  std::span<const uint32_t> active_views,
                                  LightfieldFrameUpdates* out) {
  Impl& d = *impl_;
  const auto start = std::chrono::steady_clock::now();
  if (frame >= d.header.frame_count) {
    return bad_argument("frame " + std::to_string(frame) + " of a clip of " +
                        std::to_string(d.header.frame_count));
  }
  std::vector<uint32_t> active(active_views.begin(), active_views.end());
  if (active.empty()) {
    for (uint32_t v = 0; v < d.header.view_count; ++v) {
      if (d.view_problems[v].ok()) active.push_back(v);
    }
  }
  std::vector<bool> seen(d.header.view_count, false);
  for (uint32_t v : active) {
    if (v >= d.header.view_count || seen[v]) {
      return bad_argument("active view " + std::to_string(v) + " is out of range or repeated");
    }
    if (!d.view_problems[v].ok()) {
      return bad_argument("active view " + std::to_string(v) +
                          " was dropped at open: " + d.view_problems[v].to_string());
    }
    seen[v] = true;
  }
  std::vector<Frustum> frusta;
  for (size_t i = 0; i < eyes.size(); ++i) {
    CALF_RETURN_IF_ERROR(check_eye(eyes[i], i));
    frusta.push_back(eye_frustum(eyes[i]));
  }

  out->frame = frame;
  out->updates.clear();
  out->cells.clear();
  out->tiles.clear();
  out->chunks.clear();
  out->stats = FrameStats{};
  FrameStats& stats = out->stats;
  stats.frame = frame;
  d.arena.clear();
  d.spans.clear();
  d.in_use.clear();
  d.prefetch_ids.clear();
  auto report = [&](const Status& s) {
    if (stats.errors++ == 0) stats.first_error = s.to_string();
  };

  CullStats cull;
  std::vector<uint32_t> all_cells(d.cells.cell_count()), all_regions(d.tiles.cell_count());
  for (uint32_t i = 0; i < all_cells.size(); ++i) all_cells[i] = i;
  for (uint32_t i = 0; i < all_regions.size(); ++i) all_regions[i] = i;
  // The visible sets depend on the viewers and the culling options only (not on the frame): kept
  // from frame to frame while those stay the same, recomputed per view when it is next needed.
  if (!d.same_viewers(eyes)) {
    for (Impl::VisibleSets& vs : d.visible_cache) vs.valid = false;
    d.cache_eyes.assign(eyes.begin(), eyes.end());
    d.cache_options = d.options;
  }
  std::vector<PreparedEye> prepared;
  for (const Frustum& f : frusta) prepared.push_back(prepare_eye(f));
  std::vector<uint32_t> by_eye;
  const size_t memory_per_eye = (size_t{d.header.view_count} + 1) * 12;
  if (d.cull_memory.size() != eyes.size() * memory_per_eye) {
    d.cull_memory.resize(eyes.size() * memory_per_eye);
  }
  // `view`: view_count for the sky pass.
  auto cull_cells = [&](const Vec3& apex, uint32_t view, uint32_t f, bool tiles, double z_near,
                        double z_far, size_t eye) {
    const GridCuller& culler = tiles ? *d.region_culler : *d.cell_culler;
    const CubeFace face = static_cast<CubeFace>(f);
    if (d.options.brute_force_culling) {
      by_eye = visible_cells_brute_force(apex, face, culler.grid(), z_near, z_far,
                                         std::span<const Frustum>(&frusta[eye], 1), &cull);
    } else {
      CullMemory& memory =
          d.cull_memory[eye * memory_per_eye + (size_t{view} * 6 + f) * 2 + (tiles ? 1 : 0)];
      culler.visible_reusing(apex, face, z_near, z_far, prepared[eye], d.options.quadtree_levels,
                             &memory, &cull, &by_eye);
    }
  };
  // Sky: it is at infinity, so the renderer reads every view's sky in the eye ray's own
  // direction, not at a point in the viewer's frustum. A cell whose directions meet the viewer's
  // is therefore needed too: its frustum placed at the eye, tested against the eye's frustum with
  // a far cap beyond the eye's (so every shared direction has a shared point). That set is the
  // same for every view: computed once per eye, face and grid, when first needed.
  std::vector<std::array<std::optional<std::vector<uint32_t>>, 12>> sky(eyes.size());
  auto sky_set = [&](size_t i, uint32_t f, bool tiles) -> const std::vector<uint32_t>& {
    std::optional<std::vector<uint32_t>>& slot = sky[i][f * 2 + (tiles ? 1 : 0)];
    if (!slot) {
      cull_cells(eyes[i].position, d.header.view_count, f, tiles, eyes[i].near, 2 * eyes[i].far, i);
      slot = by_eye;
    }
    return *slot;
  };
  // Every view's culling first, then every view's decoding: the culler's nodes and memory stay
  // in the processor's caches from one view to the next.
  const auto cull_start = std::chrono::steady_clock::now();
  bool culled = false;
  std::vector<double> z_far(eyes.size());
  std::vector<uint32_t> merged;
  auto unite = [&](std::vector<uint32_t>& united, const std::vector<uint32_t>& more) {
    merged.clear();
    std::set_union(united.begin(), united.end(), more.begin(), more.end(),
                   std::back_inserter(merged));
    united.swap(merged);
  };
  for (uint32_t v : active) {
    const LightfieldViewInfo& info = d.views[v];
    const Vec3 p = info.position;
    Impl::VisibleSets& vs = d.visible_cache[v];
    if (d.options.view_dependent && !vs.valid) {
      culled = true;
      // Geometry: a cell frustum reaching past each viewer's far plane (seen from this viewpoint)
      // holds every point the viewer can see through it. The far cap depends on the viewer, so
      // each viewer is culled on its own and the visible sets are united: several viewers see
      // exactly the union of each.
      for (size_t i = 0; i < eyes.size(); ++i) {
        z_far[i] = std::max<double>(info.z_far, length(eyes[i].position - p) + eyes[i].far);
      }
      for (uint32_t f = 0; f < 6; ++f) {
        for (bool tiles : {false, true}) {
          std::vector<uint32_t>& united = tiles ? vs.tiles[f] : vs.cells[f];
          united.clear();
          for (size_t i = 0; i < eyes.size(); ++i) {
            cull_cells(p, v, f, tiles, info.z_near, z_far[i], i);
            unite(united, by_eye);
            unite(united, sky_set(i, f, tiles));
          }
        }
      }
      vs.valid = true;
    }
  }
  if (culled) {
    stats.culling_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - cull_start)
            .count();
  }
  for (uint32_t v : active) {
    const bool has_material = d.views[v].has_material && d.material_coding.has_value();
    const bool with_coverage = d.has_coverage && d.options.coverage;
    const Impl::VisibleSets& vs = d.visible_cache[v];
    for (uint32_t f = 0; f < 6; ++f) {
      const CubeFace face = static_cast<CubeFace>(f);
      const std::vector<uint32_t>& vis_cells = d.options.view_dependent ? vs.cells[f] : all_cells;
      const std::vector<uint32_t>& vis_regions =
          d.options.view_dependent ? vs.tiles[f] : all_regions;
      stats.total_cells += d.cells.cell_count();
      stats.total_regions += d.tiles.cell_count();
      stats.visible_cells += static_cast<uint32_t>(vis_cells.size());
      stats.visible_regions += static_cast<uint32_t>(vis_regions.size());
      for (uint32_t c : vis_cells) {
        if (Status s =
                d.av1 ? d.update_cell_av1(v, f, c, frame, out) : d.update_cell(v, f, c, frame, out);
            !s.ok()) {
          report(s);
        }
      }
      for (uint32_t t : vis_regions) {
        out->tiles.push_back(LightfieldRegionRef{v, face, t});
        if (Status s = d.update_region(LightfieldStream::kDepth, v, f, t, frame, out); !s.ok()) {
          report(s);
        }
        if (has_material) {
          Status s = d.update_region(LightfieldStream::kMaterial, v, f, t, frame, out);
          if (!s.ok()) report(s);
        }
        if (with_coverage) {
          Status s = d.update_region(LightfieldStream::kCoverage, v, f, t, frame, out);
          if (!s.ok()) report(s);
        }
      }
      // Without the background thread nothing would read the queue.
      const uint32_t prefetch = d.options.background_thread ? d.options.prefetch_frames : 0;
      for (uint32_t ahead = 1; ahead <= prefetch; ++ahead) {
        if (frame + ahead >= d.header.frame_count) break;
        for (uint32_t c : vis_cells) d.queue_prefetch(true, v, f, c, frame + ahead);
        for (uint32_t t : vis_regions) d.queue_prefetch(false, v, f, t, frame + ahead);
      }
    }
  }
  for (size_t i = 0; i < out->updates.size(); ++i) {
    out->updates[i].bytes =
        std::span<const uint8_t>(d.arena).subspan(d.spans[i].first, d.spans[i].second);
  }
  stats.updates = static_cast<uint32_t>(out->updates.size());
  stats.culling_tests = cull.tests;
  stats.culling_exact_tests = cull.exact_tests;
  stats.culling_reused = cull.reused;
  // Nearest frames first; a chunk serving several of them once.
  std::unordered_set<uint32_t> queued;
  std::erase_if(d.prefetch_ids, [&](uint32_t id) { return !queued.insert(id).second; });
  d.cache->prefetch(d.prefetch_ids);
  stats.cached_bytes = d.cache->cached_bytes();
  stats.decode_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return Status::Ok();
}

}  // namespace calf::decoder
