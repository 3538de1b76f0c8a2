// Paper 002 Table 1 for the lightfield track: for each capture set, the bytes of the colour and
// depth streams at each stage of the encoder (raw, temporal, +spatial (BCn), +zstd, +LZMA2) and
// their ratios to raw, taken from the encoder's own per-stream accounting
// (encoder::LightfieldEncodeStats), plus, in the same run, general-purpose peers on the raw
// streams: `xz -9` and `zstd -19` of the raw colour stream (RGBA8 sRGB for LDR input, RGBA16F for
// HDR, as encoder::StreamBytes::raw counts it) and of the raw log-16 depth stream (per-view z_near
// / z_far from the data, as the encoder quantises). Also encode seconds and peak RSS (getrusage).
// Prints markdown.
//
// With --depth-format pred16 (pred16m) the depth column is the predicted coding (format r16p,
// r16pm). Unless the
// run is the encoder without predicted depth (raw16 and --depth-fixed-groups), one more zstd encode
// with raw16 depth and one chunk per K frames gives those depth bytes beside it, "today's" of the
// issue. --no-colour-peers skips the colour peers (most of the run's time on noisy colour) when
// only depth is being measured; --no-lzma2 skips the LZMA2 encode.
//
// The paper's own accounting is printed beside it: raw colour as 24-bit RGB and raw depth as
// 32-bit float per texel, and calf's stored bytes as ratios to those.
//
// --video-peers adds calf-bench's peer set (tests/bench/calf_bench/peers.h, docs/BENCH.md "The
// peers") on the same capture against the zstd clip: ffmpeg FFV1 and x265 lossless on the log-16
// depth, x265 on 8-bit sRGB colour at the PSNR calf's decoded colour reaches against the same
// frames, and xz -9 / zstd -19 of those frames — Table 1's video-coder columns in the same run.
//
//   bench-lightfield_table1 --capture DIR [--capture DIR ...] [--threads N] [--psnr Q]
//       [--depth-format raw16|pred16|pred16m] [--depth-fixed-groups] [--no-colour-peers]
//       [--no-lzma2] [--video-peers [--x265-preset P] [--x265-params K=V:...]]
//       [--psnr-auto] [--av1-crf N ... [--av1-preset P] [--av1-keyframe-interval K]
//       [--av1-cell C] [--av1-chroma 420|444 ...] [--csv FILE] [--no-peer-table]
//       [--x265-pix-fmt F]]
//
// --av1-crf (with --video-peers) adds the AV1 colour mode (calf-encode --colour-codec av1) at each
// CRF: the BC clip and each AV1 clip are decoded, their colour's PSNR against the capture taken
// as the peer set takes it, and x265 matched to each; printed with bytes, ratio to x265, encode
// s, decode ms, uploaded bytes and seek cost per frame, and the capture's render noise estimate.
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include "calf/capture/capture_set.h"
#include "calf/encoder/lightfield_encode.h"
#include "calf/encoder/noise_estimate.h"
#include "calf/format/bc.h"
#include "calf/format/colour.h"
#include "calf/format/log_depth.h"
#include "calf_bench/peers.h"
#include "calf_bench/report.h"

namespace {

namespace fs = std::filesystem;
using namespace calf;

double now_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}
uint64_t peak_rss_kib(int who) {
  rusage u{};
  getrusage(who, &u);
  return static_cast<uint64_t>(u.ru_maxrss);
}
std::string bytes(uint64_t b) {
  return bench::grouped(b);
}
std::string ratio(uint64_t raw, std::optional<uint64_t> b) {
  if (!b || *b == 0) return "—";
  return fmt::format("{:.1f}×", static_cast<double>(raw) / static_cast<double>(*b));
}
std::string cell(std::optional<uint64_t> b) {
  return b ? bytes(*b) : "—";
}

// Writes the raw colour and log-16 depth streams of `dir` (view-major, frame, texel; colour RGBA
// interleaved; depth little-endian u16) to two files.
Status write_raw_streams(const capture::CaptureSetReader& in, bool hdr, const fs::path& colour_path,
                         const fs::path& depth_path) {
  std::ofstream colour(colour_path, std::ios::binary), depth(depth_path, std::ios::binary);
  const auto& m = in.manifest();
  capture::ViewFrame vf;
  std::vector<float> z;
  std::vector<uint8_t> buf;
  for (uint32_t v = 0; v < m.viewpoints.size(); ++v) {
    z.clear();
    float lo = std::numeric_limits<float>::infinity(), hi = 0;
    for (uint32_t f = 0; f < m.frame_count; ++f) {
      CALF_RETURN_IF_ERROR(in.read(v, f, &vf));
      const size_t n = vf.texel_count();
      buf.clear();
      for (size_t i = 0; i < n; ++i) {
        if (hdr) {
          for (int c = 0; c < 4; ++c) {
            const uint16_t h = c == 3 ? bc::float_to_half(1.0f)
                                      : bc::float_to_half(std::min(vf.color[3 * i + c], 65504.0f));
            buf.push_back(static_cast<uint8_t>(h & 0xff));
            buf.push_back(static_cast<uint8_t>(h >> 8));
          }
        } else {
          for (int c = 0; c < 3; ++c) buf.push_back(srgb8_from_linear(vf.color[3 * i + c]));
          buf.push_back(255);
        }
        const float d = vf.depth[i];
        z.push_back(d);
        if (std::isfinite(d)) {
          lo = std::min(lo, d);
          hi = std::max(hi, d);
        }
      }
      colour.write(reinterpret_cast<const char*>(buf.data()),
                   static_cast<std::streamsize>(buf.size()));
    }
    std::optional<LogDepthRange> range;
    if (hi > 0) {
      CALF_ASSIGN_OR_RETURN(LogDepthRange r, LogDepthRange::covering(lo, hi));
      range = r;
    }
    buf.clear();
    for (float d : z) {
      const uint16_t code = range ? range->encode_unchecked(d) : kLog16Sky;
      buf.push_back(static_cast<uint8_t>(code & 0xff));
      buf.push_back(static_cast<uint8_t>(code >> 8));
    }
    depth.write(reinterpret_cast<const char*>(buf.data()),
                static_cast<std::streamsize>(buf.size()));
  }
  colour.close();
  depth.close();
  if (!colour || !depth) return Status(ErrorId::kFileWrite, "writing the raw streams failed");
  return Status::Ok();
}

bool have_tool(const char* name) {
  return std::system(fmt::format("command -v {} >/dev/null 2>&1", name).c_str()) == 0;
}

struct Peer {
  std::optional<uint64_t> size;
  double seconds = 0;
};
// Runs `tool args < file | wc -c` and returns the compressed size.
Peer run_peer(const std::string& tool_args, const fs::path& file) {
  Peer p;
  const std::string cmd = fmt::format("{} -c '{}' | wc -c", tool_args, file.string());
  const double t0 = now_s();
  FILE* pipe = popen(cmd.c_str(), "r");
  if (!pipe) return p;
  unsigned long long n = 0;
  const bool got = std::fscanf(pipe, "%llu", &n) == 1;
  const int rc = pclose(pipe);
  p.seconds = now_s() - t0;
  if (got && rc == 0) p.size = n;
  return p;
}

struct EncodeRun {
  encoder::LightfieldEncodeStats stats;
  double seconds = 0;
  uint64_t file_bytes = 0;
};
// The clip is removed afterwards unless `keep`.
Expected<EncodeRun> encode(const fs::path& capture, const fs::path& out,
                           const encoder::LightfieldEncodeOptions& o, bool keep = false) {
  EncodeRun r;
  const double t0 = now_s();
  CALF_ASSIGN_OR_RETURN(r.stats, encoder::encode_lightfield_file(capture, out.string(), o));
  r.seconds = now_s() - t0;
  r.file_bytes = fs::file_size(out);
  if (!keep) fs::remove(out);
  return r;
}

const char* format_name(uint16_t f) {
  using container::PixelFormat;
  switch (static_cast<PixelFormat>(f)) {
    case PixelFormat::kBc1:
      return "BC1";
    case PixelFormat::kBc5:
      return "BC5";
    case PixelFormat::kBc6h:
      return "BC6H";
    case PixelFormat::kBc7:
      return "BC7";
    case PixelFormat::kRgba8:
      return "RGBA8";
    case PixelFormat::kRgba16f:
      return "RGBA16F";
    case PixelFormat::kR16:
      return "raw16";
    case PixelFormat::kR16Predicted:
      return "pred16 (r16p)";
    case PixelFormat::kR16PredictedMasked:
      return "pred16m (r16pm)";
    default:
      return "?";
  }
}

struct Run {
  uint32_t threads = 0;
  double min_psnr_db = encoder::LightfieldEncodeOptions{}.min_psnr_db;  // calf-encode's --psnr
  bool have_xz = false, have_zstd = false, colour_peers = true;
  encoder::DepthCoding depth = encoder::DepthCoding::kRaw16;
  bool fixed_groups = false, lzma2 = true;
  bool video_peers = false;
  bench::PeerSettings peers;
  bool peer_table = true;  // false: --video-peers measures the colour codings' matches only
  bool psnr_auto = false;  // Q from the capture's noise estimate, as calf-encode --psnr auto
  // The AV1 colour mode beside BC (with --video-peers): one encode per CRF, each matched by x265.
  std::vector<uint32_t> av1_crfs;
  std::vector<std::string> av1_chromas = {"420"};  // each CRF at each (calf-encode --av1-chroma)
  encoder::Av1ColourOptions av1;
  uint32_t av1_cell = 64;
  std::string csv;  // append one line per colour coding matched by x265 (empty: none)
};

std::string noise_text(const encoder::NoiseEstimate& e, encoder::NoiseMetric metric) {
  if (!e.psnr_db) return fmt::format("none ({} samples)", e.samples);
  return fmt::format("{:.2f} dB {}", *e.psnr_db,
                     metric == encoder::NoiseMetric::kLog2 ? "log2-PSNR" : "sRGB PSNR");
}

// The colour codings side by side, each against x265 at the PSNR it reaches.
void print_matches(const std::string& scene, const capture::CaptureManifest& m,
                   const std::optional<encoder::CaptureNoise>& noise,
                   const std::vector<bench::ColourMatch>& rows, const std::string& error,
                   const Run& run) {
  fmt::print(
      "Colour codings against x265 ({}, {}{}{}) at matched PSNR: PSNR of each "
      "decoding's 8-bit sRGB frames against the capture's (mean per frame); render noise of the "
      "capture (frame-to-frame, the keyframe test's metric): {}. Decode: LightfieldDecoder::"
      "advance, every cell of every view, median ms of frames 2..{} in order; uploaded: mean "
      "texture bytes a frame; seek: mean ms of a jump (last frame down to 1, then forwards by "
      "2) and the most AV1 pictures one cell decoded for a jump.\n\n",
      run.peers.x265_pix_fmt == "auto" ? std::string("8-bit 4:4:4 or RGB") : run.peers.x265_pix_fmt,
      run.peers.x265_preset, run.peers.x265_params.empty() ? "" : ", ", run.peers.x265_params,
      noise ? noise_text(noise->set, noise->metric) : std::string("not measured"), m.frame_count);
  if (!error.empty()) {
    fmt::print("- failed: {}\n\n", error);
    return;
  }
  fmt::print(
      "| colour coding | bytes | PSNR | x265 bytes | x265 PSNR (CRF) | × x265 | encode s | decode "
      "ms/frame | uploaded bytes/frame | seek ms (pictures) |\n");
  fmt::print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
  std::FILE* csv = run.csv.empty() ? nullptr : std::fopen(run.csv.c_str(), "a");
  for (const bench::ColourMatch& r : rows) {
    const bool x = r.x265.available || r.x265.bytes > 0;
    fmt::print(
        "| {} | {} | {:.2f} dB | {} | {} | {} | {:.2f} | {:.2f} | {} | {:.2f} ({}) |\n",
        r.calf.label, bytes(r.calf.colour_bytes), r.psnr_db,
        x ? bytes(r.x265.bytes) : std::string("—"),
        x ? fmt::format("{:.2f} dB ({:.2f})", r.x265.psnr_db, r.x265.crf) : "n/a: " + r.x265.note,
        x && r.x265.bytes ? fmt::format("{:.2f}", static_cast<double>(r.calf.colour_bytes) /
                                                      static_cast<double>(r.x265.bytes))
                          : std::string("—"),
        r.calf.encode_s, r.decode_ms, bytes(static_cast<uint64_t>(r.upload_bytes)), r.seek_ms,
        r.seek_max_units);
    if (csv) {
      std::string label = r.calf.label;
      std::replace(label.begin(), label.end(), ',', ';');
      fmt::print(csv, "{},{},{},{},{:.4f},{},{:.4f},{:.0f},{:.3f},{:.3f}\n", scene, m.face_size,
                 m.viewpoints.size(), label, r.psnr_db, r.calf.colour_bytes, r.x265.psnr_db,
                 static_cast<double>(r.x265.bytes), r.calf.encode_s, r.decode_ms);
    }
  }
  if (csv) std::fclose(csv);
  for (const bench::ColourMatch& r : rows) {
    if (!r.x265.note.empty() && r.x265.available) {
      fmt::print("- x265 beside {}: {}\n", r.calf.label, r.x265.note);
    }
  }
  fmt::print("\n");
  std::fflush(stdout);
}

int run_one(const fs::path& dir, const Run& run) {
  const uint32_t threads = run.threads;
  const bool have_xz = run.have_xz, have_zstd = run.have_zstd;
  auto in = capture::CaptureSetReader::open(dir);
  if (!in.ok()) {
    fmt::print(stderr, "{}: {}\n", dir.string(), in.status().to_string());
    return 1;
  }
  const auto& m = in->manifest();
  // The render noise of the capture (the keyframe test's metric), which --psnr-auto sets Q from.
  std::optional<encoder::CaptureNoise> noise;
  double min_psnr_db = run.min_psnr_db;
  if (run.psnr_auto || !run.av1_crfs.empty()) {
    encoder::NoiseEstimateOptions no;
    no.threads = threads;
    auto n = encoder::estimate_capture_noise(*in, encoder::ColourCoding::kAuto, no);
    if (!n.ok()) {
      fmt::print(stderr, "{}: {}\n", dir.string(), n.status().to_string());
      return 1;
    }
    noise = *n;
    if (run.psnr_auto) {
      min_psnr_db = encoder::auto_psnr_db(noise->set, encoder::kDefaultPsnrNoiseMargin);
    }
  }
  const fs::path tmp = fs::temp_directory_path() / fmt::format("calf-table1-{}", ::getpid());
  fs::create_directories(tmp);
  const fs::path zstd_clip = tmp / "zstd.calf";
  const bool merge = !run.fixed_groups;
  // The options of one encode: the run's, with this supercompression and depth layout.
  auto options = [&](container::Compression sc, encoder::DepthCoding depth,
                     bool merge_static_groups) {
    encoder::LightfieldEncodeOptions o;
    o.threads = threads;
    o.min_psnr_db = min_psnr_db;
    o.depth = depth;
    o.merge_static_groups = merge_static_groups;
    o.supercompression = sc;
    return o;
  };
  auto z = encode(dir, zstd_clip, options(container::Compression::kZstd, run.depth, merge),
                  run.video_peers);
  const uint64_t rss_after_zstd = peak_rss_kib(RUSAGE_SELF);
  Status failed = z.status();
  std::optional<EncodeRun> x;
  if (failed.ok() && run.lzma2) {
    auto r =
        encode(dir, tmp / "lzma2.calf", options(container::Compression::kLzma2, run.depth, merge));
    failed = r.status();
    if (r.ok()) x = *r;
  }
  // The depth bytes without predicted depth or static groups (raw16, one chunk per K frames).
  std::optional<EncodeRun> before;
  if (failed.ok() && (run.depth != encoder::DepthCoding::kRaw16 || merge)) {
    auto r = encode(dir, tmp / "before.calf",
                    options(container::Compression::kZstd, encoder::DepthCoding::kRaw16, false));
    failed = r.status();
    if (r.ok()) before = *r;
  }
  const uint64_t rss_after_lzma = peak_rss_kib(RUSAGE_SELF);
  if (!failed.ok()) {
    fmt::print(stderr, "{}: {}\n", dir.string(), failed.to_string());
    fs::remove_all(tmp);
    return 1;
  }
  const encoder::LightfieldEncodeStats& s = z->stats;
  const encoder::LightfieldEncodeStats none;
  const encoder::LightfieldEncodeStats& sx = x ? x->stats : none;
  auto lz = [&](uint64_t v) { return x ? std::optional<uint64_t>(v) : std::nullopt; };

  // Peers on the raw streams.
  Peer xz_c, xz_d, zs_c, zs_d;
  std::string raw_note;
  const fs::path rc = tmp / "colour.raw", rd = tmp / "depth.raw";
  Status st = write_raw_streams(*in, s.hdr, rc, rd);
  if (!st.ok()) {
    raw_note = "raw streams not written: " + st.to_string();
  } else {
    if (fs::file_size(rc) != s.colour.raw || fs::file_size(rd) != s.depth.raw) {
      raw_note = fmt::format("note: raw files {} / {} bytes differ from the encoder's raw counts",
                             fs::file_size(rc), fs::file_size(rd));
    }
    if (have_xz) {
      if (run.colour_peers) xz_c = run_peer("xz -9 -T1", rc);
      xz_d = run_peer("xz -9 -T1", rd);
    }
    if (have_zstd) {
      if (run.colour_peers) zs_c = run_peer("zstd -19 -q -T1", rc);
      zs_d = run_peer("zstd -19 -q -T1", rd);
    }
  }
  // calf-bench's peer set on the same capture, against the zstd clip.
  std::vector<bench::PeerRow> video_peers;
  std::string video_notes;
  if (run.video_peers && run.peer_table) {
    bench::CalfReference ref;
    ref.base_clip = zstd_clip;
    ref.base.colour_bytes = s.colour.stored;
    ref.base.depth_bytes = s.depth.stored;
    ref.base.colour_raw = s.colour.raw;
    ref.base.depth_raw = s.depth.raw;
    ref.base.encode_s = z->seconds;
    ref.base_label =
        fmt::format("{} + {} + zstd", format_name(s.colour_format), format_name(s.depth_format));
    const double t0 = now_s();
    auto rows = bench::measure_peers(dir, ref, run.peers, &video_notes);
    if (rows.ok()) {
      video_peers = std::move(*rows);
      video_notes += fmt::format(" Peer set measured in {:.0f} s.", now_s() - t0);
    } else {
      video_notes = "video peers failed: " + rows.status().to_string();
    }
  }
  // BC and the AV1 mode at each CRF, each against x265 at the PSNR it reaches.
  std::vector<bench::ColourMatch> matches;
  std::string match_error;
  if (run.video_peers && !run.av1_crfs.empty()) {
    std::vector<bench::ColourClip> clips;
    clips.push_back({fmt::format("{} Q {:.2f}", format_name(s.colour_format), min_psnr_db),
                     zstd_clip, s.colour.stored, z->seconds});
    for (const std::string& chroma : run.av1_chromas) {
      for (uint32_t crf : run.av1_crfs) {
        encoder::LightfieldEncodeOptions o =
            options(container::Compression::kZstd, run.depth, merge);
        o.colour = encoder::ColourCoding::kAv1;
        o.cell_size = run.av1_cell;
        o.av1 = run.av1;
        o.av1.crf = crf;
        o.av1.chroma444 = chroma == "444";
        const fs::path clip = tmp / fmt::format("av1_{}_{}.calf", chroma, crf);
        auto r = encode(dir, clip, o, true);
        if (!r.ok()) {
          match_error = r.status().to_string();
          break;
        }
        clips.push_back({fmt::format("AV1 {} CRF {}, preset {}, cell {}, K {}",
                                     o.av1.chroma444 ? "4:4:4" : "4:2:0", crf, run.av1.preset,
                                     run.av1_cell, run.av1.keyframe_interval),
                         clip, r->stats.colour.stored, r->seconds});
      }
    }
    if (match_error.empty()) {
      auto mr = bench::match_colour_to_x265(dir, clips, run.peers);
      if (mr.ok()) {
        matches = std::move(*mr);
      } else {
        match_error = mr.status().to_string();
      }
    }
  }
  fs::remove_all(tmp);

  const std::string scene = m.scene.empty() ? dir.filename().string() : m.scene;
  fmt::print("### {} — {} views × {} frames, face {}, cell 64, {} input\n\n", scene,
             m.viewpoints.size(), m.frame_count, m.face_size, s.hdr ? "HDR" : "LDR");
  fmt::print(
      "Capture `{}`; colour {} (raw = {}), Q {} dB, depth {} (raw = log-16 u16); threads {}.\n\n",
      dir.string(), format_name(s.colour_format), s.hdr ? "RGBA16F" : "RGBA8 sRGB", min_psnr_db,
      format_name(s.depth_format), threads);
  fmt::print("| stage | colour bytes | colour ratio | depth bytes | depth ratio |\n");
  fmt::print("|---|---:|---:|---:|---:|\n");
  auto row = [&](const char* name, std::optional<uint64_t> c, std::optional<uint64_t> d) {
    fmt::print("| {} | {} | {} | {} | {} |\n", name, cell(c), ratio(s.colour.raw, c), cell(d),
               ratio(s.depth.raw, d));
  };
  row("raw", s.colour.raw, s.depth.raw);
  row("temporal (keyframes / P-frames)", s.colour.temporal, s.depth.temporal);
  row("+spatial (BCn)", s.colour.spatial, s.depth.spatial);
  row("+zstd (level 19, per chunk)", s.colour.stored, s.depth.stored);
  row("+LZMA2 (preset 6, per chunk)", lz(sx.colour.stored), lz(sx.depth.stored));
  if (before) {
    row("+zstd, depth raw16, one chunk per K frames", {}, before->stats.depth.stored);
  }
  row("peer: `zstd -19` of raw", zs_c.size, zs_d.size);
  row("peer: `xz -9` of raw", xz_c.size, xz_d.size);
  fmt::print("\n");
  if (!have_xz) fmt::print("- `xz` not installed: peer skipped.\n");
  if (!have_zstd) fmt::print("- `zstd` not installed: peer skipped.\n");
  if (!raw_note.empty()) fmt::print("- {}\n", raw_note);
  // Paper 002 Table 1's accounting: colour 24-bit RGB, depth 32-bit float per texel.
  const uint64_t texels =
      uint64_t{m.face_size} * m.face_size * 6 * m.viewpoints.size() * m.frame_count;
  auto paper = [](uint64_t raw, uint64_t b) {
    return b ? fmt::format("{:.1f}×", static_cast<double>(raw) / static_cast<double>(b)) : "—";
  };
  fmt::print(
      "- the paper's accounting (raw colour 24-bit RGB = {} bytes, raw depth 32-bit float = {} "
      "bytes): calf +zstd colour {}, depth {}; +LZMA2 colour {}, depth {}\n",
      bytes(texels * 3), bytes(texels * 4), paper(texels * 3, s.colour.stored),
      paper(texels * 4, s.depth.stored), paper(texels * 3, sx.colour.stored),
      paper(texels * 4, sx.depth.stored));
  auto times = [](uint64_t a, std::optional<uint64_t> b) {
    return b && *b ? fmt::format("{:.2f}×", static_cast<double>(a) / static_cast<double>(*b))
                   : std::string("—");
  };
  fmt::print("- depth +zstd: {} of `xz -9` of raw, {} of depth raw16 in chunks of K frames\n",
             times(s.depth.stored, xz_d.size),
             times(s.depth.stored,
                   before ? std::optional<uint64_t>(before->stats.depth.stored) : std::nullopt));
  fmt::print(
      "- encode: {:.2f} s ({:.2f} Mpix/s) zstd, {} LZMA2; file {} / {} bytes; peak RSS {:.1f} "
      "MiB after the zstd encode, {:.1f} MiB after all encodes (process peak, includes reading "
      "the raw streams later: {:.1f} MiB)\n",
      z->seconds, z->seconds > 0 ? static_cast<double>(texels) / 1e6 / z->seconds : 0.0,
      x ? fmt::format("{:.2f} s", x->seconds) : std::string("not run"), bytes(z->file_bytes),
      x ? bytes(x->file_bytes) : std::string("—"), rss_after_zstd / 1024.0, rss_after_lzma / 1024.0,
      peak_rss_kib(RUSAGE_SELF) / 1024.0);
  fmt::print(
      "- peers: zstd -19 {:.2f} s + {:.2f} s, xz -9 {:.2f} s + {:.2f} s (colour + depth); "
      "largest child peak RSS {:.1f} MiB\n",
      zs_c.seconds, zs_d.seconds, xz_c.seconds, xz_d.seconds,
      peak_rss_kib(RUSAGE_CHILDREN) / 1024.0);
  fmt::print(
      "- colour: {} cells, {} keyframes of {} cell-frames, min temporal quality {:.1f} dB; "
      "depth: {} tiles, {} keyframes, {} P-frames ({} empty); index {} bytes\n",
      s.colour_cells, s.colour_keyframes, s.colour_cells * m.frame_count, s.min_colour_quality_db,
      s.depth_regions, s.depth_keyframes, s.depth_pframes, s.depth_empty_pframes,
      bytes(s.index_bytes));
  // What no stream column counts: the file's header, directory and padding (SPEC §4, §7), per
  // chunk; container 1.1 compresses the directory (docs/ENCODER.md "Compressed directory").
  const uint64_t chunks =
      s.colour.chunks + s.depth.chunks + s.material.chunks + m.viewpoints.size();
  const uint64_t payload = s.colour.stored + s.depth.stored + s.material.stored + s.index_bytes;
  if (z->file_bytes >= payload) {
    fmt::print(
        "- container: {} bytes of header, directory and padding beside {} chunks ({:.1f} "
        "bytes per chunk, {:.2f} % of the file)\n",
        bytes(z->file_bytes - payload), chunks,
        chunks ? static_cast<double>(z->file_bytes - payload) / chunks : 0.0,
        100.0 * static_cast<double>(z->file_bytes - payload) / z->file_bytes);
  }
  if (s.material_views > 0) {
    fmt::print("- material ({} views, {}): raw {}, temporal {}, +spatial {}, +zstd {}, +LZMA2 {}\n",
               s.material_views, format_name(s.material_format), bytes(s.material.raw),
               bytes(s.material.temporal), bytes(s.material.spatial), bytes(s.material.stored),
               x ? bytes(sx.material.stored) : std::string("—"));
  } else {
    fmt::print("- material: none (no view sees a reflective or refractive texel)\n");
  }
  fmt::print("\n");
  if (run.video_peers && run.peer_table) {
    fmt::print("Video peers (calf-bench's peer set, docs/BENCH.md \"The peers\"): {}\n\n",
               video_notes);
    if (!video_peers.empty()) fmt::print("{}\n", bench::peer_table(video_peers));
  }
  if (!run.av1_crfs.empty() && run.video_peers)
    print_matches(scene, m, noise, matches, match_error, run);
  std::fflush(stdout);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "Paper 002 Table 1 for the lightfield track of each capture set, with xz / zstd peers"};
  std::vector<std::string> captures;
  Run run;
  std::string depth = "pred16m";
  bool no_colour_peers = false;
  app.add_option("--capture", captures, "capture-set directory (repeatable)")->required();
  app.add_option("--threads", run.threads, "encoder threads, 0 = all cores (default 0)");
  app.add_option("--psnr", run.min_psnr_db,
                 "Q: calf-encode's --psnr, the dB every interpolated colour frame keeps (default "
                 "50)")
      ->check(CLI::Range(1e-3, 200.0));
  app.add_option("--depth-format", depth,
                 "depth coding: pred16m (calf-encode's default), pred16 or raw16; with either "
                 "predicted coding raw16's zstd bytes are printed beside it (default pred16m)")
      ->check(CLI::IsMember({"raw16", "pred16", "pred16m"}));
  app.add_flag("--depth-fixed-groups", run.fixed_groups,
               "one depth chunk per K frames even where a tile does not change (calf-encode's "
               "option; default off)");
  bool no_lzma2 = false;
  app.add_flag("--no-lzma2", no_lzma2, "skip the LZMA2 encode (default: run it)");
  app.add_flag("--no-colour-peers", no_colour_peers,
               "skip xz / zstd on the raw colour stream (default: run them)");
  app.add_flag("--video-peers", run.video_peers,
               "also measure calf-bench's peer set on each capture against the zstd clip: ffmpeg "
               "FFV1 and x265 lossless on the log-16 depth, x265 on 8-bit sRGB colour at the PSNR "
               "calf's decoded colour reaches, xz -9 / zstd -19 of the same frames (default off)");
  app.add_option("--x265-preset", run.peers.x265_preset,
                 "x265 preset of the video peers (default medium)");
  app.add_option("--x265-params", run.peers.x265_params,
                 "further x265 parameters of the colour peer, key=value:key=value (default none); "
                 "keyint=1 makes it intra-only, each frame decodable alone as each calf frame is");
  bool no_peer_table = false;
  app.add_flag("--no-peer-table", no_peer_table,
               "with --video-peers and --av1-crf: only the colour codings against x265, not the "
               "peer set's table (default: both)");
  app.add_flag("--psnr-auto", run.psnr_auto,
               "Q from the capture's render noise estimate, as calf-encode --psnr auto (margin 3 "
               "dB); overrides --psnr (default off)");
  app.add_option("--x265-pix-fmt", run.peers.x265_pix_fmt,
                 "pixel format of x265 in the colour codings' matches: auto (yuv444p, else gbrp) "
                 "or an ffmpeg pix_fmt, e.g. yuv420p (default auto)");
  app.add_option("--av1-crf", run.av1_crfs,
                 "with --video-peers: also encode the AV1 colour mode at this CRF (repeatable) and "
                 "set BC and each AV1 encode against x265 at matched PSNR (default none)")
      ->check(CLI::Range(1, 63));
  app.add_option("--av1-preset", run.av1.preset,
                 "SVT-AV1 preset (libaom cpu-used for 4:4:4) of those encodes (default 5, "
                 "calf-encode's)")
      ->check(CLI::Range(0, 13));
  app.add_option("--av1-chroma", run.av1_chromas,
                 "their chroma, 420 (SVT-AV1) or 444 (libaom), each CRF at each given "
                 "(repeatable; default 420)")
      ->check(CLI::IsMember({"420", "444"}));
  app.add_option("--av1-keyframe-interval", run.av1.keyframe_interval,
                 "their key frame interval (default 30)")
      ->check(CLI::Range(1, 100000));
  app.add_option("--av1-cell", run.av1_cell,
                 "their colour cell size, one AV1 stream per cell (default 64)");
  app.add_option("--csv", run.csv,
                 "append one line per colour coding matched by x265: scene, face, views, coding, "
                 "PSNR, bytes, x265 PSNR, x265 bytes, encode s, decode ms (default none)");
  CLI11_PARSE(app, argc, argv);
  run.depth = depth == "pred16"    ? encoder::DepthCoding::kRaw16Predicted
              : depth == "pred16m" ? encoder::DepthCoding::kRaw16PredictedMasked
                                   : encoder::DepthCoding::kRaw16;
  run.colour_peers = !no_colour_peers;
  run.peer_table = !no_peer_table;
  run.lzma2 = !no_lzma2;
  run.have_xz = have_tool("xz");
  run.have_zstd = have_tool("zstd");
  int rc = 0;
  for (const auto& c : captures) rc |= run_one(c, run);
  return rc;
}
