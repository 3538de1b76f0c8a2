// Test-only generator of the crafted lightfield conformance clips (tests/conformance/lightfield/
// crafted_*.calf, format/SPEC.md §14): clips written chunk by chunk and block by block, not by
// the encoder, so that they reach what the encoded clips never do — every BC7 mode and partition,
// every BC6H mode and partition, reserved block modes, BC1 3-colour blocks with index 3, faces
// whose size is not a multiple of the cell, tile or block size, material P-frame rectangles,
// interpolated BC1 and BC7 frames, a lightfield track that is not track 0, optional chunk flags,
// zstd frames with a content checksum, and a dropped view. Every byte comes from a fixed
// pseudo-random sequence and hand-built zstd Raw_Block frames (no compressor runs), so the files
// never depend on a library version. Header-only: the test that checks the committed files against
// it (tests/decoder/lightfield_crafted_test.cc) includes it; the runners read only the files.
#pragma once

#include <algorithm>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "calf/format/bc_tables.h"
#include "calf/format/container.h"
#include "calf/format/container_codec.h"
#include "calf/format/container_fields.h"
#include "calf/format/container_io.h"
#include "calf/format/grid.h"
#include "calf/format/lightfield_layout.h"
#include "container_corpus.h"

namespace calf::conformance::crafted {

using Bytes = std::vector<uint8_t>;
using container::PixelFormat;

// splitmix64: a fixed sequence, the same on every platform.
struct Rng {
  uint64_t s;
  uint64_t next() {
    uint64_t z = (s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  uint32_t below(uint32_t n) { return static_cast<uint32_t>(next() % n); }
  uint8_t byte() { return static_cast<uint8_t>(next()); }
};

// Writes the low `n` bits of `value` at block bits [pos, pos + n), LSB first (BPTC bit order).
inline void put_bits(uint8_t* block, int pos, int n, uint32_t value) {
  for (int i = 0; i < n; ++i) {
    const int b = pos + i;
    block[b / 8] =
        static_cast<uint8_t>((block[b / 8] & ~(1u << (b % 8))) | (((value >> i) & 1u) << (b % 8)));
  }
}

// The forced header of the i-th BC7 block: the reserved mode (byte 0 = 0), then every partition of
// modes 0, 1, 2, 3 and 7, every rotation and index selection of modes 4 and 5, and mode 6; after
// those 286 blocks the modes repeat with random partitions. The rest of each block is random.
inline void bc7_block(uint32_t i, Rng& rng, uint8_t* block) {
  for (int b = 0; b < 16; ++b) block[b] = rng.byte();
  struct Run {
    int mode, count;
  };
  constexpr Run kRuns[] = {{-1, 1}, {0, 16}, {1, 64}, {2, 64}, {3, 64},
                           {4, 8},  {5, 4},  {6, 1},  {7, 64}};
  uint32_t k = i, which = 0;
  bool found = false;
  for (const Run& r : kRuns) {
    if (k < static_cast<uint32_t>(r.count)) {
      found = true;
      break;
    }
    k -= static_cast<uint32_t>(r.count);
    ++which;
  }
  if (!found) {
    which = 1 + rng.below(8);
    k = rng.below(static_cast<uint32_t>(kRuns[which].count));
  }
  const int mode = kRuns[which].mode;
  if (mode < 0) {
    block[0] = 0;
    return;
  }
  put_bits(block, 0, mode + 1, 1u << mode);
  if (mode == 4) {
    put_bits(block, 5, 2, k & 3);   // rotation
    put_bits(block, 7, 1, k >> 2);  // index selection
  } else if (mode == 5) {
    put_bits(block, 6, 2, k);  // rotation
  } else if (mode != 6) {
    put_bits(block, mode + 1, mode == 0 ? 4 : 6, k);  // partition
  }
}

// The forced header of the i-th BC6H block: every partition (0-31) of the ten two-region modes,
// the four one-region modes, the four reserved mode values 19, 23, 27, 31; then random modes.
inline void bc6h_block(uint32_t i, Rng& rng, uint8_t* block) {
  for (int b = 0; b < 16; ++b) block[b] = rng.byte();
  uint32_t k = i;
  for (int m = 0; m < 14; ++m) {
    const bc::Bc6hMode& mode = bc::kBc6hModes[m];
    const uint32_t count = mode.partition_bits ? 32 : 1;
    if (k < count) {
      put_bits(block, 0, mode.mode_bits, mode.mode_value);
      if (mode.partition_bits) put_bits(block, 77, 5, k);  // after the 77 header bits
      return;
    }
    k -= count;
  }
  if (k < 4) {
    put_bits(block, 0, 5, 19 + 4 * k);
    return;
  }
  const bc::Bc6hMode& mode = bc::kBc6hModes[rng.below(14)];
  put_bits(block, 0, mode.mode_bits, mode.mode_value);
}

// The i-th BC1 block: random, so about half are 4-colour (c0 > c1) and half 3-colour (c0 <= c1)
// with random indices (index 3 of a 3-colour block occurs), except the first two, SPEC §11.1.10's
// example written out: c0 = 0xF800, c1 = 0x0800 (reds 255 and 8) with texel k taking index k mod 4
// (R = 255, 8, 172, 90 in each row), and the same endpoints swapped, a 3-colour block, with texel
// k taking index 3 - k mod 4 (R = 0, 131, 255, 8: index 3 first, since the first cell's second
// block column is an edge block of two texels).
inline void bc1_block(uint32_t i, Rng& rng, uint8_t* block) {
  for (int b = 0; b < 8; ++b) block[b] = rng.byte();
  if (i < 2) {
    const uint8_t example[8] = {0x00, 0xF8, 0x00, 0x08, 0xE4, 0xE4, 0xE4, 0xE4};
    std::copy(example, example + 8, block);
    if (i == 1) {
      std::swap_ranges(block, block + 2, block + 2);
      std::fill(block + 4, block + 8, uint8_t{0x1B});
    }
  }
}

// One crafted clip's parameters.
struct ClipSpec {
  std::string name;
  uint16_t colour_format = 0, depth_format = 0, material_format = 0, flags = 0;
  uint32_t face_size = 0, cell_size = 0, depth_region_size = 0, frame_count = 0, view_count = 1;
  uint32_t depth_keyframe_interval = 1;
  uint64_t seed = 0;
  bool lightfield_is_track_1 = false;  // track 0 is then an unknown optional kind
  bool chunk_flags_and_checksums = false;
  int dropped_view = -1;  // this view's index chunk is left out
};

// The cell timelines: (keyframes, t) patterns, chosen per cell in turn. Every pattern has t = 0 at
// its keyframes; 0 < t < 255 and t = 255 occur between keyframes.
struct Timeline {
  std::vector<uint32_t> keyframes;
  std::vector<uint8_t> t;
};
inline Timeline timeline_for(uint32_t cell_serial, uint32_t frame_count) {
  Timeline tl;
  tl.t.assign(frame_count, 0);
  switch (cell_serial % 4) {
    case 0:  // 0 and 3: frames 1, 2 interpolated (t 1 and 200), 4 … held
      tl.keyframes = {0, 3};
      tl.t[1] = 1;
      tl.t[2] = 200;
      break;
    case 1:  // 0, 2, 4: t 255 then 77
      tl.keyframes = {0, 2, 4};
      tl.t[1] = 255;
      tl.t[3] = 77;
      break;
    case 2:  // one keyframe, held
      tl.keyframes = {0};
      break;
    default:  // every frame a keyframe but frame 1, t 128
      tl.keyframes = {0, 2, 3, 4};
      tl.t[1] = 128;
      break;
  }
  return tl;
}

// Texels / blocks of a w x h region in a colour or region format.
inline size_t block_count(uint32_t w, uint32_t h) {
  return size_t{(w + 3) / 4} * ((h + 3) / 4);
}

// The payload of a colour keyframe of a w x h cell (§11.1.5). `serial` numbers the blocks of the
// clip's colour format so that the forced BC7 / BC6H headers run through every mode.
inline Bytes colour_payload(const ClipSpec& s, uint32_t w, uint32_t h, uint32_t& serial, Rng& rng) {
  Bytes out;
  const size_t blocks = block_count(w, h);
  if (s.colour_format == static_cast<uint16_t>(PixelFormat::kBc1)) {
    Bytes b(8 * blocks);
    for (size_t i = 0; i < blocks; ++i, ++serial) bc1_block(serial, rng, &b[8 * i]);
    lf::append_block_split(out, b, 8, false);
  } else {
    Bytes b(16 * blocks);
    for (size_t i = 0; i < blocks; ++i, ++serial) {
      if (s.colour_format == static_cast<uint16_t>(PixelFormat::kBc7)) {
        bc7_block(serial, rng, &b[16 * i]);
      } else {
        bc6h_block(serial, rng, &b[16 * i]);
      }
    }
    out = std::move(b);
  }
  return out;
}

// A region chunk (§11.1.6) of a tw x th tile over `frames` frames: the keyframe's whole tile, then
// per P-frame 0, 1 or 2 random non-overlapping rectangles (block formats: x, y multiples of 4).
inline Bytes region_chunk(uint32_t tw, uint32_t th, uint32_t frames, lf::RegionCoding coding,
                          Rng& rng) {
  const bool block = lf::region_coding_is_block(coding);
  lf::RegionHead head;
  auto random_rect = [&](uint32_t x0, uint32_t x1) {  // inside columns [x0, x1)
    lf::RegionRect r;
    const uint32_t step = block ? 4 : 1;
    const uint32_t nx = (x1 - x0 + step - 1) / step, ny = (th + step - 1) / step;
    r.x = static_cast<uint16_t>(x0 + step * rng.below(nx));
    r.y = static_cast<uint16_t>(step * rng.below(ny));
    r.w = static_cast<uint16_t>(1 + rng.below(x1 - r.x));
    r.h = static_cast<uint16_t>(1 + rng.below(th - r.y));
    return r;
  };
  for (uint32_t f = 0; f < frames; ++f) {
    if (f == 0) {
      head.rect_counts.push_back(1);
      head.rects.push_back({0, 0, static_cast<uint16_t>(tw), static_cast<uint16_t>(th)});
      continue;
    }
    const uint32_t split = block ? (tw / 2) / 4 * 4 : tw / 2;
    const uint32_t n = split == 0 ? rng.below(2) : rng.below(3);
    head.rect_counts.push_back(n);
    if (n == 1) head.rects.push_back(random_rect(0, tw));
    if (n == 2) {
      head.rects.push_back(random_rect(0, split));
      head.rects.push_back(random_rect(split, tw));
    }
  }
  Bytes out;
  (void)container::write_fields(head, out, "crafted region head");
  Bytes texels, blocks;
  for (const lf::RegionRect& r : head.rects) {
    const size_t n = size_t{r.w} * r.h;
    switch (coding) {
      case lf::RegionCoding::kR16:
        for (size_t i = 0; i < n; ++i) {
          const uint16_t code = rng.below(8) == 0 ? 65535 : static_cast<uint16_t>(rng.next());
          texels.push_back(static_cast<uint8_t>(code >> 8));
          texels.push_back(static_cast<uint8_t>(code));
        }
        break;
      case lf::RegionCoding::kRgb8:
        for (size_t i = 0; i < 3 * n; ++i) texels.push_back(rng.byte());
        break;
      case lf::RegionCoding::kBc5:
        for (size_t i = 0; i < 16 * block_count(r.w, r.h); ++i) blocks.push_back(rng.byte());
        break;
      default:  // kBc1
        for (size_t i = 0; i < 8 * block_count(r.w, r.h); ++i) blocks.push_back(rng.byte());
        break;
    }
  }
  if (coding == lf::RegionCoding::kR16 || coding == lf::RegionCoding::kRgb8) {
    // The texels were drawn interleaved (high, low / reflect, refract, ior): store them as planes.
    lf::append_planes(out, texels, coding == lf::RegionCoding::kR16 ? 2 : 3);
  } else {
    lf::append_block_split(out, blocks, coding == lf::RegionCoding::kBc5 ? 16 : 8,
                           coding == lf::RegionCoding::kBc5);
  }
  return out;
}

// Writes the clip. Chunks are stored (compression none), except, with chunk_flags_and_checksums,
// the t chunks: zstd frames with a content checksum; every third chunk of the lightfield track
// then also has optional chunk flag bits set (bit 8, and bit 15 on every sixth).
inline Expected<Bytes> make_clip(const ClipSpec& s) {
  using container::ChunkKeys;
  using container::LightfieldStream;
  Bytes file;
  CALF_ASSIGN_OR_RETURN(
      container::Writer w,
      container::Writer::create(
          container::memory_sink(&file),
          container::CompressionOptions{.compress_directory = false, .store_when_larger = false}));
  uint16_t track = 0;
  if (s.lightfield_is_track_1) {
    CALF_RETURN_IF_ERROR(w.add_track(0x7777, 0, Bytes{'c', 'r', 'a', 'f', 't'}).status());
    track = 1;
  }
  container::LightfieldTrackHeader h;
  h.frame_count = s.frame_count;
  h.fps_numerator = 24;
  h.fps_denominator = 1;
  h.view_count = s.view_count;
  h.face_size = s.face_size;
  h.cell_size = s.cell_size;
  h.depth_region_size = s.depth_region_size;
  h.colour_format = s.colour_format;
  h.depth_format = s.depth_format;
  h.material_format = s.material_format;
  h.flags = s.flags;
  CALF_RETURN_IF_ERROR(w.add_track(h).status());
  CALF_RETURN_IF_ERROR(w.set_metadata("calf.conformance", "crafted " + s.name));
  if (s.lightfield_is_track_1) {
    ChunkKeys k;
    k.stream = 1;
    CALF_RETURN_IF_ERROR(
        w.add_chunk(k, Bytes{1, 2, 3, 4, 5}, container::Compression::kNone).status());
  }
  std::vector<uint32_t> flagged;  // chunk ids of the lightfield track given optional flags
  uint32_t lf_chunks = 0;
  auto add = [&](const ChunkKeys& k, const Bytes& raw, bool checksummed) -> Status {
    Expected<uint32_t> id =
        checksummed
            ? w.add_stored_chunk(
                  k,
                  container::StoredChunk{container::Compression::kZstd, raw.size(),
                                         container::corpus::raw_zstd_frame(raw, raw.size(), true)})
            : w.add_chunk(k, raw, container::Compression::kNone);
    if (!id.ok()) return id.status();
    if (s.chunk_flags_and_checksums && lf_chunks % 3 == 1) flagged.push_back(*id);
    ++lf_chunks;
    return Status::Ok();
  };
  Rng rng{s.seed};
  CALF_ASSIGN_OR_RETURN(FaceGrid cells, FaceGrid::with_cell_size(s.face_size, s.cell_size));
  CALF_ASSIGN_OR_RETURN(FaceGrid tiles, FaceGrid::with_cell_size(s.face_size, s.depth_region_size));
  CALF_ASSIGN_OR_RETURN(lf::RegionCoding depth, lf::depth_coding(s.depth_format));
  const bool material = s.material_format != 0;
  lf::RegionCoding mat = lf::RegionCoding::kRgb8;
  if (material) {
    CALF_ASSIGN_OR_RETURN(mat, lf::material_coding(s.material_format));
  }
  uint32_t serial = 0, cell_serial = 0;
  for (uint32_t v = 0; v < s.view_count; ++v) {
    ChunkKeys k;
    k.track = track;
    k.view = v;
    if (static_cast<int>(v) != s.dropped_view) {
      lf::ViewIndex vi;
      vi.position = {static_cast<double>(v), 0.25, -0.5};
      vi.z_near = 0.5f;
      vi.z_far = 50.0f;
      vi.has_depth = true;
      vi.has_material = material && v % 2 == 0;  // odd views: no material
      vi.depth_keyframe_interval = s.depth_keyframe_interval;
      vi.depth_window = 1;
      vi.min_psnr_db = 40;
      CALF_ASSIGN_OR_RETURN(Bytes index, lf::serialize_view_index(vi));
      k.stream = static_cast<uint16_t>(LightfieldStream::kIndex);
      CALF_RETURN_IF_ERROR(add(k, index, false));
    }
    for (uint32_t f = 0; f < 6; ++f) {
      k.face = f;
      for (uint32_t c = 0; c < cells.cell_count(); ++c, ++cell_serial) {
        CALF_ASSIGN_OR_RETURN(PixelRect r, cells.cell_rect(c));
        const Timeline tl = timeline_for(cell_serial, s.frame_count);
        lf::CellTimeline ct{tl.keyframes, tl.t};
        Bytes raw;
        CALF_RETURN_IF_ERROR(container::write_fields(ct, raw, "crafted t chunk"));
        k.region = c;
        k.stream = static_cast<uint16_t>(LightfieldStream::kTParams);
        k.first_frame = 0;
        k.frame_count = s.frame_count;
        CALF_RETURN_IF_ERROR(add(k, raw, s.chunk_flags_and_checksums));
        k.stream = static_cast<uint16_t>(LightfieldStream::kColour);
        for (size_t i = 0; i < tl.keyframes.size(); ++i) {
          k.first_frame = tl.keyframes[i];
          k.frame_count =
              (i + 1 < tl.keyframes.size() ? tl.keyframes[i + 1] : s.frame_count) - k.first_frame;
          CALF_RETURN_IF_ERROR(add(k, colour_payload(s, r.width, r.height, serial, rng), false));
        }
      }
      const bool view_material = material && v % 2 == 0;
      for (int pass = 0; pass < (view_material ? 2 : 1); ++pass) {
        k.stream = static_cast<uint16_t>(pass == 0 ? LightfieldStream::kDepth
                                                   : LightfieldStream::kMaterial);
        for (uint32_t t = 0; t < tiles.cell_count(); ++t) {
          CALF_ASSIGN_OR_RETURN(PixelRect r, tiles.cell_rect(t));
          k.region = t;
          for (uint32_t g = 0; g * s.depth_keyframe_interval < s.frame_count; ++g) {
            k.first_frame = g * s.depth_keyframe_interval;
            k.frame_count = std::min(s.depth_keyframe_interval, s.frame_count - k.first_frame);
            CALF_RETURN_IF_ERROR(
                add(k, region_chunk(r.width, r.height, k.frame_count, pass == 0 ? depth : mat, rng),
                    false));
          }
        }
      }
    }
  }
  CALF_RETURN_IF_ERROR(w.finish());
  if (flagged.empty()) return file;
  // Optional chunk flag bits (§6.2: bits 8-15, ignored by readers) are set in the directory: the
  // chunk hashes cover the stored bytes only, so only the directory and header are re-sealed.
  auto reader = container::Reader::open(container::memory_source(std::span<const uint8_t>(file)));
  if (!reader.ok()) return reader.status();
  const uint64_t dir = reader->header().directory_offset;
  // The plain directory (§4): metadata count and entries, track records, then the chunk index
  // entries of 64 bytes before the 8-byte checksum; flags are at byte 34 of an entry.
  const uint64_t index_at = file.size() - 8 - 64 * uint64_t{reader->header().chunk_count};
  for (size_t i = 0; i < flagged.size(); ++i) {
    const uint16_t flags = i % 2 == 0 ? 0x0100 : 0x8100;
    uint8_t* p = &file[index_at + 64 * uint64_t{flagged[i]} + 34];
    p[0] = static_cast<uint8_t>(flags);
    p[1] = static_cast<uint8_t>(flags >> 8);
  }
  const uint64_t sum =
      container::hash64(std::span<const uint8_t>(file).subspan(dir, file.size() - dir - 8));
  for (int i = 0; i < 8; ++i) file[file.size() - 8 + i] = static_cast<uint8_t>(sum >> (8 * i));
  return file;
}

// The crafted clips (tests/conformance/README.md says what each exercises).
inline std::vector<ClipSpec> clip_specs() {
  std::vector<ClipSpec> out;
  ClipSpec bc7;
  bc7.name = "crafted_bc7_raw16_mat";
  bc7.colour_format = static_cast<uint16_t>(PixelFormat::kBc7);
  bc7.depth_format = static_cast<uint16_t>(PixelFormat::kR16);
  bc7.material_format = static_cast<uint16_t>(PixelFormat::kRgba8);
  bc7.face_size = 30;  // cells 16 + 14, tiles 12 + 12 + 6, edge blocks of 2 texels
  bc7.cell_size = 16;
  bc7.depth_region_size = 12;
  bc7.frame_count = 5;
  bc7.view_count = 2;
  bc7.depth_keyframe_interval = 2;
  bc7.seed = 0xB7;
  bc7.lightfield_is_track_1 = true;
  bc7.chunk_flags_and_checksums = true;
  out.push_back(bc7);
  ClipSpec bc6h;
  bc6h.name = "crafted_bc6h_bc5_mat";
  bc6h.colour_format = static_cast<uint16_t>(PixelFormat::kBc6h);
  bc6h.depth_format = static_cast<uint16_t>(PixelFormat::kBc5);
  bc6h.material_format = static_cast<uint16_t>(PixelFormat::kBc1);
  bc6h.flags = 1;  // HDR
  bc6h.face_size = 30;
  bc6h.cell_size = 16;
  bc6h.depth_region_size = 13;  // tiles 13 + 13 + 4: rectangles with partial blocks
  bc6h.frame_count = 5;
  bc6h.view_count = 2;
  bc6h.depth_keyframe_interval = 3;
  bc6h.seed = 0xB6;
  out.push_back(bc6h);
  ClipSpec bc1;
  bc1.name = "crafted_bc1_raw16";
  bc1.colour_format = static_cast<uint16_t>(PixelFormat::kBc1);
  bc1.depth_format = static_cast<uint16_t>(PixelFormat::kR16);
  bc1.face_size = 10;  // cells 6 + 4, tiles 7 + 3
  bc1.cell_size = 6;
  bc1.depth_region_size = 7;
  bc1.frame_count = 5;
  bc1.view_count = 2;
  bc1.depth_keyframe_interval = 5;
  bc1.seed = 0xB1;
  out.push_back(bc1);
  ClipSpec dropped = bc1;
  dropped.name = "crafted_bc1_dropped_view";
  dropped.dropped_view = 1;
  out.push_back(dropped);
  return out;
}

}  // namespace calf::conformance::crafted
