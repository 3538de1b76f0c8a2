#include "calf_encode/tiles.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string_view>
#include <system_error>
#include <thread>
#include <vector>

#include <fmt/format.h>

#include "calf/capture/capture_set.h"
#include "calf/format/container.h"
#include "calf/format/version.h"
#include "command_line.h"

namespace calf::tools {

namespace {

inline constexpr EnumTable<encoder::TilesAlphaEstimate, 2> kAlphaEstimates = {
    {{"votes", encoder::TilesAlphaEstimate::kViewVotes},
     {"constraints", encoder::TilesAlphaEstimate::kConstraints}}};

inline constexpr EnumTable<encoder::TilesAtlasFormat, 2> kAtlasFormats = {
    {{"bc7", encoder::TilesAtlasFormat::kBc7}, {"rgba8", encoder::TilesAtlasFormat::kRgba8}}};

}  // namespace

void add_options(CLI::App& app, TilesOptions& o) {
  encoder::TilesBuildOptions& b = o.build;
  const auto add = [&](const char* name, auto& value, const char* help) {
    return app.add_option(name, value, help)->group(kTilesGroup);
  };
  add("--tiles-frame", o.frame, "tiles: the capture frame the tiles are built from");
  add("--tiles-triangles", b.max_triangles,
      "tiles: L_tris, most triangles (2 per tile), respected exactly, >= 2");
  add("--tiles-overdraw", b.max_average_overdraw,
      "tiles: L_area, most average overdraw (the tiles' solid angle from the view region's centre "
      "over 4 pi), > 0");
  add("--tiles-peak-overdraw", b.max_peak_overdraw,
      "tiles: most modelled overdraw of any 90-degree view, > 0");
  add("--tiles-directions", b.overdraw_directions,
      "tiles: F, the 90-degree view directions the peak bound is modelled on, 6..4096");
  add("--tiles-merge-resolution", b.merge_resolution,
      "tiles: point-merging grid texels across a cube face, 0 = the capture's face size");
  app.add_option_function<std::vector<uint32_t>>(
         "--tiles-levels",
         [&b](const std::vector<uint32_t>& levels) {
           b.min_level = levels[0];
           b.max_level = levels[1];
         },
         "tiles: MIN,MAX quadtree levels of the candidate cells (2^level cells across a face), "
         "0 <= MIN <= MAX <= 10")
      ->delimiter(',')
      ->expected(2)
      ->default_str(fmt::format("{},{}", b.min_level, b.max_level))
      ->group(kTilesGroup);
  add("--tiles-min-cell-texels", b.min_cell_texels,
      "tiles: leaves are never finer than this many capture texels across (the leaf level "
      "becomes min(MAX, log2(face size / N)), at least MIN + 1); 0 = off (8: Seurat's levels 3-7 "
      "at 1024² faces; finer leaves carve into holes or let coarse many-layer cells win)")
      ->check(CLI::Range(0u, 16384u));
  add("--tiles-planes", b.max_planes, "tiles: K, most planes (tiles) per cell, 1..16");
  add("--tiles-ransac-trials", b.ransac_trials,
      "tiles: RANSAC trials of each cell's first plane, 1..4096");
  add("--tiles-ransac-threshold", b.ransac_threshold,
      "tiles: RANSAC inlier bound on the relative radial error, > 0");
  add("--tiles-min-cell-points", b.min_cell_points,
      "tiles: a cell with fewer merged points takes its parent's planes, >= 1");
  add("--tiles-refine-iterations", b.refine_iterations,
      "tiles: assign-and-refit iterations after each plane split, 1..256");
  add("--tiles-refine-samples", b.refine_sample_limit, "tiles: most points per plane refit, >= 16");
  add("--tiles-split-stop", b.split_stop_energy,
      "tiles: a cell stops splitting below this mean energy (relative radial error squared), "
      ">= 0");
  add("--tiles-dilation", b.tile_dilation,
      "tiles: each tile's cell grows by this fraction of its width per side, so neighbours "
      "overlap instead of cracking, 0..0.25");
  add("--tiles-selection-iterations", b.selection_iterations,
      "tiles: subgradient iterations of the Lagrangian selection, 1..20000");
  add("--tiles-texels-per-degree", b.texels_per_degree,
      "tiles: texture density per degree of a tile's angular width, 0 = twice the capture's "
      "(face size / 45)");
  add("--tiles-min-texels", b.min_tile_texels, "tiles: smallest tile texture side in texels, >= 2");
  add("--tiles-max-texels", b.max_tile_texels,
      "tiles: largest tile texture side in texels, <= 1024");
  add("--tiles-max-atlas", b.max_atlas_size,
      "tiles: largest atlas side; textures shrink uniformly to fit, 16..16384");
  add("--tiles-solid-threshold", b.solid_threshold,
      "tiles: Seurat's thresh_solid, relative distance of solid / free-space carving, [0, 1); 0 "
      "= the RANSAC threshold plus 1.25 face texel angles in radians (0.041 at 64² faces, 0.018 "
      "at 256², 0.014 at 512²) (Seurat's 0.01 carves holes into coarse tiles, docs/TILES.md)");
  app.add_flag("!--tiles-no-sky", b.sky_layer,
               "tiles: no sky layer (by default, where a view saw sky, one far opaque tile per "
               "root cell holds its colour, within the budgets; without it the set is "
               "transparent there)")
      ->group(kTilesGroup);
  add("--tiles-texture-solve", b.texture_solve_iterations,
      "tiles: conjugate-gradient steps of the least-squares colour fit (texels whose bilinear "
      "magnification best reproduces the samples), 0..1000; 0 keeps Seurat's filtered splat");
  add("--tiles-texture-smoothness", b.texture_smoothness,
      "tiles: membrane weight of the colour fit relative to a texel's sample weight, 0..100: "
      "larger is smoother, smaller follows the samples");
  add("--tiles-secondary-colour-weight", b.secondary_colour_weight,
      "tiles: weight of a sample's colour on the other tiles of its cell within the solid "
      "threshold (Seurat's crack mitigation) against 1 on its own tile, 0..1: 1 shares it fully "
      "(Seurat), smaller lets a tile's own samples outweigh a nearby surface's colour, 0 leaves "
      "cracks");
  add("--tiles-edge-colour-weight", b.edge_colour_weight,
      "tiles: weight of a colour sample at a view's depth edge (box-filtered texels that blend "
      "foreground and background) against 1 elsewhere, 0..1; 1 takes every sample alike");
  add("--tiles-edge-depth-ratio", b.edge_depth_ratio,
      "tiles: the relative depth step to a neighbouring texel that makes a texel an edge texel "
      "for --tiles-edge-colour-weight, (0, 100]");
  add_enum_option(app, "--tiles-alpha", b.alpha_estimate, kAlphaEstimates,
                  "tiles: alpha estimate: votes (each view votes solid where it sees the tile's "
                  "surface, free where it sees through it; alpha is the solid share, "
                  "anti-aliased) or constraints (Seurat's: nearest solid or free-space "
                  "constraint, hard)")
      ->group(kTilesGroup);
  add("--tiles-alpha-samples", b.alpha_supersampling,
      "tiles: S x S carving samples per texel for alpha, 1..8");
  add("--tiles-measure-directions", b.measure_directions,
      "tiles: 90-degree views per eye in which the built tiles' overdraw is measured, >= 6");
  add("--tiles-measure-resolution", b.measure_resolution,
      "tiles: side in px of each measured view, 8..1024");
  add_enum_option(app, "--tiles-atlas", o.encode.atlas_format, kAtlasFormats,
                  "tiles: atlas coding, bc7 (GPU-native, lossy) or rgba8 (lossless)")
      ->group(kTilesGroup);
  add("--tiles-bc7-quality", o.encode.bc7_quality,
      "tiles: BC7 search effort 0 (fast), 1, 2 (slow)");
}

int run(const CommonOptions& common, const TilesOptions& options) {
  encoder::TilesBuildOptions build = options.build;
  build.threads =
      common.threads > 0 ? common.threads : std::max(1u, std::thread::hardware_concurrency());
  encoder::TilesEncodeOptions encode = options.encode;
  encode.threads = common.threads;
  encode.supercompression = common.supercompression;
  encode.levels.compress_directory = !common.plain_directory;
  if (Status s = encoder::validate_tiles_build_options(build); !s.ok()) {
    return print_error("calf-encode", s, kExitUsage);
  }
  if (Status s = encoder::validate_tiles_encode_options(encode); !s.ok()) {
    return print_error("calf-encode", s, kExitUsage);
  }
  const std::filesystem::path dir = input_folder(common.input, capture::kManifestFileName);
  const std::string& out = common.output;
  const auto start = std::chrono::steady_clock::now();
  auto reader = capture::CaptureSetReader::open(dir, common.max_image_pixels);
  if (!reader.ok()) return fail(reader.status());

  // One progress line rewritten in place: the build of a 512² capture takes minutes.
  std::string_view last_stage;
  if (!common.quiet) {
    build.progress = [&last_stage](std::string_view stage, double fraction) {
      std::fprintf(stderr, "\rcalf-encode: tiles %-12.*s %3.0f %%", static_cast<int>(stage.size()),
                   stage.data(), 100.0 * fraction);
      last_stage = stage;
    };
  }
  encoder::TilesBuildReport report;
  auto tiles = encoder::build_tiles(*reader, options.frame, build, &report);
  if (!last_stage.empty()) std::fputc('\n', stderr);
  if (!tiles.ok()) return fail(tiles.status());

  auto writer = container::Writer::create(out, encode.levels);
  if (!writer.ok()) return fail(writer.status());
  const double fps = reader->manifest().fps;
  if (fps > 0 && fps <= 1e6) {
    // The frame's rate as a fraction over 1000 (the track's timing is informative for one frame).
    encode.fps_numerator = static_cast<uint32_t>(fps * 1000.0 + 0.5);
    encode.fps_denominator = 1000;
  }
  encoder::TilesEncodeStats stats;
  if (Status s = encoder::encode_tiles_track(*tiles, encode, &*writer, &stats); !s.ok()) {
    return fail(s);
  }
  if (Status s = writer->set_metadata("encoder", std::string("calf-encode ") + kVersionString);
      !s.ok()) {
    return fail(s);
  }
  if (Status s = writer->set_metadata("tiles_frame", std::to_string(options.frame)); !s.ok()) {
    return fail(s);
  }
  if (Status s = writer->finish(); !s.ok()) return fail(s);

  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::error_code ec;  // the size is informative: 0 if the file cannot be stat'ed
  const uintmax_t size = std::filesystem::file_size(out, ec);
  const uint64_t bytes = ec ? 0 : size;
  std::fprintf(stderr, "%s", encoder::format_tiles_report(report).c_str());
  std::fprintf(
      stderr,
      "calf-encode: wrote %s in %.2f s (tiles: %u tiles, %u triangles, atlas %u x %u "
      "%s at %.2f dB; %llu bytes: quads %llu, atlas %llu)\n",
      out.c_str(), seconds, stats.tiles, 2 * stats.tiles, stats.atlas_width, stats.atlas_height,
      encode.atlas_format == encoder::TilesAtlasFormat::kBc7 ? "BC7" : "RGBA8", stats.atlas_psnr_db,
      static_cast<unsigned long long>(bytes), static_cast<unsigned long long>(stats.quads_stored),
      static_cast<unsigned long long>(stats.atlas_stored));
  return 0;
}

}  // namespace calf::tools
