// calf-bench: what a sweep writes — sweep.md (markdown tables per scene and knob, peers, how it
// was measured), sweep.csv (one row per measured point) and, through gnuplot, PNG plots of PSNR
// against clip bytes and against frame milliseconds per scene with the Pareto front marked.
// Every file is written to a temporary name and renamed, so a reader never sees half a file.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "calf/format/status.h"
#include "sweep.h"

namespace calf::bench {

// Which of the (cost, quality) pairs lie on the Pareto front: a pair is on it unless another
// pair has a cost no higher and a quality no lower, one of them strictly (so equal pairs are
// both on it). Costs are minimised, qualities maximised.
std::vector<bool> pareto_front(const std::vector<std::pair<double, double>>& cost_quality);

// Sets front_bytes (clip bytes vs PSNR) and front_ms (decode + upload + render ms vs PSNR) of
// every point of the scene.
void mark_pareto(SceneResult* scene);

// How the run went, for the head of sweep.md.
struct RunInfo {
  std::string command_line;
  std::string date_utc;              // ISO 8601
  std::string machine;               // CPU, cores, memory, OS
  std::string renderer;              // "GL: llvmpipe (...)" or "CPU reference renderer, N threads"
  std::string load_start, load_end;  // /proc/loadavg at start and end
  std::string settings;              // face, frames, ground truth size, threads, ...
  double total_s = 0;
  size_t points = 0, encodes = 0;  // measured points (one playback each) and encodes
  std::string plot_notice;         // filled by write_plots()
};

// One line per measured point; columns as the header row names them.
Status write_csv(const std::filesystem::path& file, const std::vector<SceneResult>& scenes);

// The markdown report.
Status write_markdown(const std::filesystem::path& file, const std::vector<SceneResult>& scenes,
                      const RunInfo& run);

// Writes per scene `<scene>.dat`, `<scene>_front_{bytes,ms}.dat` and the gnuplot scripts
// `<scene>_psnr_{bytes,ms}.gp` into `dir`, then runs gnuplot on each script (pngcairo if it has
// it, else the libgd png terminal; 800 x 500). Returns the plot file names made; `notice` says
// which terminal was used, or why no PNG was made (gnuplot missing or failing), in one line.
std::vector<std::string> write_plots(const std::filesystem::path& dir,
                                     const std::vector<SceneResult>& scenes, std::string* notice);

// Writes `text` to `file` whole: a temporary file in the same directory, then a rename.
Status write_file_whole(const std::filesystem::path& file, const std::string& text);

// 1234567 -> "1,234,567".
std::string grouped(uint64_t n);

// The peers of a scene as a markdown table (stream, method, bytes, raw bytes, ratio, x calf,
// encode s, decode ms/frame, marginal ms/frame, quality, note); unavailable peers say why.
std::string peer_table(const std::vector<PeerRow>& peers);

}  // namespace calf::bench
