// bench-tiles_build: builds the tile set (paper 000; calf/encoder/tiles_build.h) of one frame of a
// capture set and prints the builder's report: seconds per stage, triangles against L_tris,
// modelled and measured overdraw against L_area and L_peakOD, texels and atlas occupancy.
// docs/TILES.md lists the runs behind its figures. --repeats N builds N times and prints the
// median total seconds (the tile set must be identical each time, else it fails).
#include <fmt/core.h>
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cstdio>
#include <string>
#include <thread>
#include <vector>

#include "calf/capture/capture_set.h"
#include "calf/encoder/tiles_build.h"

int main(int argc, char** argv) {
  CLI::App app{"Builds the tiles of one capture-set frame and prints the build report."};
  std::string dir;
  uint32_t frame = 0, repeats = 1;
  bool quiet = false;
  calf::encoder::TilesBuildOptions o;
  app.add_option("capture_set", dir, "capture set directory (format/CAPTURE.md)")->required();
  app.add_option("--frame", frame, "frame index")->capture_default_str();
  app.add_option("--triangles", o.max_triangles, "L_tris, the triangle budget")
      ->capture_default_str();
  app.add_option("--average-overdraw", o.max_average_overdraw, "L_area")->capture_default_str();
  app.add_option("--peak-overdraw", o.max_peak_overdraw, "L_peakOD")->capture_default_str();
  app.add_option("--directions", o.overdraw_directions, "F, views of the peak-overdraw model")
      ->capture_default_str();
  app.add_option("--min-level", o.min_level, "quadtree root level")->capture_default_str();
  app.add_option("--max-level", o.max_level, "quadtree leaf level")->capture_default_str();
  app.add_option("--max-planes", o.max_planes, "K, most planes per cell")->capture_default_str();
  app.add_option("--merge-resolution", o.merge_resolution,
                 "point-merge grid per face (0 = the capture's face size)")
      ->capture_default_str();
  app.add_option("--texels-per-degree", o.texels_per_degree,
                 "tile texture density (0 = face size / 90)")
      ->capture_default_str();
  app.add_option("--max-tile-texels", o.max_tile_texels, "largest tile texture side")
      ->capture_default_str();
  app.add_option("--max-atlas", o.max_atlas_size, "largest atlas side")->capture_default_str();
  app.add_option("--supersampling", o.alpha_supersampling, "alpha supersamples per texel side")
      ->capture_default_str();
  app.add_option("--iterations", o.selection_iterations, "subgradient iterations")
      ->capture_default_str();
  app.add_option("--threads", o.threads, "worker threads")->capture_default_str();
  app.add_option("--repeats", repeats, "builds to time (median)")->capture_default_str();
  bool no_region_bound = false;
  app.add_flag("--no-region-bound", no_region_bound,
               "model each tile's fill from O only (not bounded over the view region)");
  app.add_flag("--quiet", quiet, "no progress on stderr");
  CLI11_PARSE(app, argc, argv);
  o.overdraw_region_bound = !no_region_bound;

  auto reader = calf::capture::CaptureSetReader::open(dir);
  if (!reader.ok()) {
    std::fprintf(stderr, "bench-tiles_build: %s\n", reader.status().to_string().c_str());
    return 1;
  }
  if (!quiet) {
    o.progress = [last = std::string()](std::string_view stage, double fraction) mutable {
      if (stage != last) std::fprintf(stderr, "\n%.*s", int(stage.size()), stage.data());
      last = std::string(stage);
      std::fprintf(stderr, " %.0f%%", 100 * fraction);
    };
  }
  std::vector<double> totals;
  calf::encoder::TilesBuildReport report;
  calf::TileSet first;
  for (uint32_t r = 0; r < std::max<uint32_t>(1, repeats); ++r) {
    auto set = calf::encoder::build_tiles(*reader, frame, o, &report);
    if (!quiet) std::fprintf(stderr, "\n");
    if (!set.ok()) {
      std::fprintf(stderr, "bench-tiles_build: %s\n", set.status().to_string().c_str());
      return 1;
    }
    if (r == 0) {
      first = std::move(*set);
    } else if (set->atlas_rgba != first.atlas_rgba || set->tiles.size() != first.tiles.size()) {
      std::fprintf(stderr, "bench-tiles_build: build %u differs from the first\n", r);
      return 1;
    }
    totals.push_back(report.seconds_total);
  }
  std::sort(totals.begin(), totals.end());
  fmt::print("capture set {} frame {}, {} threads (of {} hardware threads)\n", dir, frame,
             o.threads, std::thread::hardware_concurrency());
  fmt::print("{}", calf::encoder::format_tiles_report(report));
  if (totals.size() > 1) {
    fmt::print("total seconds: median {:.2f} of {} builds (min {:.2f}, max {:.2f})\n",
               totals[totals.size() / 2], totals.size(), totals.front(), totals.back());
  }
  return 0;
}
