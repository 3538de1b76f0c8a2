#include "peers.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <thread>

#include <fmt/format.h>

#include "../ffmpeg_peers.h"
#include "calf/capture/capture_set.h"
#include "calf/decoder/lightfield_decoder.h"
#include "calf/decoder/lightfield_reference.h"
#include "calf/format/colour.h"
#include "calf/format/container.h"
#include "calf/format/container_codec.h"
#include "calf/format/cube.h"
#include "calf/format/log_depth.h"
#include "measure.h"

namespace calf::bench {

namespace fs = std::filesystem;

namespace {

// Every view's six faces per frame in one image: face i of view v at columns [i F, (i + 1) F),
// rows [v F, (v + 1) F).
struct GridFrames {
  uint32_t face = 0, views = 0, frames = 0, width = 0, height = 0;
  std::vector<uint16_t> depth;  // frames x height x width log-16 codes
  std::vector<uint8_t> rgb;     // frames x height x width x 3 sRGB bytes
  size_t at(uint32_t frame, uint32_t view, int face_index, uint32_t x, uint32_t y) const {
    return (size_t{frame} * height + size_t{view} * face + y) * width + size_t(face_index) * face +
           x;
  }
};

Expected<GridFrames> capture_grid(const capture::CaptureSetReader& in) {
  const capture::CaptureManifest& m = in.manifest();
  GridFrames g;
  g.face = m.face_size;
  g.views = static_cast<uint32_t>(m.viewpoints.size());
  g.frames = m.frame_count;
  g.width = 6 * g.face;
  g.height = g.views * g.face;
  const size_t pixels = size_t{g.width} * g.height * g.frames;
  g.depth.resize(pixels);
  g.rgb.resize(pixels * 3);
  capture::ViewFrame vf;
  std::vector<float> z;
  for (uint32_t v = 0; v < g.views; ++v) {
    // The view's depth range covers every finite depth of every frame, as the encoder's does.
    z.clear();
    float lo = std::numeric_limits<float>::infinity(), hi = 0;
    for (uint32_t f = 0; f < g.frames; ++f) {
      CALF_RETURN_IF_ERROR(in.read(v, f, &vf));
      for (int i = 0; i < kCubeFaceCount; ++i) {
        for (uint32_t y = 0; y < g.face; ++y) {
          for (uint32_t x = 0; x < g.face; ++x) {
            const size_t t = vf.texel_index(static_cast<CubeFace>(i), x, y);
            const size_t o = g.at(f, v, i, x, y);
            for (int c = 0; c < 3; ++c) g.rgb[3 * o + c] = srgb8_from_linear(vf.color[3 * t + c]);
            const float d = vf.depth[t];
            z.push_back(d);
            if (std::isfinite(d)) {
              lo = std::min(lo, d);
              hi = std::max(hi, d);
            }
          }
        }
      }
    }
    std::optional<LogDepthRange> range;
    if (hi > 0) {
      CALF_ASSIGN_OR_RETURN(LogDepthRange r, LogDepthRange::covering(lo, hi));
      range = r;
    }
    size_t k = 0;
    for (uint32_t f = 0; f < g.frames; ++f) {
      for (int i = 0; i < kCubeFaceCount; ++i) {
        for (uint32_t y = 0; y < g.face; ++y) {
          for (uint32_t x = 0; x < g.face; ++x) {
            g.depth[g.at(f, v, i, x, y)] = range ? range->encode_unchecked(z[k]) : kLog16Sky;
            ++k;
          }
        }
      }
    }
  }
  return g;
}

// The clip's colour decoded by the reference decoder into the grid layout as sRGB bytes, and the
// number of depth codes that differ from `g` (-1 when the clip's depth is not raw16).
struct DecodedClip {
  std::vector<uint8_t> rgb;
  int64_t depth_mismatches = -1;
};

Expected<DecodedClip> decode_clip(const fs::path& clip, const GridFrames& g) {
  CALF_ASSIGN_OR_RETURN(container::Reader reader, container::Reader::open(clip.string()));
  CALF_ASSIGN_OR_RETURN(decoder::LightfieldReference ref,
                        decoder::LightfieldReference::open(reader, 0));
  const auto& h = ref.header();
  if (h.view_count != g.views || h.face_size != g.face || h.frame_count != g.frames) {
    return Status(ErrorId::kInvalidArgument, clip.string() + ": clip does not match the capture");
  }
  DecodedClip out;
  out.rgb.resize(g.rgb.size());
  const bool raw16 =
      h.depth_format == static_cast<uint16_t>(container::PixelFormat::kR16) ||
      h.depth_format == static_cast<uint16_t>(container::PixelFormat::kR16Predicted) ||
      h.depth_format == static_cast<uint16_t>(container::PixelFormat::kR16PredictedMasked);
  if (raw16) out.depth_mismatches = 0;
  decoder::LightfieldFace face;
  for (uint32_t f = 0; f < g.frames; ++f) {
    for (uint32_t v = 0; v < g.views; ++v) {
      for (int i = 0; i < kCubeFaceCount; ++i) {
        CALF_RETURN_IF_ERROR(ref.decode_face(v, static_cast<uint32_t>(i), f, &face));
        for (uint32_t y = 0; y < g.face; ++y) {
          for (uint32_t x = 0; x < g.face; ++x) {
            const size_t t = size_t{y} * g.face + x, o = g.at(f, v, i, x, y);
            for (int c = 0; c < 3; ++c) {
              out.rgb[3 * o + c] = srgb8_from_linear(face.colour[3 * t + c]);
            }
            if (raw16 && face.depth[t] != g.depth[o]) ++out.depth_mismatches;
          }
        }
      }
    }
  }
  return out;
}

// Decode time per frame of the whole clip (every view, every cell and tile, no culling):
// LightfieldDecoder::advance frame after frame; the median of frames 2..n and frame 1 apart, and
// the bytes the frames' updates upload, on average.
struct DecodeTiming {
  double median_ms = 0, first_ms = 0;
  double mean_update_bytes = 0;
};
Expected<DecodeTiming> calf_full_decode_ms(const fs::path& clip) {
  CALF_ASSIGN_OR_RETURN(container::Reader reader, container::Reader::open(clip.string()));
  decoder::LightfieldDecoderOptions o;
  o.view_dependent = false;
  CALF_ASSIGN_OR_RETURN(decoder::LightfieldDecoder d,
                        decoder::LightfieldDecoder::open(reader, 0, o));
  decoder::LightfieldFrameUpdates updates;
  std::vector<double> ms;
  double update_bytes = 0;
  for (uint32_t f = 0; f < d.header().frame_count; ++f) {
    CALF_RETURN_IF_ERROR(d.advance(f, {}, {}, &updates));
    if (updates.stats.errors > 0) {
      return Status(ErrorId::kInternal, clip.string() + ": " + updates.stats.first_error);
    }
    ms.push_back(updates.stats.decode_ms);
    update_bytes += static_cast<double>(updates.stats.update_bytes());
  }
  DecodeTiming t;
  t.mean_update_bytes = update_bytes / static_cast<double>(ms.size());
  t.first_ms = ms.front();
  if (ms.size() > 1) ms.erase(ms.begin());
  t.median_ms = median(ms);
  return t;
}

std::span<const uint8_t> bytes_of(const std::vector<uint16_t>& v) {
  return {reinterpret_cast<const uint8_t*>(v.data()), v.size() * 2};
}

// A raw stream through one of calf's chunk coders at a peer's level, decoded back 3 times.
PeerRow raw_peer(const std::string& stream, const std::string& method, std::span<const uint8_t> raw,
                 container::Compression c, uint32_t frames) {
  PeerRow r;
  r.stream = stream;
  r.method = method;
  r.raw_bytes = raw.size();
  container::CompressionOptions levels;
  levels.zstd_level = 19;  // zstd -19
  levels.lzma_preset = 9;  // xz -9
  const double t0 = now_seconds();
  auto stored = container::compress_chunk(raw, c, levels);
  r.encode_s = now_seconds() - t0;
  if (!stored.ok()) {
    r.note = stored.status().to_string();
    return r;
  }
  r.bytes = stored->bytes.size();
  std::vector<uint8_t> back(raw.size());
  double best = std::numeric_limits<double>::infinity();
  for (int run = 0; run < 3; ++run) {
    const double d0 = now_seconds();
    if (Status s = container::decompress_chunk(stored->bytes, c, back); !s.ok()) {
      r.note = s.to_string();
      return r;
    }
    best = std::min(best, now_seconds() - d0);
  }
  r.available = true;
  r.decode_ms_per_frame = 1e3 * best / frames;
  r.quality = std::equal(back.begin(), back.end(), raw.begin()) ? "exact" : "DIFFERS";
  return r;
}

// xz -9 and zstd -19 of one stream. Both coders are single-threaded, so they run side by side
// on two threads: the machine has two cores and the run's wall time halves; each one's
// seconds are still its own call's.
struct RawPair {
  PeerRow xz, zstd;
};
RawPair raw_peers_in_parallel(const std::string& stream, std::span<const uint8_t> raw,
                              uint32_t frames) {
  RawPair r;
  std::thread xz([&] {
    r.xz = raw_peer(stream, "xz -9 (liblzma LZMA2 preset 9)", raw, container::Compression::kLzma2,
                    frames);
  });
  r.zstd =
      raw_peer(stream, "zstd -19 (libzstd level 19)", raw, container::Compression::kZstd, frames);
  xz.join();
  return r;
}

PeerRow ffmpeg_row(const std::string& stream, const PeerResult& p, uint64_t raw_bytes) {
  PeerRow r;
  r.stream = stream;
  r.method = p.method;
  r.available = p.available;
  r.bytes = p.bytes;
  r.raw_bytes = raw_bytes;
  r.encode_s = p.encode_s;
  r.decode_ms_per_frame = p.decode_ms_per_frame;
  r.marginal_ms_per_frame = p.marginal_ms_per_frame;
  r.note = p.note;
  if (p.available) {
    r.quality = p.crf >= 0
                    ? fmt::format("{:.2f} dB (CRF {:.2f}, {} encodes)", p.psnr_db, p.crf, p.encodes)
                    : (p.exact ? "exact" : "DIFFERS");
  }
  return r;
}

PeerRow skipped(const std::string& stream, const std::string& method, const std::string& why) {
  PeerRow r;
  r.stream = stream;
  r.method = method;
  r.note = why;
  return r;
}

}  // namespace

Expected<std::vector<PeerRow>> measure_peers(const fs::path& capture_dir, const CalfReference& calf,
                                             const PeerSettings& settings, std::string* notes) {
  CALF_ASSIGN_OR_RETURN(capture::CaptureSetReader in, capture::CaptureSetReader::open(capture_dir));
  CALF_ASSIGN_OR_RETURN(GridFrames g, capture_grid(in));
  CALF_ASSIGN_OR_RETURN(DecodedClip decoded, decode_clip(calf.base_clip, g));
  CALF_ASSIGN_OR_RETURN(const DecodeTiming full_decode, calf_full_decode_ms(calf.base_clip));
  const size_t frame_bytes = size_t{g.width} * g.height * 3;
  const double calf_psnr = mean_psnr_db(g.rgb, decoded.rgb, frame_bytes, g.frames);
  const uint64_t raw_depth = g.depth.size() * 2, raw_rgb = g.rgb.size();

  *notes = fmt::format(
      "Peer input: {} frames of {}×{} (a row of 6 faces per view, {} views of {}²); depth as "
      "log-16 codes (per-view range over all frames, raw {} bytes){}; colour as 8-bit sRGB "
      "(raw {} bytes; calf's raw colour stream as the encoder counts it: {} bytes). calf's "
      "colour PSNR against those frames: {:.2f} dB (mean per frame, peak 255), the target of the "
      "x265 colour peer. calf decode: LightfieldDecoder::advance over the whole clip (every view, "
      "cell and tile, no culling), colour and depth together: median {:.2f} ms/frame of frames "
      "2..{}, frame 1 {:.2f} ms; calf's encode s is the whole clip's (colour, depth and material "
      "together). Raw-stream peers: fastest of 3 decodes; ffmpeg peers: fastest of 3 decodes "
      "including ffmpeg's start-up, 'marginal' without it; the x265 colour peer's encode s is its "
      "final encode at the chosen CRF (the bisection's other encodes not counted).",
      g.frames, g.width, g.height, g.views, g.face, raw_depth,
      decoded.depth_mismatches < 0 ? ""
      : decoded.depth_mismatches == 0
          ? ", identical code for code to the base clip's decoded depth"
          : fmt::format(", differing from the base clip's decoded depth in {} codes",
                        decoded.depth_mismatches),
      raw_rgb, calf.base.colour_raw, calf_psnr, full_decode.median_ms, g.frames,
      full_decode.first_ms);

  std::vector<PeerRow> rows;
  auto calf_row = [&](const std::string& stream, const std::string& method, uint64_t bytes,
                      uint64_t raw, double encode_s, double decode_ms, const std::string& q) {
    PeerRow r;
    r.stream = stream;
    r.method = method;
    r.available = true;
    r.bytes = bytes;
    r.raw_bytes = raw;
    r.encode_s = encode_s;
    r.decode_ms_per_frame = decode_ms;
    r.quality = q;
    rows.push_back(r);
  };
  const std::string depth_quality = decoded.depth_mismatches == 0  ? "exact"
                                    : decoded.depth_mismatches < 0 ? "lossy"
                                                                   : "DIFFERS";
  calf_row("depth", "calf " + calf.base_label, calf.base.depth_bytes, raw_depth, calf.base.encode_s,
           full_decode.median_ms, depth_quality);
  for (const auto& e : calf.extra) {
    if (e.stream == "depth")
      calf_row("depth", "calf " + e.method, e.bytes, raw_depth, e.encode_s, -1, "");
  }
  {
    const RawPair depth = raw_peers_in_parallel("depth", bytes_of(g.depth), g.frames);
    rows.push_back(depth.xz);
    rows.push_back(depth.zstd);
  }
  if (settings.ffmpeg) {
    rows.push_back(
        ffmpeg_row("depth", ffv1_depth(g.depth, g.width, g.height, g.frames), raw_depth));
    rows.push_back(ffmpeg_row(
        "depth", x265_lossless_depth(g.depth, g.width, g.height, g.frames, settings.x265_preset),
        raw_depth));
  } else {
    rows.push_back(skipped("depth", "ffmpeg FFV1 / x265 lossless", "skipped (--no-ffmpeg)"));
  }

  calf_row("colour", "calf " + calf.base_label, calf.base.colour_bytes, raw_rgb, calf.base.encode_s,
           full_decode.median_ms, fmt::format("{:.2f} dB", calf_psnr));
  for (const auto& e : calf.extra) {
    if (e.stream == "colour")
      calf_row("colour", "calf " + e.method, e.bytes, raw_rgb, e.encode_s, -1, "");
  }
  {
    const RawPair colour = raw_peers_in_parallel("colour", g.rgb, g.frames);
    rows.push_back(colour.xz);
    rows.push_back(colour.zstd);
  }
  if (settings.ffmpeg) {
    rows.push_back(ffmpeg_row("colour",
                              x265_colour_matched(g.rgb, g.width, g.height, g.frames, calf_psnr,
                                                  settings.colour_tolerance_db, "auto",
                                                  settings.x265_preset, 3, settings.x265_params),
                              raw_rgb));
  } else {
    rows.push_back(skipped("colour", "ffmpeg x265 at matched PSNR", "skipped (--no-ffmpeg)"));
  }
  for (PeerRow& r : rows) {
    r.calf_bytes = r.stream == "depth" ? calf.base.depth_bytes : calf.base.colour_bytes;
  }
  return rows;
}

Expected<std::vector<ColourMatch>> match_colour_to_x265(const fs::path& capture_dir,
                                                        std::span<const ColourClip> clips,
                                                        const PeerSettings& settings) {
  CALF_ASSIGN_OR_RETURN(capture::CaptureSetReader in, capture::CaptureSetReader::open(capture_dir));
  CALF_ASSIGN_OR_RETURN(GridFrames g, capture_grid(in));
  const size_t frame_bytes = size_t{g.width} * g.height * 3;
  std::vector<ColourMatch> out;
  for (const ColourClip& c : clips) {
    ColourMatch m;
    m.calf = c;
    CALF_ASSIGN_OR_RETURN(DecodedClip decoded, decode_clip(c.clip, g));
    m.psnr_db = mean_psnr_db(g.rgb, decoded.rgb, frame_bytes, g.frames);
    CALF_ASSIGN_OR_RETURN(DecodeTiming timing, calf_full_decode_ms(c.clip));
    m.decode_ms = g.frames > 1 ? timing.median_ms : 0;
    m.upload_bytes = timing.mean_update_bytes;
    CALF_ASSIGN_OR_RETURN(container::Reader reader, container::Reader::open(c.clip.string()));
    decoder::LightfieldDecoderOptions o;
    o.view_dependent = false;
    // Seeks: after frame 0, jumps backwards from the last frame to frame 1 (each a restart at
    // its GOP's key frame), then forwards by two.
    {
      CALF_ASSIGN_OR_RETURN(decoder::LightfieldDecoder d,
                            decoder::LightfieldDecoder::open(reader, 0, o));
      decoder::LightfieldFrameUpdates updates;
      CALF_RETURN_IF_ERROR(d.advance(0, {}, {}, &updates));
      std::vector<uint32_t> jumps;
      for (uint32_t f = g.frames; f-- > 1;) jumps.push_back(f);
      for (uint32_t f = 2; f < g.frames; f += 2) jumps.push_back(f);
      double sum = 0;
      for (uint32_t f : jumps) {
        CALF_RETURN_IF_ERROR(d.advance(f, {}, {}, &updates));
        sum += updates.stats.decode_ms;
        m.seek_max_units = std::max(m.seek_max_units, updates.stats.av1_max_pictures_per_cell);
      }
      m.seek_ms = jumps.empty() ? 0 : sum / static_cast<double>(jumps.size());
    }
    m.x265 = x265_colour_matched(g.rgb, g.width, g.height, g.frames, m.psnr_db,
                                 settings.colour_tolerance_db, settings.x265_pix_fmt,
                                 settings.x265_preset, 3, settings.x265_params);
    out.push_back(std::move(m));
  }
  return out;
}

}  // namespace calf::bench
