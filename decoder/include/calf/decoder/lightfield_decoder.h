// The view-dependent lightfield decoder (paper 002 Sec. 6.2 and 7.1): a clip state that advances
// to any frame for a set of viewers and yields exactly the texture updates a renderer needs to
// show that frame — only for the cells and tiles whose frustum meets a viewer's frustum.
//
// What a renderer keeps per view (the "texture state" the updates are written into):
//   - colour: two keyframe slots per face (slot 0 and slot 1). Keyframe k_i of a cell always goes
//     into slot i % 2, so moving from the bracket (k_i, k_i+1) to (k_i+1, k_i+2) uploads one
//     keyframe, never two. A cell's colour at frame n is mix(slot a, slot 1 - a, t / 255) in
//     linear RGB, with (t, a) from the frame's CellParams (SPEC §11.1.4);
//   - depth (log-16 codes) and, when the view has it, material: one image per face.
// The decoder remembers what each cell's slots and each tile's texels hold, so a cell or tile that
// was culled (or a view that was inactive) is brought up to date the moment it becomes visible,
// and seeking to any frame uploads only what differs: colour loads the bracketing keyframes;
// depth / material restart from the group keyframe when they must and then step through P-frames
// W at a time (Sec. 7.1: "frames 40 + 4i").
//
// Update payloads are GPU-ready (the file's block split and byte planes undone), in the order they
// must be applied; rectangles of successive updates to one face may overlap (later wins):
//   colour  kBc1     8-byte BC1 blocks, row-major over the rect, sRGB-encoded RGB
//           kBc7     16-byte BC7 blocks, sRGB-encoded
//           kBc6h    16-byte BC6H unsigned-float blocks, linear
//           kRgba8   4 bytes per texel, sRGB-encoded RGB, A = 255
//           kRgba16f 4 half floats per texel (little-endian), linear RGB, A = 1
//   depth   kR16     one little-endian u16 log-16 code per texel (65535 = sky)
//           kBc5     16-byte BC5 blocks; code = 256 * R + G of the decoded 8-bit channels
//   material kRgba8  4 bytes per texel: reflect, refract, ior code, 255 (material_from_codes)
//           kBc1     BC1 blocks of (reflect, refract, ior code), not sRGB
//   coverage kRgba8  4 bytes per texel: mask low byte, mask high byte, near count, far count
//                    (lf::coverage_from_gpu; only with LightfieldDecoderOptions::coverage)
// Block formats cover ceil(w / 4) x ceil(h / 4) blocks; rect x and y are multiples of 4 and w, h
// are too unless the rect reaches the face's right / bottom edge.
//
// Streaming: chunks are fetched and decompressed on a background thread (and read on demand when
// the thread has not got to them yet); after each frame the chunks the same visible set needs for
// the next `prefetch_frames` frames are queued. Decompressed chunks live in a cache bounded by
// `cache_bytes` (least recently used first out; the chunks of the frame being decoded are never
// evicted while in use). A chunk that fails (bad hash, bad layout) is reported in the frame's
// stats; the cells and tiles that needed it keep their last good state and are retried on later
// frames. The updates do not depend on timing, thread count or cache size.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "calf/decoder/culling.h"
#include "calf/decoder/lightfield_reference.h"
#include "calf/format/container.h"
#include "calf/format/cube.h"
#include "calf/format/grid.h"
#include "calf/format/status.h"

namespace calf::decoder {

enum class UpdateTarget : uint8_t { kColour = 0, kDepth = 1, kMaterial = 2, kCoverage = 3 };

// Replace texels `rect` (face texel coordinates) of the (view, face[, slot]) image with `bytes`.
struct TextureUpdate {
  UpdateTarget target = UpdateTarget::kColour;
  uint32_t view = 0;
  CubeFace face = CubeFace::kPosX;
  uint32_t slot = 0;  // colour: keyframe slot 0 or 1; depth / material: 0
  PixelRect rect;
  container::PixelFormat format = container::PixelFormat::kNone;
  std::span<const uint8_t> bytes;  // valid until the next advance() or the decoder's destruction
};

// The interpolation state of one visible colour cell at the frame (SPEC §11.1.4).
struct CellParams {
  uint32_t view = 0;
  CubeFace face = CubeFace::kPosX;
  uint32_t cell = 0;   // index in the view's colour cell grid
  uint8_t t = 0;       // weight of slot 1 - a_slot is t / 255
  uint8_t a_slot = 0;  // the slot holding the keyframe at or before the frame
};

// A visible depth / material tile.
struct LightfieldRegionRef {
  uint32_t view = 0;
  CubeFace face = CubeFace::kPosX;
  uint32_t tile = 0;  // index in the view's depth region grid
  friend bool operator==(const LightfieldRegionRef&, const LightfieldRegionRef&) = default;
};

struct FrameStats {
  uint32_t frame = 0;
  uint64_t culling_tests = 0;        // frustum-frustum tests, cells and tiles
  uint64_t culling_exact_tests = 0;  // of those, full separating-axis tests (culling.h GridCuller)
  uint64_t culling_reused = 0;       // node decisions kept from earlier frames instead of tests
  uint32_t visible_cells = 0;        // colour cells of active views seen by a viewer
  uint32_t total_cells = 0;          // colour cells of active views
  uint32_t visible_regions = 0;      // depth regions of active views seen by a viewer
  uint32_t total_regions = 0;
  uint32_t updates = 0;                                            // texture updates yielded
  uint64_t colour_bytes = 0, depth_bytes = 0, material_bytes = 0;  // update payload bytes
  uint64_t coverage_bytes = 0;
  // AV1 colour: pictures decoded (every cell), and the most one cell decoded: 1 in playback, at
  // most the keyframe interval after a seek (a restart at the GOP's key frame). 0 for BC colour.
  uint32_t av1_pictures = 0, av1_max_pictures_per_cell = 0;
  uint32_t chunks_needed = 0;          // chunks this frame's updates were decoded from
  uint32_t chunks_read_on_demand = 0;  // of those, read by advance() itself (not prefetched)
  size_t cached_bytes = 0;             // decompressed chunks held by the cache after the frame
  double decode_ms = 0;                // wall time of advance()
  double culling_ms = 0;               // of which the culling (visible sets of every view)
  uint32_t errors = 0;                 // chunks that failed this frame
  std::string first_error;  // the first of them, with its id, e.g. "CALF-E202 view 0 ..."
  uint64_t update_bytes() const {
    return colour_bytes + depth_bytes + material_bytes + coverage_bytes;
  }
  // The bitrate of the updates if every frame were like this one, at 24 frames per second
  // (paper 002 Table 3).
  double mbps_at_24fps() const { return update_bytes() * 8.0 * 24.0 / 1e6; }
};

struct LightfieldFrameUpdates {
  uint32_t frame = 0;
  std::vector<TextureUpdate> updates;      // in application order
  std::vector<CellParams> cells;           // every visible cell of every active view
  std::vector<LightfieldRegionRef> tiles;  // every visible tile of every active view
  // The chunks this frame's updates were decoded from (stats.chunks_needed ids, in order of use;
  // a chunk used twice is listed twice): what a benchmark decompresses to time "the limit".
  std::vector<uint32_t> chunks;
  FrameStats stats;
};

// A viewer: its frustum (EyeView); several viewers share one decoder (stereo, several users).
struct LightfieldDecoderOptions {
  // false: every cell and tile of every active view is kept up to date (Table 3 "VD no").
  bool view_dependent = true;
  // Quadtree levels descended per face (0 = all; 1 = test every cell directly).
  uint32_t quadtree_levels = 0;
  // Test every cell against every eye instead (the reference the quadtree is tested against).
  bool brute_force_culling = false;
  // Frames ahead whose chunks are queued for the background thread after each frame (0..64).
  uint32_t prefetch_frames = 2;
  // Bound on decompressed chunks kept in memory (>= 1 MiB).
  size_t cache_bytes = size_t{256} << 20;
  // Fetch chunks on a background thread (false: everything on the caller's thread).
  bool background_thread = true;
  // Decode the track's coverage stream (SPEC §11.1.11), when it has one, into kCoverage updates
  // of every visible tile; off, the stream is never read.
  bool coverage = false;
};

class LightfieldDecoder {
 public:
  // `reader` must outlive the decoder. Errors as LightfieldReference::open, and
  // CALF-E300 for invalid options.
  static Expected<LightfieldDecoder> open(const container::Reader& reader, uint16_t track,
                                          const LightfieldDecoderOptions& options = {});
  LightfieldDecoder(LightfieldDecoder&&) noexcept;
  LightfieldDecoder& operator=(LightfieldDecoder&&) noexcept;
  ~LightfieldDecoder();

  const container::LightfieldTrackHeader& header() const;
  const LightfieldViewInfo& view(uint32_t v) const;
  // The track has a coverage stream (decoded only with LightfieldDecoderOptions::coverage).
  bool has_coverage() const;
  // Ok, or why view v was dropped at open (its index chunk unusable; LightfieldReference::open):
  // a dropped view is never decoded, and naming it in advance()'s active views is an error.
  const Status& view_problem(uint32_t v) const;
  const LightfieldDecoderOptions& options() const;

  // Brings the state of `active_views` (indices, any order, no duplicates, none dropped; empty =
  // every view not dropped) to
  // `frame` for the viewers `eyes`, and fills `out` with the updates and the visible cells'
  // parameters. With no eyes and view_dependent on, nothing is visible. Errors (nothing changes):
  // CALF-E300 for a frame, view or eye out of range (an eye that fails eye_view_problem: not
  // finite, degenerate axes, far <= near). Corrupt chunks are not errors: see FrameStats::errors.
  Status advance(uint32_t frame, std::span<const EyeView> eyes,
                 std::span<const uint32_t> active_views, LightfieldFrameUpdates* out);

  // Turns view-dependent decoding on or off from the next advance() (e.g. a renderer that traces
  // secondary rays reads texels outside the viewers' frusta). Cells that were culled are brought
  // up to date as soon as they are decoded again; nothing is lost.
  void set_view_dependent(bool on);

  // Forgets what the renderer holds (e.g. after it lost its textures): the next advance() uploads
  // everything visible again.
  void reset();

 private:
  struct Impl;
  explicit LightfieldDecoder(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace calf::decoder
