// ffmpeg peers for the benchmarks (DESIGN.md "Measuring": FFV1 and x265 lossless for depth, x265
// at matched PSNR for colour), measured in the same run on the same data as calf.
//
// Each peer writes the frames to a raw file in a private temporary directory (mkdtemp, removed
// when the call returns), encodes them by running the `ffmpeg` command (posix_spawnp, no shell,
// stdin closed, stderr kept for the message on failure), decodes the result back with
// `ffmpeg -i FILE -f rawvideo -pix_fmt P -` into a pipe that this process reads to the end, and
//   - checks the round trip: lossless peers must give back every input bit (else `exact` is
//     false and the note says where they differ); the colour peer reports its PSNR;
//   - times the decode: wall time from spawn to exit, the minimum of `decode_runs` runs, divided
//     by the frame count. That includes ffmpeg's start-up (process, probing, codec init), so the
//     decode of the first frame alone (-frames:v 1) is timed the same way, and
//     (all - first) / (frames - 1) is reported as the marginal cost of a frame.
// When ffmpeg or the encoder is missing, or a run fails, the result has available = false and a
// note; nothing throws or exits. Benches print "n/a" for such a peer.
//
// Depth (paper 002 Table 2): frames of W x H log-16 codes (row-major u16, calf/format/log_depth.h).
//   - FFV1: gray16le, level 3, range coder with large contexts (-coder 1 -context 1), 4 slices,
//     every frame intra (FFV1 has no inter prediction). Lossless by construction.
//   - x265 lossless: x265 codes at most 12 bits a sample and has no 16-bit gray, so each code u is
//     spread over three 8-bit channels with the paper's bit swizzle (Sec. 7.1): bit i of u goes to
//     bit i / 3 of channel i mod 3 (channel 0 holds bits 0, 3, ..., 15; channels 1 and 2 five
//     bits each), so each channel is a coarse, smooth copy of the depth rather than noisy low
//     bits. The channels are coded as the Y, U, V planes of yuv444p with -x265-params lossless=1
//     (no colour conversion happens: the input already is yuv444p).
// Colour: frames of W x H 8-bit sRGB (rgb24, interleaved). x265 at the CRF that brings
//   the mean per-frame PSNR (RGB, peak 255, each frame capped at 100 dB so that an exact frame
//   does not make the mean infinite) within `tolerance_db` of a target, found by bisection of the
//   CRF over [0, 51]; pixel format yuv444p by default (no chroma subsampling: the strongest
//   peer against calf's full-resolution BCn colour), converted from RGB by ffmpeg (BT.601,
//   limited range), which caps the PSNR reachable near 50 dB; above that, gbrp (the RGB planes
//   coded directly) is used instead (x265_colour_matched, pix_fmt "auto").
#pragma once

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <vector>

extern char** environ;

namespace calf::bench {

// What one peer measured.
struct PeerResult {
  bool available = false;  // false: ffmpeg / the encoder missing or a run failed (see note)
  std::string method;      // e.g. "ffmpeg FFV1 gray16le"
  std::string note;        // why it is unavailable, or details worth printing
  uint64_t bytes = 0;      // compressed file size
  uint32_t frames = 0;
  double encode_s = 0;               // wall time of the (last) encode
  double decode_ms_per_frame = 0;    // min over decode runs of the decode wall time, per frame
  double first_frame_ms = 0;         // min over runs of decoding only the first frame (start-up)
  double marginal_ms_per_frame = 0;  // (all - first frame) / (frames - 1); 0 for one frame
  bool exact = false;                // lossless peers: decoded bits equal the input
  double psnr_db = 0;                // colour: mean per-frame PSNR of the decoded frames
  double crf = -1;                   // colour: the CRF chosen
  int encodes = 0;                   // colour: encodes the bisection needed
};

// ---------------------------------------------------------------------------------------------
// The paper's bit swizzle (Sec. 7.1), restricted to 16-bit codes.

// Bit i of u to bit i / 3 of c[i % 3].
inline void swizzle16(uint16_t u, uint8_t c[3]) {
  c[0] = c[1] = c[2] = 0;
  for (int i = 0; i < 16; ++i) c[i % 3] |= static_cast<uint8_t>(((u >> i) & 1u) << (i / 3));
}
// The inverse: bit i / 3 of c[i % 3] back to bit i.
inline uint16_t unswizzle16(const uint8_t c[3]) {
  uint32_t u = 0;
  for (int i = 0; i < 16; ++i) u |= ((c[i % 3] >> (i / 3)) & 1u) << i;
  return static_cast<uint16_t>(u);
}

namespace internal {

namespace fs = std::filesystem;

inline double now_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// A private temporary directory, removed with everything in it when this goes out of scope.
class TempDir {
 public:
  TempDir() {
    std::string pattern = (fs::temp_directory_path() / "calf-ffmpeg-XXXXXX").string();
    if (::mkdtemp(pattern.data()) != nullptr) path_ = pattern;
  }
  ~TempDir() {
    std::error_code ec;
    if (!path_.empty()) fs::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  bool ok() const { return !path_.empty(); }
  fs::path operator/(const std::string& name) const { return path_ / name; }

 private:
  fs::path path_;
};

struct ProcessResult {
  bool started = false;
  int exit_code = -1;        // -1 when killed by a signal or not started
  double seconds = 0;        // spawn to exit
  std::vector<uint8_t> out;  // stdout, when captured
  std::string error;         // last line of stderr, or why it did not start
};

inline std::string last_line(const fs::path& file) {
  std::ifstream in(file);
  std::string line, last;
  while (std::getline(in, line)) {
    if (!line.empty()) last = line;
  }
  return last;
}

// Runs argv[0] (searched on PATH) with stdin from /dev/null and stderr to `err_file`; stdout is
// read through a pipe into `out` when `capture` is true (else sent to /dev/null).
inline ProcessResult run(const std::vector<std::string>& args, bool capture,
                         const fs::path& err_file) {
  ProcessResult r;
  std::vector<char*> argv;
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  int fds[2] = {-1, -1};
  if (capture && ::pipe2(fds, O_CLOEXEC) != 0) {
    r.error = "pipe failed";
    return r;
  }
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 0, "/dev/null", O_RDONLY, 0);
  if (capture) {
    posix_spawn_file_actions_adddup2(&fa, fds[1], 1);
  } else {
    posix_spawn_file_actions_addopen(&fa, 1, "/dev/null", O_WRONLY, 0);
  }
  posix_spawn_file_actions_addopen(&fa, 2, err_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
  pid_t pid = 0;
  const double t0 = now_s();
  const int rc = ::posix_spawnp(&pid, argv[0], &fa, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&fa);
  if (capture) ::close(fds[1]);
  if (rc != 0) {
    if (capture) ::close(fds[0]);
    r.error = std::string("cannot run ") + args[0] + ": " + std::strerror(rc);
    return r;
  }
  r.started = true;
  if (capture) {
    uint8_t buf[1 << 16];
    for (;;) {
      const ssize_t n = ::read(fds[0], buf, sizeof buf);
      if (n > 0) {
        r.out.insert(r.out.end(), buf, buf + n);
      } else if (n == 0 || errno != EINTR) {
        break;
      }
    }
    ::close(fds[0]);
  }
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  r.seconds = now_s() - t0;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  if (r.exit_code != 0) {
    r.error = last_line(err_file);
    if (r.error.empty()) r.error = args[0] + " failed (exit " + std::to_string(r.exit_code) + ")";
  }
  return r;
}

inline bool write_file(const fs::path& path, const void* data, size_t size) {
  std::ofstream out(path, std::ios::binary);
  out.write(static_cast<const char*>(data), static_cast<std::streamsize>(size));
  return static_cast<bool>(out);
}

inline std::vector<std::string> ffmpeg_args(std::initializer_list<std::string> rest) {
  std::vector<std::string> a = {"ffmpeg", "-hide_banner", "-nostdin", "-loglevel", "error", "-y"};
  a.insert(a.end(), rest);
  return a;
}

// Decodes `file` to raw `pix_fmt` `runs` times (the first frame only when `first_only`); keeps
// the first run's bytes in `*out` and the fastest run's seconds in `*best_s`. Returns "" or the
// error.
inline std::string decode_timed(const fs::path& file, const std::string& pix_fmt, int runs,
                                bool first_only, const fs::path& err, std::vector<uint8_t>* out,
                                double* best_s) {
  *best_s = std::numeric_limits<double>::infinity();
  for (int i = 0; i < std::max(runs, 1); ++i) {
    std::vector<std::string> args = ffmpeg_args({"-i", file.string()});
    if (first_only) args.insert(args.end(), {"-frames:v", "1"});
    args.insert(args.end(), {"-f", "rawvideo", "-pix_fmt", pix_fmt, "-"});
    ProcessResult r = run(args, true, err);
    if (r.exit_code != 0) return "decode: " + r.error;
    *best_s = std::min(*best_s, r.seconds);
    if (i == 0) *out = std::move(r.out);
  }
  return "";
}

// Times the full decode and the first-frame decode of `file` into `p`; the full decode's bytes
// go to `*out`. Returns "" or the error.
inline std::string time_decodes(const fs::path& file, const std::string& pix_fmt, int runs,
                                const fs::path& err, std::vector<uint8_t>* out, PeerResult* p) {
  double all_s = 0, first_s = 0;
  std::vector<uint8_t> first;
  std::string e = decode_timed(file, pix_fmt, runs, false, err, out, &all_s);
  if (e.empty()) e = decode_timed(file, pix_fmt, runs, true, err, &first, &first_s);
  if (!e.empty()) return e;
  p->decode_ms_per_frame = all_s * 1000 / p->frames;
  p->first_frame_ms = first_s * 1000;
  p->marginal_ms_per_frame =
      p->frames > 1 ? std::max(0.0, all_s - first_s) * 1000 / (p->frames - 1) : 0.0;
  return "";
}

inline std::string size_arg(uint32_t w, uint32_t h) {
  return std::to_string(w) + "x" + std::to_string(h);
}

}  // namespace internal

// Whether `ffmpeg` runs and lists `encoder` (e.g. "ffv1", "libx265") among its encoders.
inline bool ffmpeg_has_encoder(const std::string& encoder) {
  internal::TempDir tmp;
  if (!tmp.ok()) return false;
  const internal::ProcessResult r =
      internal::run({"ffmpeg", "-hide_banner", "-nostdin", "-encoders"}, true, tmp / "err.txt");
  if (r.exit_code != 0) return false;
  const std::string text(r.out.begin(), r.out.end());
  return text.find(" " + encoder + " ") != std::string::npos;
}

// Lossless depth with FFV1: `codes` holds `frames` frames of w x h log-16 codes, row-major.
inline PeerResult ffv1_depth(std::span<const uint16_t> codes, uint32_t w, uint32_t h,
                             uint32_t frames, int decode_runs = 3) {
  PeerResult p;
  p.method = "ffmpeg FFV1 (gray16le, level 3, range coder)";
  p.frames = frames;
  if (codes.size() != size_t{w} * h * frames || codes.empty()) {
    p.note = "input size does not match w x h x frames";
    return p;
  }
  if (!ffmpeg_has_encoder("ffv1")) {
    p.note = "ffmpeg or its FFV1 encoder is not installed";
    return p;
  }
  internal::TempDir tmp;
  if (!tmp.ok()) {
    p.note = "mkdtemp failed";
    return p;
  }
  // gray16le: little-endian u16, which is how the codes sit in memory on every calf target
  // (DESIGN.md: little-endian); written byte by byte so that the file is right on any host.
  std::vector<uint8_t> raw(codes.size() * 2);
  for (size_t i = 0; i < codes.size(); ++i) {
    raw[2 * i] = static_cast<uint8_t>(codes[i] & 0xff);
    raw[2 * i + 1] = static_cast<uint8_t>(codes[i] >> 8);
  }
  const auto in = tmp / "in.raw", out = tmp / "out.mkv", err = tmp / "err.txt";
  if (!internal::write_file(in, raw.data(), raw.size())) {
    p.note = "writing the raw frames failed";
    return p;
  }
  const internal::ProcessResult enc = internal::run(
      internal::ffmpeg_args(
          {"-f",      "rawvideo", "-pix_fmt", "gray16le",  "-s",        internal::size_arg(w, h),
           "-r",      "24",       "-i",       in.string(), "-c:v",      "ffv1",
           "-level",  "3",        "-coder",   "1",         "-context",  "1",
           "-slices", "4",        "-g",       "1",         out.string()}),
      false, err);
  if (enc.exit_code != 0) {
    p.note = "encode: " + enc.error;
    return p;
  }
  p.encode_s = enc.seconds;
  p.bytes = std::filesystem::file_size(out);
  std::vector<uint8_t> back;
  const std::string e = internal::time_decodes(out, "gray16le", decode_runs, err, &back, &p);
  if (!e.empty()) {
    p.note = e;
    return p;
  }
  p.available = true;
  p.exact = back == raw;
  if (!p.exact) {
    p.note = "round trip differs (" + std::to_string(back.size()) + " bytes back of " +
             std::to_string(raw.size()) + ")";
  }
  return p;
}

// Lossless depth with x265 on the bit-swizzled codes (see the top of this file). `preset` is
// x265's speed preset ("ultrafast" ... "placebo").
inline PeerResult x265_lossless_depth(std::span<const uint16_t> codes, uint32_t w, uint32_t h,
                                      uint32_t frames, const std::string& preset = "medium",
                                      int decode_runs = 3) {
  PeerResult p;
  p.method = "ffmpeg x265 lossless (swizzled yuv444p, " + preset + ")";
  p.frames = frames;
  if (codes.size() != size_t{w} * h * frames || codes.empty()) {
    p.note = "input size does not match w x h x frames";
    return p;
  }
  if (!ffmpeg_has_encoder("libx265")) {
    p.note = "ffmpeg or its libx265 encoder is not installed";
    return p;
  }
  internal::TempDir tmp;
  if (!tmp.ok()) {
    p.note = "mkdtemp failed";
    return p;
  }
  // yuv444p: per frame the three planes, each w x h bytes.
  const size_t plane = size_t{w} * h;
  std::vector<uint8_t> raw(codes.size() * 3);
  for (uint32_t f = 0; f < frames; ++f) {
    uint8_t* dst = raw.data() + 3 * plane * f;
    for (size_t i = 0; i < plane; ++i) {
      uint8_t c[3];
      swizzle16(codes[plane * f + i], c);
      dst[i] = c[0];
      dst[plane + i] = c[1];
      dst[2 * plane + i] = c[2];
    }
  }
  const auto in = tmp / "in.yuv", out = tmp / "out.hevc", err = tmp / "err.txt";
  if (!internal::write_file(in, raw.data(), raw.size())) {
    p.note = "writing the raw frames failed";
    return p;
  }
  const internal::ProcessResult enc =
      internal::run(internal::ffmpeg_args(
                        {"-f", "rawvideo", "-pix_fmt", "yuv444p", "-s", internal::size_arg(w, h),
                         "-r", "24", "-i", in.string(), "-c:v", "libx265", "-preset", preset,
                         "-x265-params", "lossless=1:log-level=error", "-f", "hevc", out.string()}),
                    false, err);
  if (enc.exit_code != 0) {
    p.note = "encode: " + enc.error;
    return p;
  }
  p.encode_s = enc.seconds;
  p.bytes = std::filesystem::file_size(out);
  std::vector<uint8_t> back;
  const std::string e = internal::time_decodes(out, "yuv444p", decode_runs, err, &back, &p);
  if (!e.empty()) {
    p.note = e;
    return p;
  }
  p.available = true;
  // Compare decoded codes, not only bytes: the unswizzle is part of what a player would do.
  p.exact = back.size() == raw.size();
  for (uint32_t f = 0; p.exact && f < frames; ++f) {
    const uint8_t* src = back.data() + 3 * plane * f;
    for (size_t i = 0; i < plane; ++i) {
      const uint8_t c[3] = {src[i], src[plane + i], src[2 * plane + i]};
      if (unswizzle16(c) != codes[plane * f + i]) {
        p.exact = false;
        p.note = "round trip differs at frame " + std::to_string(f) + " pixel " + std::to_string(i);
        break;
      }
    }
  }
  if (back.size() != raw.size()) {
    p.note = "round trip gave " + std::to_string(back.size()) + " bytes of " +
             std::to_string(raw.size());
  }
  return p;
}

// Mean over frames of the per-frame PSNR of 8-bit samples (peak 255), each frame capped at
// 100 dB. `a` and `b` hold `frames` frames of `frame_size` samples.
inline double mean_psnr_db(std::span<const uint8_t> a, std::span<const uint8_t> b,
                           size_t frame_size, uint32_t frames) {
  double sum = 0;
  for (uint32_t f = 0; f < frames; ++f) {
    double se = 0;
    for (size_t i = 0; i < frame_size; ++i) {
      const double d = double(a[f * frame_size + i]) - double(b[f * frame_size + i]);
      se += d * d;
    }
    const double mse = se / static_cast<double>(frame_size);
    sum += mse > 0 ? std::min(100.0, 10 * std::log10(255.0 * 255.0 / mse)) : 100.0;
  }
  return sum / frames;
}

// Colour with x265 at the CRF whose mean PSNR is within `tolerance_db` of `target_psnr_db`.
// `rgb` holds `frames` frames of w x h rgb24; `pix_fmt` is what x265 codes (yuv444p, yuv420p,
// gbrp, ...). When even CRF 0 stays below the target (an RGB -> YUV conversion caps the PSNR),
// the result is unavailable and the note gives the best PSNR reached; when the bisection cannot
// get within the tolerance (x265's PSNR is not exactly monotonic in CRF) the closest CRF is kept
// and the note says so. `params` are further x265 parameters ("key=value:key=value", e.g.
// "keyint=1" for intra-only coding), "" for none.
inline PeerResult x265_colour_matched_in(std::span<const uint8_t> rgb, uint32_t w, uint32_t h,
                                         uint32_t frames, double target_psnr_db,
                                         double tolerance_db, const std::string& pix_fmt,
                                         const std::string& preset, int decode_runs,
                                         const std::string& params = "") {
  PeerResult p;
  p.method = "ffmpeg x265 (" + pix_fmt + ", " + preset + (params.empty() ? "" : ", " + params) +
             ") at matched PSNR";
  const std::string x265_params = params.empty() ? "log-level=error" : "log-level=error:" + params;
  p.frames = frames;
  const size_t frame_size = size_t{w} * h * 3;
  if (rgb.size() != frame_size * frames || rgb.empty()) {
    p.note = "input size does not match w x h x 3 x frames";
    return p;
  }
  if (!ffmpeg_has_encoder("libx265")) {
    p.note = "ffmpeg or its libx265 encoder is not installed";
    return p;
  }
  internal::TempDir tmp;
  if (!tmp.ok()) {
    p.note = "mkdtemp failed";
    return p;
  }
  const auto in = tmp / "in.rgb", err = tmp / "err.txt";
  if (!internal::write_file(in, rgb.data(), rgb.size())) {
    p.note = "writing the raw frames failed";
    return p;
  }
  struct Trial {
    double crf = 0, psnr = 0, encode_s = 0;
    uint64_t bytes = 0;
  };
  // Encodes at `crf`, decodes once, measures. Returns "" or the error.
  auto trial = [&](double crf, Trial* t) -> std::string {
    const auto out = tmp / "out.hevc";
    char crf_text[32];
    std::snprintf(crf_text, sizeof crf_text, "%.2f", crf);
    const internal::ProcessResult enc =
        internal::run(internal::ffmpeg_args({"-f",           "rawvideo",  "-pix_fmt",
                                             "rgb24",        "-s",        internal::size_arg(w, h),
                                             "-r",           "24",        "-i",
                                             in.string(),    "-c:v",      "libx265",
                                             "-preset",      preset,      "-crf",
                                             crf_text,       "-pix_fmt",  pix_fmt,
                                             "-x265-params", x265_params, "-f",
                                             "hevc",         out.string()}),
                      false, err);
    if (enc.exit_code != 0) return "encode: " + enc.error;
    const internal::ProcessResult dec = internal::run(
        internal::ffmpeg_args({"-i", out.string(), "-f", "rawvideo", "-pix_fmt", "rgb24", "-"}),
        true, err);
    if (dec.exit_code != 0) return "decode: " + dec.error;
    if (dec.out.size() != rgb.size()) {
      return "decode gave " + std::to_string(dec.out.size()) + " bytes of " +
             std::to_string(rgb.size());
    }
    ++p.encodes;
    *t = {crf, mean_psnr_db(rgb, dec.out, frame_size, frames), enc.seconds,
          std::filesystem::file_size(out)};
    return "";
  };

  // PSNR falls as the CRF rises: bisect [lo, hi] keeping psnr(lo) >= target > psnr(hi).
  Trial lo_t, hi_t, best;
  if (std::string e = trial(0, &lo_t); !e.empty()) {
    p.note = e;
    return p;
  }
  best = lo_t;
  auto closer = [&](const Trial& t) {
    if (std::abs(t.psnr - target_psnr_db) < std::abs(best.psnr - target_psnr_db)) best = t;
  };
  if (lo_t.psnr < target_psnr_db - tolerance_db) {
    char buf[160];
    std::snprintf(buf, sizeof buf, "even CRF 0 reaches only %.2f dB (target %.2f dB)", lo_t.psnr,
                  target_psnr_db);
    p.note = buf;
    return p;
  }
  if (std::abs(lo_t.psnr - target_psnr_db) > tolerance_db) {
    if (std::string e = trial(51, &hi_t); !e.empty()) {
      p.note = e;
      return p;
    }
    closer(hi_t);
    if (hi_t.psnr < target_psnr_db) {
      double lo = 0, hi = 51;
      for (int it = 0; it < 14 && std::abs(best.psnr - target_psnr_db) > tolerance_db; ++it) {
        const double mid = 0.5 * (lo + hi);
        Trial t;
        if (std::string e = trial(mid, &t); !e.empty()) {
          p.note = e;
          return p;
        }
        closer(t);
        (t.psnr >= target_psnr_db ? lo : hi) = mid;
      }
    }
  }
  // Re-encode at the chosen CRF (the file was overwritten by later trials), then time decodes.
  Trial final_t;
  if (std::string e = trial(best.crf, &final_t); !e.empty()) {
    p.note = e;
    return p;
  }
  std::vector<uint8_t> back;
  const std::string e =
      internal::time_decodes(tmp / "out.hevc", "rgb24", decode_runs, err, &back, &p);
  if (!e.empty()) {
    p.note = e;
    return p;
  }
  p.available = true;
  p.crf = final_t.crf;
  p.psnr_db = final_t.psnr;
  p.bytes = final_t.bytes;
  p.encode_s = final_t.encode_s;
  if (std::abs(p.psnr_db - target_psnr_db) > tolerance_db) {
    char buf[160];
    std::snprintf(buf, sizeof buf, "closest CRF misses the target by %.2f dB",
                  p.psnr_db - target_psnr_db);
    p.note = buf;
  }
  return p;
}

// The same, with pix_fmt "auto" (the default): yuv444p, or gbrp when yuv444p cannot reach the
// target even at CRF 0. 8-bit limited-range YUV loses about 50 dB worth of precision on the way
// from and back to RGB (measured on the demo bench: 49.6 dB at CRF 0), which is where calf's
// default colour threshold lies; gbrp codes the RGB planes themselves and has no such cap.
inline PeerResult x265_colour_matched(std::span<const uint8_t> rgb, uint32_t w, uint32_t h,
                                      uint32_t frames, double target_psnr_db,
                                      double tolerance_db = 0.25,
                                      const std::string& pix_fmt = "auto",
                                      const std::string& preset = "medium", int decode_runs = 3,
                                      const std::string& params = "") {
  if (pix_fmt != "auto") {
    return x265_colour_matched_in(rgb, w, h, frames, target_psnr_db, tolerance_db, pix_fmt, preset,
                                  decode_runs, params);
  }
  PeerResult yuv = x265_colour_matched_in(rgb, w, h, frames, target_psnr_db, tolerance_db,
                                          "yuv444p", preset, decode_runs, params);
  if (yuv.available || yuv.note.rfind("even CRF 0", 0) != 0) return yuv;
  PeerResult gbr = x265_colour_matched_in(rgb, w, h, frames, target_psnr_db, tolerance_db, "gbrp",
                                          preset, decode_runs, params);
  gbr.encodes += yuv.encodes;
  gbr.note = "yuv444p " + yuv.note + (gbr.note.empty() ? "" : "; ") + gbr.note;
  return gbr;
}

}  // namespace calf::bench
