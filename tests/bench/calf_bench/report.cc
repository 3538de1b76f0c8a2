#include "report.h"

#include <unistd.h>

#include <algorithm>
#include <fstream>
#include <string>

#include <fmt/format.h>

#include "../ffmpeg_peers.h"
#include "calf/format/files.h"
#include "sweep_plan.h"

namespace calf::bench {

namespace fs = std::filesystem;

std::vector<bool> pareto_front(const std::vector<std::pair<double, double>>& cq) {
  std::vector<bool> on(cq.size(), true);
  for (size_t i = 0; i < cq.size(); ++i) {
    for (size_t j = 0; j < cq.size() && on[i]; ++j) {
      const bool no_worse = cq[j].first <= cq[i].first && cq[j].second >= cq[i].second;
      const bool better = cq[j].first < cq[i].first || cq[j].second > cq[i].second;
      if (j != i && no_worse && better) on[i] = false;
    }
  }
  return on;
}

// A value as sweep.csv prints it (3 decimals): the front is computed on the reported numbers,
// so that anyone recomputing it from the CSV gets the same points.
namespace {
double as_reported(double v) {
  return std::stod(fmt::format("{:.3f}", v));
}
}  // namespace

void mark_pareto(SceneResult* scene) {
  std::vector<std::pair<double, double>> bytes, ms;
  for (const MeasuredPoint& p : scene->points) {
    const double psnr = as_reported(p.result.psnr_db);
    bytes.emplace_back(static_cast<double>(p.result.clip_bytes), psnr);
    ms.emplace_back(as_reported(p.result.total_cpu_ms()), psnr);
  }
  const std::vector<bool> fb = pareto_front(bytes), fm = pareto_front(ms);
  for (size_t i = 0; i < scene->points.size(); ++i) {
    scene->points[i].result.front_bytes = fb[i];
    scene->points[i].result.front_ms = fm[i];
  }
}

std::string grouped(uint64_t n) {
  const std::string s = std::to_string(n);
  std::string out;
  for (size_t i = 0; i < s.size(); ++i) {
    if (i && (s.size() - i) % 3 == 0) out += ',';
    out += s[i];
  }
  return out;
}

std::string peer_table(const std::vector<PeerRow>& peers) {
  std::string out =
      "| stream | method | bytes | raw bytes | ratio | × calf | encode s | decode ms/frame | "
      "marginal ms/frame | quality | note |\n"
      "|---|---|---:|---:|---:|---:|---:|---:|---:|---|---|\n";
  for (const PeerRow& r : peers) {
    if (!r.available) {
      out += fmt::format("| {} | {} | n/a | | | | | | | | {} |\n", r.stream, r.method, r.note);
      continue;
    }
    out += fmt::format(
        "| {} | {} | {} | {} | {:.1f}× | {} | {:.2f} | {} | {} | {} | {} |\n", r.stream, r.method,
        grouped(r.bytes), grouped(r.raw_bytes),
        r.bytes ? static_cast<double>(r.raw_bytes) / static_cast<double>(r.bytes) : 0.0,
        r.calf_bytes ? fmt::format("{:.2f}", static_cast<double>(r.bytes) / r.calf_bytes) : "—",
        r.encode_s, r.decode_ms_per_frame >= 0 ? fmt::format("{:.2f}", r.decode_ms_per_frame) : "—",
        r.marginal_ms_per_frame >= 0 ? fmt::format("{:.2f}", r.marginal_ms_per_frame) : "—",
        r.quality, r.note);
  }
  return out;
}

Status write_file_whole(const fs::path& file, const std::string& text) {
  // calf's output rules (regular file or absent, temporary name, cleanup): files::TempFile.
  CALF_ASSIGN_OR_RETURN(files::TempFile temp, files::TempFile::create(file.string()));
  CALF_RETURN_IF_ERROR(
      temp.write(std::span(reinterpret_cast<const uint8_t*>(text.data()), text.size())));
  return temp.commit(/*sync=*/false);
}

namespace {

std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

std::string front_text(const PointResult& r) {
  std::string s;
  if (r.front_bytes) s += "B";
  if (r.front_ms) s += s.empty() ? "T" : " T";
  return s;
}

// What a row of a knob's table adds beyond the common columns.
std::string detail(Knob k, const MeasuredPoint& p) {
  const PointResult& r = p.result;
  switch (k) {
    case Knob::kQ:
    case Knob::kCell:
      return fmt::format("{} keyframes / {} cells", grouped(r.colour_keyframes),
                         grouped(r.colour_cells));
    case Knob::kColour:
      return fmt::format("stored {}{}; {} keyframes", r.colour_format, r.hdr ? " (HDR)" : " (LDR)",
                         grouped(r.colour_keyframes));
    case Knob::kDepth:
      return p.point.encode.depth == encoder::DepthCoding::kBc5
                 ? fmt::format("max relative depth error {:.2f} %", 100 * r.bc5_max_rel_error)
                 : "exact (log-16)";
    case Knob::kViews:
      return fmt::format("{:.1f} active on average", r.mean_active_views);
    case Knob::kSuper:
    case Knob::kWindow:
    case Knob::kAabbs:
      return fmt::format("{:.1f} Mbps@24 of updates", r.mean_mbps);
    case Knob::kAv1:
      return p.point.encode.colour == encoder::ColourCoding::kAv1
                 ? fmt::format("stored {}, cell {}, a key frame every {} frames", r.colour_format,
                               p.point.encode.cell, p.point.encode.av1_keyframe_interval)
                 : fmt::format("stored {}; {} keyframes", r.colour_format,
                               grouped(r.colour_keyframes));
    case Knob::kDenoise:
    case Knob::kMargin: {
      const std::string noise = p.point.encode.psnr_auto
                                    ? (r.noise_db > 0 ? fmt::format("noise {:.2f} dB, ", r.noise_db)
                                                      : std::string("no noise estimate, "))
                                    : "";
      return fmt::format(
          "{}Q {:.2f}, window {}: {} texel-frames averaged; {} keyframes / {} cells", noise,
          r.q_used, r.denoise_used > 1 ? std::to_string(r.denoise_used) : "off",
          grouped(r.colour_denoised), grouped(r.colour_keyframes), grouped(r.colour_cells));
    }
    default:
      return "";
  }
}

// The base point's own value of knob `k`, for its row in that knob's table.
std::string base_value(Knob k, const SweepPoint& p) {
  const EncodeConfig& e = p.encode;
  switch (k) {
    case Knob::kQ:
      return fmt::format("{:g}", e.q);
    case Knob::kCell:
      return fmt::format("{}", e.cell);
    case Knob::kWindow:
      return fmt::format("{}", e.window);
    case Knob::kAabbs:
      return fmt::format("{}", e.aabbs);
    case Knob::kDepth:
      return depth_coding_name(e.depth);
    case Knob::kColour:
      return colour_coding_name(e.colour);
    case Knob::kSuper:
      return super_name(e.super);
    case Knob::kViews:
      return fmt::format("{}", p.play.views);
    case Knob::kSteps:
      return fmt::format("{}", p.play.steps);
    case Knob::kAv1:
      return fmt::format("bc, colour {}", colour_coding_name(e.colour));
    case Knob::kDenoise:
      return fmt::format("{}", e.denoise_window);
    case Knob::kMargin:
      return fmt::format("none: Q {:g}", e.q);
    case Knob::kBase:
      break;
  }
  return "base";
}

std::string point_row(Knob k, const MeasuredPoint& p, bool base) {
  const PointResult& r = p.result;
  const std::string value =
      base ? fmt::format("**{} (base)**", base_value(k, p.point)) : p.point.value;
  return fmt::format(
      "| {} | {} | {} | {} | {} | {:.2f} ({:.1f}) | {:.2f} | {:.2f} | {:.1f} | {:.1f} | "
      "{:.1f} / {:.1f} / {:.1f} | {:.2f} | {:.4f} | {} | {} |\n",
      value, grouped(r.clip_bytes), grouped(r.colour_bytes), grouped(r.depth_bytes),
      grouped(r.material_bytes), r.encode_s, r.encode_cpu_s, r.decode_ms, r.upload_ms, r.render_ms,
      r.total_cpu_ms(), r.first_decode_ms, r.first_upload_ms, r.first_render_ms, r.psnr_db, r.ssim,
      front_text(r), detail(k, p));
}

const char* kPointHeader =
    "| {} | clip bytes | colour | depth | material | encode s (CPU s) | decode ms | upload ms | "
    "render ms | frame CPU ms | first frame ms (dec / upl / ren) | PSNR dB | SSIM | front | |\n"
    "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|---|\n";

}  // namespace

Status write_csv(const fs::path& file, const std::vector<SceneResult>& scenes) {
  std::string out =
      "scene,knob,value,label,is_base,cell,q,colour,depth,window,aabbs,super,views,steps,"
      "stored_colour_format,hdr,clip_bytes,colour_bytes,depth_bytes,material_bytes,"
      "colour_keyframes,encode_s,encode_cpu_s,decode_ms,upload_ms,render_ms,frame_ms,"
      "prepare_cpu_ms,render_cpu_ms,frame_cpu_ms,first_decode_ms,first_upload_ms,"
      "first_render_ms,frames,mean_active_views,mean_mbps_at_24fps,psnr_db,worst_psnr_db,ssim,"
      "front_bytes,front_cpu_ms,av1,psnr_auto_margin,q_used,noise_psnr_db,denoise_window,"
      "colour_denoised\n";
  for (const SceneResult& s : scenes) {
    for (const MeasuredPoint& p : s.points) {
      const EncodeConfig& e = p.point.encode;
      const PointResult& r = p.result;
      out += fmt::format(
          "{},{},{},{},{},{},{:g},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{:.3f},{:.3f},{:.3f},"
          "{:.3f},{:.3f},{:.3f},{:.3f},{:.3f},{:.3f},{:.3f},{:.3f},{:.3f},{},{:.2f},{:.3f},{:.3f},"
          "{:.3f},{:.5f},{},{},{},{},{:.3f},{:.3f},{},{}\n",
          s.scene, knob_name(p.point.knob), csv_field(p.point.value), csv_field(p.point.label),
          p.is_base ? 1 : 0, e.cell, e.q, colour_coding_name(e.colour), depth_coding_name(e.depth),
          e.window, e.aabbs, super_name(e.super), p.point.play.views, p.point.play.steps,
          r.colour_format, r.hdr ? 1 : 0, r.clip_bytes, r.colour_bytes, r.depth_bytes,
          r.material_bytes, r.colour_keyframes, r.encode_s, r.encode_cpu_s, r.decode_ms,
          r.upload_ms, r.render_ms, r.total_ms(), r.prepare_cpu_ms, r.render_cpu_ms,
          r.total_cpu_ms(), r.first_decode_ms, r.first_upload_ms, r.first_render_ms, r.frames,
          r.mean_active_views, r.mean_mbps, r.psnr_db, r.worst_psnr_db, r.ssim,
          r.front_bytes ? 1 : 0, r.front_ms ? 1 : 0,
          e.colour == encoder::ColourCoding::kAv1
              ? fmt::format("{}:{}", e.av1_444 ? 444 : 420, e.av1_crf)
              : std::string(),
          e.psnr_auto ? fmt::format("{:g}", e.noise_margin) : std::string(), r.q_used, r.noise_db,
          r.denoise_used, r.colour_denoised);
    }
  }
  return write_file_whole(file, out);
}

Status write_markdown(const fs::path& file, const std::vector<SceneResult>& scenes,
                      const RunInfo& run) {
  std::string out = "# calf-bench: speed ↔ accuracy sweep\n\n";
  const int minutes = static_cast<int>(run.total_s / 60);
  out += fmt::format(
      "Made by\n\n    {}\n\non {} (UTC): {} points ({} encodes, {} playbacks) and the peers in "
      "{} min {:.0f} s total wall time.\n\n",
      run.command_line, run.date_utc, run.points, run.encodes, run.points, minutes,
      run.total_s - 60.0 * minutes);
  out += fmt::format(
      "- machine: {}\n- renderer: {}\n- load average (1 / 5 / 15 min): {} at the "
      "start, {} at the end (the machine is shared: timings move with it)\n"
      "- settings: {}\n",
      run.machine, run.renderer, run.load_start, run.load_end, run.settings);
  out +=
      "- timings, one run per point (nothing cached between points): encode = "
      "`encoder::encode_lightfield_file`, wall seconds (CPU seconds of all threads in brackets); "
      "decode = "
      "`LightfieldDecoder::advance` (what calf-play prints as decode), upload = the rest of "
      "`Playback::prepare` (view selection, texture upload), render = `Playback::render` (GL: "
      "draw and read-back), wall ms; *frame CPU ms* = the process's CPU time (all threads, "
      "llvmpipe's included) over prepare + render. Each is the **median over frames 2..n** of the "
      "eye path; frame 1 (which uploads every visible cell and, on GL, compiles the shader) is "
      "apart in the *first frame* column\n"
      "- quality: `image_compare.h` PSNR / SSIM (sRGB-encoded, clamped; SSIM on luma) of each "
      "pose against the ground truth, averaged over the poses (a pose's PSNR capped at 100 dB, as "
      "calf-play's mean)\n"
      "- front: the point is on the scene's Pareto front (no other point costs no more and is no "
      "worse, and is better in one) for clip bytes vs PSNR (**B**) and for frame CPU ms vs PSNR "
      "(**T**). CPU time, not wall time, because on this shared machine the wall medians move "
      "with the other processes' load far more than between neighbouring points\n";
  out += fmt::format("- plots: {}\n\n", run.plot_notice);

  out +=
      "## Base configuration per scene\n\n"
      "| scene | views | colour | clip bytes | colour | depth | material | encode s | decode ms "
      "| upload ms | render ms | frame CPU ms | PSNR dB | SSIM |\n"
      "|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  for (const SceneResult& s : scenes) {
    if (s.points.empty()) continue;
    const PointResult& r = s.points[0].result;
    out += fmt::format(
        "| {} | {} | {}{} | {} | {} | {} | {} | {:.2f} | {:.2f} | {:.2f} | {:.1f} | {:.1f} | "
        "{:.2f} | {:.4f} |\n",
        s.scene, s.views, r.colour_format, r.hdr ? " (HDR)" : "", grouped(r.clip_bytes),
        grouped(r.colour_bytes), grouped(r.depth_bytes), grouped(r.material_bytes), r.encode_s,
        r.decode_ms, r.upload_ms, r.render_ms, r.total_cpu_ms(), r.psnr_db, r.ssim);
  }
  out += "\n";

  for (const SceneResult& s : scenes) {
    out += fmt::format("## {}\n\n", s.scene);
    const PointResult& b = s.points.at(0).result;
    out += fmt::format(
        "{} views, faces {}², {} frames; ground truth {}×{}, {} poses along the scene's eye path. "
        "The capture is {} (colour auto = {}){}. Capture {:.1f} s, ground truth {:.1f} s.\n\n",
        s.views, s.face_size, s.frames, s.gt_width, s.gt_height, s.poses, b.hdr ? "HDR" : "LDR",
        b.colour_format, s.material ? "; it has a material stream" : "; no material stream",
        s.capture_s, s.ground_truth_s);
    if (b.hdr) {
      out +=
          "BC1 / BC7 on this HDR capture: the encoder clamps each linear value to [0, 1] and "
          "codes it as 8-bit sRGB (highlights above 1 are lost), and Q is then judged by PSNR "
          "on sRGB instead of log2-PSNR (docs/ENCODER.md).\n\n";
    }
    for (const auto& [knob, rows] : s.tables) {
      out += fmt::format("### {}\n\n", knob_title(knob));
      out += fmt::format(fmt::runtime(kPointHeader), knob_name(knob));
      for (size_t i : rows) out += point_row(knob, s.points[i], s.points[i].is_base);
      out += "\n";
    }
    out += "### Peers (same run, same capture)\n\n";
    if (!s.peer_notes.empty()) out += s.peer_notes + "\n\n";
    out += s.peers.empty() ? "Not measured (--no-peers).\n\n" : peer_table(s.peers) + "\n";
    // The plots, when gnuplot made them (write_plots runs first).
    for (const char* axis : {"bytes", "ms"}) {
      const std::string png = fmt::format("{}_psnr_{}.png", s.scene, axis);
      if (fs::exists(file.parent_path() / png)) {
        out += fmt::format("![{}: PSNR vs {}]({})\n", s.scene,
                           axis == std::string("bytes") ? "clip bytes" : "frame CPU ms", png);
      }
    }
    out += "\n";
  }
  return write_file_whole(file, out);
}

namespace {

// gnuplot's data for a scene: one block per knob (base first), columns bytes (MB), frame ms,
// PSNR, label; blocks are separated by two blank lines so that `index i` selects one.
std::string scene_data(const SceneResult& s, std::vector<Knob>* blocks) {
  std::string out;
  std::vector<Knob> order = {Knob::kBase};
  for (Knob k : all_knobs()) order.push_back(k);
  for (Knob k : order) {
    std::string block;
    for (const MeasuredPoint& p : s.points) {
      if (p.point.knob != k) continue;
      block += fmt::format("{:.4f} {:.3f} {:.3f} \"{}\"\n", p.result.clip_bytes / 1e6,
                           p.result.total_cpu_ms(), p.result.psnr_db, p.point.label);
    }
    if (block.empty()) continue;
    if (!out.empty()) out += "\n\n";
    out += block;
    blocks->push_back(k);
  }
  return out;
}

std::string front_data(const SceneResult& s, bool bytes) {
  std::vector<std::pair<double, double>> pts;
  for (const MeasuredPoint& p : s.points) {
    if (bytes ? p.result.front_bytes : p.result.front_ms) {
      pts.emplace_back(bytes ? p.result.clip_bytes / 1e6 : p.result.total_cpu_ms(),
                       p.result.psnr_db);
    }
  }
  std::sort(pts.begin(), pts.end());
  std::string out;
  for (const auto& [x, y] : pts) out += fmt::format("{:.4f} {:.3f}\n", x, y);
  return out;
}

// One marker per knob, the same in every plot: the base a black square, the knobs distinct
// shapes and colours.
struct PointStyle {
  int type;
  double size;
  const char* colour;
};
PointStyle point_style(Knob k) {
  switch (k) {
    case Knob::kBase:
      return {5, 1.6, "#000000"};
    case Knob::kQ:
      return {2, 1.3, "#1f77b4"};
    case Knob::kCell:
      return {3, 1.3, "#ff7f0e"};
    case Knob::kWindow:
      return {4, 1.3, "#2ca02c"};
    case Knob::kAabbs:
      return {6, 1.3, "#d62728"};
    case Knob::kDepth:
      return {8, 1.3, "#9467bd"};
    case Knob::kColour:
      return {7, 1.3, "#8c564b"};
    case Knob::kSuper:
      return {10, 1.3, "#e377c2"};
    case Knob::kViews:
      return {9, 1.3, "#17becf"};
    case Knob::kSteps:
      return {11, 1.3, "#7f7f00"};
    case Knob::kAv1:
      return {12, 1.3, "#393b79"};
    case Knob::kDenoise:
      return {13, 1.3, "#637939"};
    case Knob::kMargin:
      return {14, 1.3, "#843c39"};
  }
  return {1, 1.3, "#000000"};
}

std::string plot_script(const SceneResult& s, const std::string& terminal, bool bytes,
                        const std::vector<Knob>& blocks) {
  const std::string axis = bytes ? "bytes" : "ms";
  const int column = bytes ? 1 : 2;
  std::string g = fmt::format(
      "# Made by calf-bench; run from this directory: gnuplot {0}_psnr_{1}.gp\n"
      "set terminal {2} size 800,500\n"
      "set output '{0}_psnr_{1}.png'\n"
      "set title \"{0}: mean PSNR vs {3} (Pareto front: line and circles)\"\n"
      "set xlabel \"{4}\"\n"
      "set ylabel \"mean PSNR vs ground truth (dB)\"\n"
      "set grid\n"
      "set offsets graph 0.04, graph 0.12, graph 0.06, graph 0.06\n"
      "set key outside right top\n"
      "plot '{0}_front_{1}.dat' using 1:2 with linespoints lw 2 lc rgb '#999999' pt 6 ps 2.4 "
      "title 'Pareto front'",
      s.scene, axis, terminal, bytes ? "clip bytes" : "frame CPU time",
      bytes ? "clip bytes (MB)" : "CPU ms per frame: decode + upload + render (median)");
  for (size_t i = 0; i < blocks.size(); ++i) {
    const PointStyle st = point_style(blocks[i]);
    g += fmt::format(
        ", \\\n     '{}.dat' index {} using {}:3 with points pt {} ps {} lc rgb '{}' title '{}'",
        s.scene, i, column, st.type, st.size, st.colour,
        blocks[i] == Knob::kBase ? "base" : knob_name(blocks[i]));
  }
  g += fmt::format(
      ", \\\n     '{}.dat' using {}:3:4 with labels left offset char 0.5,0.4 font ',7' notitle\n",
      s.scene, column);
  return g;
}

}  // namespace

std::vector<std::string> write_plots(const fs::path& dir, const std::vector<SceneResult>& scenes,
                                     std::string* notice) {
  std::vector<std::string> made;
  internal::TempDir tmp;
  const fs::path err = tmp.ok() ? tmp / "gnuplot.err" : fs::path("/dev/null");
  // pngcairo draws smoother lines; the libgd png terminal is the fallback every gnuplot has.
  std::string terminal = "pngcairo";
  internal::ProcessResult probe =
      internal::run({"gnuplot", "-e", "set terminal pngcairo"}, false, err);
  if (!probe.started) {
    *notice = "gnuplot not found: plots skipped (tables and data written)";
  } else if (probe.exit_code != 0) {
    terminal = "png";
  }
  for (const SceneResult& s : scenes) {
    std::vector<Knob> blocks;
    const std::string data = scene_data(s, &blocks);
    if (!write_file_whole(dir / (s.scene + ".dat"), data).ok()) continue;
    for (bool bytes : {true, false}) {
      const std::string axis = bytes ? "bytes" : "ms";
      const std::string script = s.scene + "_psnr_" + axis + ".gp";
      if (!write_file_whole(dir / (s.scene + "_front_" + axis + ".dat"), front_data(s, bytes))
               .ok() ||
          !write_file_whole(dir / script, plot_script(s, terminal, bytes, blocks)).ok() ||
          !probe.started) {
        continue;
      }
      const internal::ProcessResult r =
          internal::run({"gnuplot", "-e", "cd '" + dir.string() + "'", script}, false, err);
      if (r.exit_code != 0) {
        *notice = "gnuplot failed on " + script + ": " + r.error + " (tables written)";
        continue;
      }
      made.push_back(s.scene + "_psnr_" + axis + ".png");
    }
  }
  if (probe.started && notice->empty()) {
    *notice =
        fmt::format("gnuplot, terminal {} (800×500); scripts and data next to the PNGs", terminal);
  }
  return made;
}

}  // namespace calf::bench
