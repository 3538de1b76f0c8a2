// calf-bench: the speed <-> accuracy sweeps of calf on the built-in scenes (
// docs/BENCH.md). Per scene: capture once, ground truth once, then one knob at a time around a base
// configuration (sweep.h), the peers in the same run (peers.h); writes sweep.md, sweep.csv and
// gnuplot PNGs into
// --out (report.h). Progress goes to stderr; errors are one line and a non-zero exit (2 for a bad
// command line, 1 for a failure while measuring).
#include <stdlib.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <map>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include "calf/encoder/colour_denoise.h"
#include "calf/format/container_types.h"
#include "calf/player/gl_context.h"
#include "calf/samples/scene.h"
#include "measure.h"
#include "peers.h"
#include "report.h"
#include "sweep_plan.h"

namespace {

namespace fs = std::filesystem;
using namespace calf;
using namespace calf::bench;

// A one-line error (the first line of a multi-line message) and the exit status.
int fail(const std::string& message, int code) {
  std::fprintf(stderr, "calf-bench: %s\n", message.substr(0, message.find('\n')).c_str());
  return code;
}

// Parses a comma-separated list of numbers in [lo, hi] (multiples of `step` when step > 0);
// "all" becomes 0 when `allow_all`. The error names the option and the item.
template <typename T>
bool parse_numbers(const std::string& option, const std::string& text, double lo, double hi,
                   uint32_t step, bool allow_all, std::vector<T>* out, std::string* error) {
  out->clear();
  for (const std::string& item : split_commas(text)) {
    if (allow_all && item == "all") {
      out->push_back(0);
      continue;
    }
    char* end = nullptr;
    const double v = std::strtod(item.c_str(), &end);
    const bool whole =
        std::is_integral_v<T> ? v == static_cast<double>(static_cast<int64_t>(v)) : true;
    if (item.empty() || *end != 0 || !(v >= lo && v <= hi) || !whole ||
        (step > 0 && static_cast<int64_t>(v) % step != 0)) {
      *error = fmt::format("{}: '{}' is not {} in [{:g}, {:g}]{}{}", option, item,
                           std::is_integral_v<T> ? "a whole number" : "a number", lo, hi,
                           step > 0 ? fmt::format(" and a multiple of {}", step) : "",
                           allow_all ? " (or 'all')" : "");
      return false;
    }
    out->push_back(static_cast<T>(v));
  }
  return true;
}

// Parses a list of names into values through `names`.
template <typename T>
bool parse_names(const std::string& option, const std::string& text,
                 const std::map<std::string, T>& names, std::vector<T>* out, std::string* error) {
  out->clear();
  for (const std::string& item : split_commas(text)) {
    auto it = names.find(item);
    if (it == names.end()) {
      std::string known;
      for (const auto& [n, v] : names) known += (known.empty() ? "" : ", ") + n;
      *error = fmt::format("{}: unknown value '{}' (known: {})", option, item, known);
      return false;
    }
    out->push_back(it->second);
  }
  return true;
}

std::string first_line_of(const fs::path& file, const std::string& key) {
  std::ifstream in(file);
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind(key, 0) == 0) {
      std::string v = line.substr(line.find_first_of(":=") + 1);
      v.erase(0, v.find_first_not_of(" \t\""));
      while (!v.empty() && (v.back() == '"' || v.back() == ' ')) v.pop_back();
      return v;
    }
  }
  return "?";
}

std::string machine_text() {
  const std::string cpu = first_line_of("/proc/cpuinfo", "model name");
  const double mem_kib = std::atof(first_line_of("/proc/meminfo", "MemTotal").c_str());
  const std::string os = first_line_of("/etc/os-release", "PRETTY_NAME");
  return fmt::format("{}, {} hardware threads, {:.1f} GiB memory, {}", cpu,
                     std::thread::hardware_concurrency(), mem_kib / (1 << 20), os);
}

std::string load_average() {
  std::ifstream in("/proc/loadavg");
  double a = 0, b = 0, c = 0;
  in >> a >> b >> c;
  return in ? fmt::format("{:.2f} / {:.2f} / {:.2f}", a, b, c) : "?";
}

std::string utc_now() {
  const std::time_t t = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%d %H:%M", &tm);
  return buf;
}

std::string clock_text(double s) {
  const int total = static_cast<int>(s + 0.5);
  return fmt::format("{}:{:02}", total / 60, total % 60);
}

std::string upper(std::string s) {
  for (char& c : s) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

// Progress on stderr: point i of N, elapsed and an ETA from the mean encode time, the mean
// playback time and the mean per-scene rest (capture, ground truth, peers) seen so far.
struct Progress {
  size_t total = 0, done = 0;             // points (one playback each)
  size_t encodes_total = 0, encodes = 0;  // distinct encodes
  size_t scenes_total = 0, scenes = 0;
  double encode_s = 0, play_s = 0, scene_rest_s = 0;
  double start = now_seconds();
  double eta() const {
    const double per_encode = encodes ? encode_s / encodes : 0;
    const double per_play = done ? play_s / done : 0;
    const double per_scene = scenes ? scene_rest_s / scenes : 0;
    return per_encode * static_cast<double>(encodes_total - encodes) +
           per_play * static_cast<double>(total - done) +
           per_scene * static_cast<double>(scenes_total - scenes);
  }
  void point(const std::string& scene, const MeasuredPoint& p, double encode, double play) {
    ++done;
    play_s += play;
    if (encode > 0) {
      ++encodes;
      encode_s += encode;
    }
    const std::string enc = encode > 0 ? fmt::format("encode {:.1f} s, ", encode) : "";
    std::fprintf(stderr,
                 "calf-bench: point %zu/%zu %s %s=%s: %splay %.1f s, %.2f dB; elapsed %s, ETA %s\n",
                 done, total, scene.c_str(), knob_name(p.point.knob), p.point.value.c_str(),
                 enc.c_str(), play, p.result.psnr_db, clock_text(now_seconds() - start).c_str(),
                 clock_text(eta()).c_str());
  }
  // A scene is done; `rest_s` is its time outside encodes and playbacks.
  void scene_done(double rest_s) {
    ++scenes;
    scene_rest_s += rest_s;
  }
  void note(const std::string& text) const {
    std::fprintf(stderr, "calf-bench: %s (elapsed %s)\n", text.c_str(),
                 clock_text(now_seconds() - start).c_str());
  }
};

struct Options {
  std::vector<std::string> scenes;
  MeasureSettings measure;
  SweepValues values;
  PeerSettings peers;
  bool run_peers = true, keep_work = false;
  fs::path out, work;
};

void copy_encode(const EncodeOutcome& e, PointResult* r) {
  r->clip_bytes = e.file_bytes;
  r->colour_bytes = e.stats.colour.stored;
  r->depth_bytes = e.stats.depth.stored;
  r->material_bytes = e.stats.material.stored;
  r->colour_raw = e.stats.colour.raw;
  r->depth_raw = e.stats.depth.raw;
  r->encode_s = e.seconds;
  r->encode_cpu_s = e.cpu_seconds;
  r->colour_format = container::pixel_format_name(e.stats.colour_format);
  r->hdr = e.stats.hdr;
  r->colour_keyframes = e.stats.colour_keyframes;
  r->colour_cells = e.stats.colour_cells;
  r->bc5_max_rel_error = e.stats.depth_max_rel_error;
  r->q_used = e.q_used;
  r->noise_db = e.noise_db;
  r->denoise_used = e.denoise_window;
  r->colour_denoised = e.stats.colour_denoised;
}

// Measures one scene: every point of its plan, then the peers.
Status run_scene(const std::string& name, const Options& o, const ScenePlan& plan,
                 Progress& progress, SceneResult* out) {
  const fs::path work = o.work / name;
  const double scene_start = now_seconds();
  double measured_s = 0;  // in encodes and playbacks
  progress.note(fmt::format("{}: capturing ({}², {} frames) and rendering ground truth", name,
                            o.measure.face_size, o.measure.frames));
  CALF_ASSIGN_OR_RETURN(std::unique_ptr<SceneInputs> in, SceneInputs::make(name, o.measure, work));
  out->scene = name;
  out->views = in->view_count();
  out->face_size = o.measure.face_size;
  out->frames = o.measure.frames;
  out->gt_width = in->eye_path().width;
  out->gt_height = in->eye_path().height;
  out->poses = static_cast<uint32_t>(in->eye_path().poses.size());
  out->material = in->material();
  out->capture_s = in->capture_seconds();
  out->ground_truth_s = in->ground_truth_seconds();
  out->tables = plan.tables;
  for (size_t i = 0; i < plan.points.size(); ++i) {
    out->points.push_back({plan.points[i], {}, i == 0});
  }
  progress.note(fmt::format("{}: capture {:.1f} s, ground truth {:.1f} s", name, out->capture_s,
                            out->ground_truth_s));

  // One encode per distinct encode configuration (the base first); its points are played from it.
  std::vector<EncodeConfig> encodes;
  for (const SweepPoint& p : plan.points) {
    if (std::find(encodes.begin(), encodes.end(), p.encode) == encodes.end())
      encodes.push_back(p.encode);
  }
  const fs::path base_clip = work / "clip_0.calf";
  for (size_t e = 0; e < encodes.size(); ++e) {
    const fs::path clip = work / fmt::format("clip_{}.calf", e);
    CALF_ASSIGN_OR_RETURN(const EncodeOutcome encoded, in->encode(encodes[e], clip));
    bool first = true;
    for (MeasuredPoint& p : out->points) {
      if (!(p.point.encode == encodes[e])) continue;
      copy_encode(encoded, &p.result);
      const double t0 = now_seconds();
      CALF_RETURN_IF_ERROR(in->play(clip, p.point.play, &p.result));
      const double play_s = now_seconds() - t0;
      measured_s += play_s + (first ? encoded.seconds : 0);
      progress.point(name, p, first ? encoded.seconds : 0, play_s);
      first = false;
    }
    std::error_code ec;
    if (e != 0) fs::remove(clip, ec);
  }

  if (o.run_peers) {
    const double t0 = now_seconds();
    progress.note(name + ": peers (xz, zstd, ffmpeg FFV1 / x265)");
    CalfReference ref;
    ref.base_clip = base_clip;
    ref.base = out->points[0].result;
    const EncodeConfig& b = out->points[0].point.encode;
    ref.base_label =
        fmt::format("{} + {} + {}, cell {}, Q {:g} (base)", upper(ref.base.colour_format),
                    depth_coding_name(b.depth), super_name(b.super), b.cell, b.q);
    for (const MeasuredPoint& p : out->points) {
      const PointResult& r = p.result;
      if (p.point.knob == Knob::kSuper && p.point.encode.super == container::Compression::kLzma2) {
        ref.extra.push_back({"depth", "base with lzma2", r.depth_bytes, r.encode_s});
        ref.extra.push_back({"colour", "base with lzma2", r.colour_bytes, r.encode_s});
      }
      if (p.point.knob == Knob::kDepth && p.point.encode.depth == encoder::DepthCoding::kBc5) {
        ref.extra.push_back({"depth", "base with bc5 depth", r.depth_bytes, r.encode_s});
      }
    }
    CALF_ASSIGN_OR_RETURN(out->peers,
                          measure_peers(in->capture_dir(), ref, o.peers, &out->peer_notes));
    progress.note(fmt::format("{}: peers {:.1f} s", name, now_seconds() - t0));
  }
  std::error_code ec;
  if (!o.keep_work) fs::remove_all(work, ec);
  progress.scene_done(now_seconds() - scene_start - measured_s);
  return Status::Ok();
}

}  // namespace

int main(int argc, char** argv) {
  // SVT-AV1 (the av1 knob's 4:2:0 points) prints its banner and settings to stderr unless SVT_LOG
  // says otherwise; set before any thread starts, and a user's own setting is kept.
  setenv("SVT_LOG", "0", 0);
  CLI::App app{
      "calf-bench: speed <-> accuracy sweeps of calf on the built-in scenes (docs/BENCH.md).\n"
      "Per scene: capture once, ground truth along its eye path once, then one knob at a time "
      "around the base configuration (calf-encode / calf-play defaults with cell 32): encode "
      "knobs re-encode, play knobs re-play the base clip. Every point: clip / colour / depth / "
      "material bytes, encode s, decode / upload / render ms per frame (median of frames 2..n, "
      "frame 1 apart), mean PSNR / SSIM against the ground truth. Peers (xz, zstd, ffmpeg FFV1 "
      "/ x265) in the same run. Writes OUT/sweep.md, OUT/sweep.csv and gnuplot PNGs with the "
      "Pareto front.",
      "calf-bench"};
  Options o;
  std::string scenes = "interior,turntable,mirror-box", knobs = "all", out = "build/bench", work;
  std::string q = "35,40,45,50,55", cells = "16,32,64", windows = "1,2,4", aabbs = "1,2,4";
  std::string depth = "raw16,bc5", colour = "auto,bc1,bc7", super = "zstd,lzma2";
  std::string views = "1,2,4,all", steps = "16,32,64,128", renderer = "gl";
  std::string av1 = "420:20,420:32,444:32", denoise = "0,4,16", margins = "2,4";
  uint32_t face = 128, frames = 8, gt = 128, threads = 0, base_cell = 32;
  float noise = 0;
  bool quick = false, no_peers = false, no_ffmpeg = false, keep = false;
  app.add_option("--scenes", scenes,
                 "built-in scenes, comma-separated (default "
                 "interior,turntable,mirror-box)");
  app.add_option("--out", out,
                 "output directory for sweep.md, sweep.csv, plots (default build/bench)");
  app.add_option("--work", work,
                 "scratch directory: each run makes its own run-XXXXXX folder "
                 "in it for captures and clips, removed afterwards unless --keep-work (default "
                 "OUT/work)");
  app.add_flag("--keep-work", keep, "keep the captures, ground truth and base clips");
  app.add_option("--face", face,
                 "cube face size of the captures, texels (default 128; --quick 64)");
  app.add_option("--frames", frames, "frames captured (default 8; --quick 4)");
  app.add_option("--noise", noise,
                 "per-frame colour noise amplitude of the captures in [0, 1], as calf-capture "
                 "--noise adds it (the ground truth is rendered without it); above 0 the knobs "
                 "denoise and margin join 'all' (default 0: converged captures)");
  app.add_option("--gt-size", gt,
                 "ground-truth image side in pixels; one pose per frame "
                 "along the scene's eye path (default 128; --quick 64)");
  app.add_option("--threads", threads,
                 "capture, encode and CPU-render threads, 0 = all cores "
                 "(default 0)");
  app.add_option("--renderer", renderer,
                 "gl (OpenGL 4.5 through OSMesa, as calf-play "
                 "--headless) or cpu (the scalar reference renderer) (default gl)");
  app.add_option("--knobs", knobs,
                 "knobs to sweep, comma-separated: q, cell, window, aabbs, "
                 "depth, colour, super, views, steps, av1, denoise, margin, or all = every knob "
                 "but av1, and but denoise and margin unless --noise is above 0 (default all)");
  app.add_option(
      "--base-cell", base_cell,
      "colour cell size of the base configuration "
      "(default 32; everything else in the base is calf-encode's / calf-play's default)");
  app.add_option("--q", q, "PSNR thresholds Q in dB (default 35,40,45,50,55; --quick 40,50)");
  app.add_option("--cells", cells, "colour cell sizes (default 16,32,64; --quick 32,64)");
  app.add_option("--windows", windows, "depth windows W (default 1,2,4; --quick 1,2)");
  app.add_option("--aabbs", aabbs, "AABB limits A (default 1,2,4; --quick 1,2)");
  app.add_option("--depth-formats", depth, "depth formats: raw16, bc5 (default raw16,bc5)");
  app.add_option("--colour-formats", colour,
                 "colour formats: auto (BC6H for HDR captures, BC1 "
                 "for LDR), bc1, bc7, bc6h (default auto,bc1,bc7; --quick auto,bc7)");
  app.add_option("--super", super, "supercompression: zstd, lzma2, none (default zstd,lzma2)");
  app.add_option("--views", views,
                 "active view counts, 'all' = every viewpoint (default "
                 "1,2,4,all; --quick 1,all)");
  app.add_option("--steps", steps, "ray-march steps (default 16,32,64,128; --quick 32,64)");
  app.add_option("--av1", av1,
                 "AV1 colour points CHROMA:CRF, CHROMA 420 (SVT-AV1) or 444 (libaom), CRF 1..63; "
                 "each an encode with --colour-codec av1, one stream per face (cell = --face) and "
                 "one key frame (--av1-keyframe-interval = --frames) (default "
                 "420:20,420:32,444:32)");
  app.add_option("--denoise-windows", denoise,
                 "render-noise pre-filter windows (calf-encode --denoise-window, 0..64, 0 = off) "
                 "at the base's Q 50; needs --noise (default 0,4,16; --quick 0,2,4)");
  app.add_option("--margins", margins,
                 "noise margins in dB (calf-encode --psnr auto --psnr-noise-margin, 0..50, with "
                 "--denoise-window auto); needs --noise (default 2,4)");
  app.add_flag("--quick", quick,
               "fewer points and a smaller capture, for trying things: the "
               "--quick values above unless given");
  app.add_flag("--no-peers", no_peers, "skip the peers (xz, zstd, ffmpeg)");
  app.add_flag("--no-ffmpeg", no_ffmpeg, "skip only the ffmpeg peers");
  app.add_option("--x265-preset", o.peers.x265_preset,
                 "x265 preset of the ffmpeg peers (default "
                 "medium)");
  app.add_option("--x265-params", o.peers.x265_params,
                 "further x265 parameters of the colour peer, key=value:key=value (default none); "
                 "keyint=1 makes it intra-only, each frame decodable alone as each calf frame is");
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp&) {
    std::fputs(app.help().c_str(), stdout);
    return 0;
  } catch (const CLI::ParseError& e) {
    return fail(std::string(e.what()) + " (see --help)", 2);
  }

  if (quick) {
    auto quick_default = [&](const char* option, std::string& value, const char* q_value) {
      if (app.count(option) == 0) value = q_value;
    };
    quick_default("--q", q, "40,50");
    quick_default("--cells", cells, "32,64");
    quick_default("--windows", windows, "1,2");
    quick_default("--aabbs", aabbs, "1,2");
    quick_default("--colour-formats", colour, "auto,bc7");
    quick_default("--views", views, "1,all");
    quick_default("--steps", steps, "32,64");
    quick_default("--denoise-windows", denoise, "0,2,4");
    if (app.count("--face") == 0) face = 64;
    if (app.count("--frames") == 0) frames = 4;
    if (app.count("--gt-size") == 0) gt = 64;
  }

  std::string error;
  SweepValues& v = o.values;
  const bool lists_ok =
      parse_knobs(knobs, noise > 0, &v.knobs, &error) && parse_av1_points(av1, &v.av1, &error) &&
      parse_numbers("--denoise-windows", denoise, 0, encoder::kMaxDenoiseWindow, 0, false,
                    &v.denoise, &error) &&
      parse_numbers("--margins", margins, 0, 50, 0, false, &v.margins, &error) &&
      parse_numbers("--q", q, 1e-3, 200, 0, false, &v.q, &error) &&
      parse_numbers("--cells", cells, 4, 16384, 4, false, &v.cells, &error) &&
      parse_numbers("--windows", windows, 1, 1e6, 0, false, &v.windows, &error) &&
      parse_numbers("--aabbs", aabbs, 1, 64, 0, false, &v.aabbs, &error) &&
      parse_numbers("--views", views, 1, 65536, 0, true, &v.views, &error) &&
      parse_numbers("--steps", steps, 1, 65536, 0, false, &v.steps, &error) &&
      parse_names<encoder::DepthCoding>(
          "--depth-formats", depth,
          {{"raw16", encoder::DepthCoding::kRaw16}, {"bc5", encoder::DepthCoding::kBc5}}, &v.depth,
          &error) &&
      parse_names<encoder::ColourCoding>("--colour-formats", colour,
                                         {{"auto", encoder::ColourCoding::kAuto},
                                          {"bc1", encoder::ColourCoding::kBc1},
                                          {"bc7", encoder::ColourCoding::kBc7},
                                          {"bc6h", encoder::ColourCoding::kBc6h}},
                                         &v.colour, &error) &&
      parse_names<container::Compression>("--super", super,
                                          {{"zstd", container::Compression::kZstd},
                                           {"lzma2", container::Compression::kLzma2},
                                           {"none", container::Compression::kNone}},
                                          &v.super, &error);
  if (!lists_ok) return fail(error, 2);
  if (renderer != "gl" && renderer != "cpu") {
    return fail("--renderer: '" + renderer + "' is neither gl nor cpu", 2);
  }
  if (face < 4 || face > 4096) return fail(fmt::format("--face {} is outside 4..4096", face), 2);
  if (frames < 1 || frames > 100000)
    return fail(fmt::format("--frames {} is outside 1..100000", frames), 2);
  if (gt < 11 || gt > 4096) {
    return fail(fmt::format("--gt-size {} is outside 11..4096 (SSIM needs 11 pixels)", gt), 2);
  }
  if (base_cell < 4 || base_cell % 4 != 0) {
    return fail(fmt::format("--base-cell {} is not a multiple of 4 of at least 4", base_cell), 2);
  }
  if (threads > 256) return fail(fmt::format("--threads {} is above 256", threads), 2);
  if (!(noise >= 0 && noise <= 1))
    return fail(fmt::format("--noise {} is outside [0, 1]", noise), 2);
  for (Knob k : v.knobs) {
    if (is_noise_knob(k) && noise == 0) {
      return fail(fmt::format("--knobs {} needs --noise above 0: the built-in captures are "
                              "converged (Q stays 50, the pre-filter off)",
                              knob_name(k)),
                  2);
    }
  }
  for (const std::string& s : split_commas(scenes)) {
    bool known = false;
    std::string names;
    for (const samples::SceneInfo& i : samples::builtin_scenes()) {
      known = known || s == i.name;
      names += std::string(names.empty() ? "" : ", ") + i.name;
    }
    if (!known)
      return fail(fmt::format("--scenes: unknown scene '{}' (built-in: {})", s, names), 2);
    if (std::find(o.scenes.begin(), o.scenes.end(), s) == o.scenes.end()) o.scenes.push_back(s);
  }
  v.base_encode.cell = base_cell;
  v.av1_cell = face;
  v.av1_keyframe_interval = frames;
  o.measure.noise = noise;
  o.measure.face_size = face;
  o.measure.frames = frames;
  o.measure.gt_width = o.measure.gt_height = gt;
  o.measure.threads = threads;
  o.measure.use_gl = renderer == "gl";
  o.run_peers = !no_peers;
  o.peers.ffmpeg = !no_ffmpeg;
  o.keep_work = keep;
  o.out = out;
  o.work = work.empty() ? o.out / "work" : fs::path(work);

  RunInfo run;
  for (int i = 0; i < argc; ++i) {
    const std::string a = argv[i];
    run.command_line += (i ? " " : "") + (a.find(' ') == std::string::npos ? a : "'" + a + "'");
  }
  run.date_utc = utc_now();
  run.machine = machine_text();
  run.load_start = load_average();
  run.settings = fmt::format(
      "faces {}², {} frames{}, ground truth {}×{} (one pose per frame), threads {} ({}), base = "
      "calf-encode defaults with cell {} (Q {:g}, colour auto, depth raw16, W 2, A 2, zstd) and "
      "calf-play --headless defaults ({} views, {} steps, no performance culling)",
      face, frames,
      noise > 0
          ? fmt::format(", render noise {:g} (calf-capture --noise; ground truth without)", noise)
          : "",
      gt, gt, threads, threads ? "as given" : "all cores", base_cell, v.base_encode.q,
      v.base_play.views, v.base_play.steps);

  std::error_code ec;
  fs::create_directories(o.out, ec);
  if (ec) return fail(o.out.string() + ": " + ec.message(), 1);
  // This run's scratch folder, fresh and private: nothing that was there before is touched.
  const fs::path work_root = o.work;
  fs::create_directories(work_root, ec);
  std::string run_dir = (work_root / "run-XXXXXX").string();
  if (ec || ::mkdtemp(run_dir.data()) == nullptr) {
    return fail(work_root.string() + ": cannot make a scratch folder", 1);
  }
  o.work = run_dir;

  // One GL context for the whole run: each playback makes its own textures and program in it.
  std::unique_ptr<player::OsMesaContext> context;
  if (o.measure.use_gl) {
    auto c = player::OsMesaContext::make();
    if (!c.ok()) return fail(c.status().to_string(), 1);
    context = std::move(*c);
    o.measure.gl = &context->gl();
    run.renderer = fmt::format("GL {}.{} through OSMesa: {}", context->gl().major_version,
                               context->gl().minor_version, context->gl().renderer);
  } else {
    run.renderer = fmt::format("CPU reference renderer, {} threads",
                               threads ? threads : std::thread::hardware_concurrency());
  }

  // The plans first, so that progress can count every point of the run.
  std::vector<ScenePlan> plans;
  Progress progress;
  for (const std::string& s : o.scenes) {
    auto scene = samples::make_builtin_scene(s);
    if (!scene.ok()) return fail(scene.status().to_string(), 1);
    plans.push_back(plan_scene(v, static_cast<uint32_t>(scene->default_rig.viewpoints.size())));
    progress.total += plans.back().points.size();
    std::vector<EncodeConfig> distinct;
    for (const SweepPoint& p : plans.back().points) {
      if (std::find(distinct.begin(), distinct.end(), p.encode) == distinct.end()) {
        distinct.push_back(p.encode);
      }
    }
    progress.encodes_total += distinct.size();
  }
  progress.scenes_total = o.scenes.size();
  std::vector<SceneResult> results(o.scenes.size());
  for (size_t i = 0; i < o.scenes.size(); ++i) {
    if (Status s = run_scene(o.scenes[i], o, plans[i], progress, &results[i]); !s.ok()) {
      if (!o.keep_work) fs::remove_all(o.work, ec);
      fs::remove(work_root, ec);  // only if empty
      return fail(o.scenes[i] + ": " + s.to_string(), 1);
    }
    mark_pareto(&results[i]);
  }
  if (!o.keep_work) {
    fs::remove_all(o.work, ec);
    fs::remove(work_root, ec);  // only if empty: never someone else's files
  } else {
    progress.note("kept the captures, ground truth and base clips in " + o.work.string());
  }

  run.total_s = now_seconds() - progress.start;
  run.points = progress.done;
  run.encodes = progress.encodes;
  run.load_end = load_average();
  const std::vector<std::string> plots = write_plots(o.out, results, &run.plot_notice);
  if (Status s = write_csv(o.out / "sweep.csv", results); !s.ok()) return fail(s.to_string(), 1);
  if (Status s = write_markdown(o.out / "sweep.md", results, run); !s.ok()) {
    return fail(s.to_string(), 1);
  }
  size_t rows = 0;
  for (const SceneResult& r : results) rows += r.points.size();
  progress.note(fmt::format("done: {} points ({} encodes) in {}", rows, progress.encodes,
                            clock_text(run.total_s)));
  std::printf(
      "calf-bench: %zu scene%s, %zu points in %s; wrote %s (sweep.md, sweep.csv, %zu "
      "plots); %s\n",
      results.size(), results.size() == 1 ? "" : "s", rows, clock_text(run.total_s).c_str(),
      o.out.string().c_str(), plots.size(), run.plot_notice.c_str());
  return 0;
}
