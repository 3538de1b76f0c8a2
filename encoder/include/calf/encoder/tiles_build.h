// The tiles builder (paper 000, Seurat): one frame of a capture set of a static view region in,
// a TileSet (calf/format/tile_set.h: budgeted layered quads with an RGBA atlas) out.
//
// Stages (docs/TILES.md describes each, what it keeps of the paper and what it changes):
//   1. Point merging (tiles_points.cc): every finite-depth texel of every view becomes a scene
//      point; points are binned into six perspective-space voxel grids around the view region's
//      centre O (face x face texel x log-radius) and each non-empty voxel keeps one merged point
//      (the weighted mean of its samples) with the count of samples it stands for.
//   2. Candidate tiles (tiles_candidates.cc): on each cube face's quadtree (levels min_level ..
//      max_level), every cell holding points is fitted with 1 .. max_planes planes (a RANSAC plane
//      with a deterministic seed per cell, refined by robust reweighted least squares on Seurat's
//      radial energy E = (1 - t_hit)^2, then divisive k-means style splitting); each k gives one
//      candidate tiling of the cell, a tile being the plane cut by the cell's (slightly dilated)
//      frustum from O.
//   3. Selection (tiles_select.cc): one tiling per covered cell or the union of its children's
//      (the And/Or tree of the quadtrees), minimising the total energy subject to
//      triangles <= max_triangles, average overdraw (sum of solid angles / 4 pi) <=
//      max_average_overdraw and, for each of `overdraw_directions` 90-degree views from O, the
//      modelled fill (bounded over the view region) <= max_peak_overdraw, by Lagrangian
//      relaxation with subgradient ascent on the dual and a final scaling of the multipliers
//      (exponential probe then bisection) that makes the answer feasible. The returned set always
//      satisfies the three modelled bounds; the triangle bound is exact.
//   4. Texturing (tiles_texture.cc): per tile a square texture sized by its angular extent
//      (texels_per_degree), corners on texel centres, projective (homogeneous) coordinates.
//      Silhouettes by carving: each capture view votes, per alpha supersample, solid where it
//      sees the tile's own surface and free where it sees through the tile (or, as Seurat, solid
//      and free constraints resolved by the nearest one: alpha_estimate); colour by projecting
//      each sample from O onto its cell's tiles, then a least-squares fit of the texels to the
//      samples under the renderer's bilinear magnification (tiles_texture_solve.cc).
//   5. Atlas (tiles_atlas.cc): textures sorted by size and packed in shelves with a one-texel pad
//      (edge texels repeated), RGB sRGB-encoded and premultiplied, as tile_set.h specifies.
//   6. Measurement (tiles_overdraw.cc): the built tiles rasterised (coverage count, alpha ignored:
//      what the GPU fills) in 90-degree views from O and from every capture viewpoint.
//
// Deterministic: the same capture set and options give the same TileSet bytes for any `threads`.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <string_view>

#include "calf/capture/capture_set.h"
#include "calf/format/status.h"
#include "calf/format/tile_set.h"

namespace calf::encoder {

// The texturing stage's alpha estimate (TilesBuildOptions::alpha_estimate).
enum class TilesAlphaEstimate : uint8_t { kViewVotes, kConstraints };

struct TilesBuildOptions {
  // --- budget (Seurat's L_tris, L_area, L_peakOD and F) ---
  // Most triangles in the output (2 per tile); respected exactly. >= 2.
  uint32_t max_triangles = 72000;
  // Most average overdraw: the tiles' total solid angle seen from O over 4 pi. > 0.
  double max_average_overdraw = 3.0;
  // Most modelled fill of any of the `overdraw_directions` 90-degree views from O, each tile's
  // solid angle bounded over the view region (see overdraw_region_bound). > 0.
  double max_peak_overdraw = 5.0;
  // F, the number of view directions (a spherical Fibonacci set) the peak bound is modelled on.
  // 6 .. 4096.
  uint32_t overdraw_directions = 126;
  // Whether a tile's fill is bounded over the view region: its solid angle times
  // (r / (r - R))^2, r its nearest corner's distance from O, R the view region's half diagonal
  // (r - R clamped to r / 4). Off: the solid angle from O.
  bool overdraw_region_bound = true;

  // --- point merging ---
  // Voxel grid resolution per cube face (texels of the merge grid across a face); 0 = the capture
  // set's face size. The radial bins have the same relative size (2 / resolution in log radius).
  uint32_t merge_resolution = 0;

  // --- candidate tiles ---
  // Quadtree levels (cells 2^level across a face): roots at min_level, leaves at max_level.
  // 0 <= min_level <= max_level <= 10.
  uint32_t min_level = 3;
  uint32_t max_level = 7;
  // Leaves are never finer than this many capture texels across: the leaf level used is
  // min(max_level, floor(log2(face_size / min_cell_texels))), but at least min_level + 1 (so a
  // small capture still has a quadtree to choose in; max_level permitting). 0 = off. The default
  // 8 is Seurat's levels 3-7 at a 1024² capture. Finer leaves hold a point or two (their tiles are
  // carved into holes), and with room for them the selection, which minimises the fit energy
  // only, also takes coarse cells of many overlapping layers whose silhouettes are cut by alpha.
  // Path PSNR on interior (docs/TILES.md), leaf texels: 64² faces 8 (roots only) 31.25 dB, 4
  // 32.60, 2 32.42, 0.5 31.90; 256² 8 38.17, 4 38.11, 2 38.08; 512² 16 38.42, 8 38.92, 4 36.53.
  uint32_t min_cell_texels = 8;
  // Most planes (tiles) per cell, K. 1 .. 16.
  uint32_t max_planes = 8;
  // RANSAC trials of the first plane of each cell (seeded by the cell, so deterministic), >= 1,
  // and the inlier threshold on |1 - t_hit| (relative radial error), > 0.
  uint32_t ransac_trials = 32;
  double ransac_threshold = 0.01;
  // Cells (below the roots) with fewer merged points than this take their parent's planes (those
  // their points choose) instead of fitting their own: a plane through one or two points fits
  // them exactly and says nothing of the surface. >= 1.
  uint32_t min_cell_points = 16;
  // k-means iterations (assign, refit) after each split, >= 1.
  uint32_t refine_iterations = 4;
  // Most points each refit uses (an evenly strided subset; the final assignment and the energy
  // use every point), >= 16.
  uint32_t refine_sample_limit = 2048;
  // A cell stops splitting once its tiling's mean energy falls below this (relative radial error
  // squared), >= 0.
  double split_stop_energy = 1e-6;
  // Each tile's cell is dilated by this fraction of its width on every side so that neighbouring
  // tiles overlap instead of cracking (Seurat dilates its tiles too). 0 .. 0.25.
  double tile_dilation = 0.02;

  // The sky layer: where some view saw sky (no depth), one far (100 times the farthest point),
  // opaque tile per root cell in those directions, coloured by the views' sky texels, drawn behind
  // everything. Its triangles, its share of the average overdraw and one layer of peak overdraw
  // come off the budgets before the selection. false: the set is transparent where the sky is
  // (Seurat's scenes are closed; a model against the sky then plays against black).
  bool sky_layer = true;

  // --- selection ---
  // Subgradient iterations on the dual, >= 1.
  uint32_t selection_iterations = 150;

  // --- texturing ---
  // Texels per degree of a tile's angular width seen from O; 0 = twice the capture's density
  // (face size / 45). The capture's own density (face size / 90, Seurat's "one texel per pixel"
  // at the capture's resolution) blurs: colour is splatted bilinearly from samples that land
  // between texel centres. Measured on interior (64² faces, docs/TILES.md): 31.3 dB at the
  // capture's density, 32.3 dB at twice it, 31.6 dB at 2.8 times.
  double texels_per_degree = 0;
  // Smallest and largest tile texture side (texels, corners included). 2 <= min <= max <= 1024.
  uint32_t min_tile_texels = 2;
  uint32_t max_tile_texels = 64;
  // Largest atlas side; when the textures do not fit, every tile side is scaled down uniformly
  // until they do (no content-adaptive choice). 16 .. 16384.
  uint32_t max_atlas_size = 8192;
  // Seurat's thresh_solid: a sample makes secondary solid constraints on other layers with
  // |t_hit - 1| below it, and a view marks free space only where its ray passes a tile more than
  // this relative distance before its surface. [0, 1); 0 = from the capture's resolution:
  // ransac_threshold + 1.25 x a face texel's angle in radians (pi / 2 / face size), i.e. 0.041,
  // 0.018 and 0.014 for 64², 256² and 512² faces: a surface lies up to the plane fit's tolerance
  // off its tile, plus the depth change across one texel at 45 degrees, where a view's centre-ray
  // depth stands for its whole texel. Seurat's 0.01 suits its fine tilings and carves holes into
  // coarse tiles (interior 64², docs/TILES.md: 23.9 dB at 0.01, 29.3 at 0.05). Measured with the
  // player's occlusion pass (docs/TILES.md "Occlusion pass and the solid threshold"; capture
  // viewpoints / novel views, dB, 0.05 -> auto): interior 64² 36.90 / 33.87 -> 37.01 / 33.88,
  // 256² 39.23 / 41.76 -> 40.75 / 42.84, 512² 38.17 / 42.40 -> 40.44 / 43.65; off the project's
  // content it costs on novel views (CesiumMilkTruck -0.16 dB, turntable -0.59, box rigs outside
  // them).
  double solid_threshold = 0;
  // Colour by least squares (tiles_texture_solve.cc): conjugate-gradient steps towards the texel
  // values whose bilinear interpolation (the renderer's magnification) best fits the samples,
  // starting from Seurat's filtered splat; 0 keeps the splat. 0 .. 1000.
  uint32_t texture_solve_iterations = 32;
  // The fit's membrane (smoothness) weight relative to a texel's mean sample weight: larger
  // blurs towards the splat's look, smaller follows the samples (and their disagreements) more
  // closely. Texels no sample reaches are filled harmonically either way. [0, 100].
  double texture_smoothness = 0.2;
  // The weight of a sample's colour on its secondary tiles (those of its cell whose planes lie
  // within solid_threshold of it, Seurat's crack mitigation) relative to its primary tile's 1.
  // 1 shares it fully (Seurat); below 1 a tile's own samples outweigh the colour of a nearby
  // surface (a crease's side face) where it has any. [0, 1]. Measured on interior (docs/TILES.md,
  // capture viewpoints / path, dB, 1 -> 0.5): 64² 36.05 / 33.42 -> 36.12 / 33.42, 256²
  // 37.03 / 40.12 -> 37.30 / 40.27, 512² 35.29 / 39.98 -> 35.54 / 40.02; 0 leaves cracks.
  double secondary_colour_weight = 0.5;
  // The weight of a colour sample at a view's depth edge (a texel with a 4-neighbour on its face
  // more than edge_depth_ratio nearer or farther, or sky beside a surface) relative to 1
  // elsewhere: a box-filtered capture's edge texels blend foreground and background, which the
  // tiles' own alpha then blends a second time; other views, and the texels beside the edge, see
  // the same surface unblended. [0, 1]; 1 = every sample alike (no edge weight). Measured
  // (docs/TILES.md "Edge colour weight", capture viewpoints / novel views, dB, 1 -> 0.3): interior
  // 64² 36.12 / 33.42 -> 36.27 / 33.58, 256² 37.30 / 40.27 -> 37.69 / 40.36, 512² 35.54 / 40.02
  // -> 35.65 / 40.08; CesiumMilkTruck 256² 50.88 / 32.04 -> 50.92 / 32.19.
  double edge_colour_weight = 0.3;
  // The relative depth step that makes a texel an edge texel (above), (0, 100].
  double edge_depth_ratio = 0.05;
  // How a supersample's alpha is estimated (docs/TILES.md "Alpha"):
  //  - kViewVotes: each view votes solid where it sees this tile's own surface at the supersample
  //    and free where its ray passes the supersample before reaching its surface; alpha is the
  //    share of solid votes. Every view's silhouette staircase lies at its own sub-pixel offset,
  //    so the share anti-aliases the edge. Measured on interior at 256² (capture viewpoints /
  //    novel views): 37.2 / 40.2 dB against 35.8 / 38.6 with kConstraints.
  //  - kConstraints: Seurat's: solid constraints where samples land (one supersample each),
  //    free space where a view's ray passes; supersamples holding both are dropped, and each
  //    supersample takes the class of its nearest constraint (hard, 0 or 1).
  TilesAlphaEstimate alpha_estimate = TilesAlphaEstimate::kViewVotes;
  // Alpha supersampling: S x S silhouette samples per texel. 1 .. 8.
  uint32_t alpha_supersampling = 2;

  // --- measurement ---
  // Directions of the measured overdraw (per eye: O and every capture viewpoint), >= 6, and the
  // side of each measured 90-degree view in pixels, 8 .. 1024.
  uint32_t measure_directions = 126;
  uint32_t measure_resolution = 64;

  // --- execution ---
  // Worker threads, >= 1. The output does not depend on it.
  uint32_t threads = 1;
  // Called from the calling thread with a stage name and the fraction done in [0, 1] (optional).
  std::function<void(std::string_view stage, double fraction)> progress;
};

struct TilesBuildReport {
  // Input.
  uint32_t views = 0, face_size = 0;
  uint64_t samples = 0;        // finite-depth texels read
  uint64_t merged_points = 0;  // after point merging
  uint64_t candidate_cells = 0, candidate_tilings = 0, candidate_tiles = 0;
  uint32_t min_level = 0, max_level = 0;  // the quadtree levels used (after min_cell_texels)
  // Selection.
  uint32_t tiles = 0, triangles = 0;  // the sky layer's included
  uint32_t sky_tiles = 0;             // of them the sky layer's
  double distortion = 0;              // sum over merged points of weight x E of the selection
  double dual_bound = 0;              // best Lagrangian dual value (a lower bound on distortion)
  uint32_t selection_evaluations = 0;
  // Modelled (what the selection constrained) and measured overdraw, with their bounds.
  double model_average_overdraw = 0, model_peak_overdraw = 0;
  double measured_mean_overdraw = 0, measured_peak_overdraw = 0;
  uint32_t measured_max_layers = 0;  // the largest per-pixel tile count seen
  uint32_t measured_views = 0;       // eyes x directions
  uint32_t max_triangles = 0;
  double max_average_overdraw = 0, max_peak_overdraw = 0;
  // Texture.
  uint64_t tile_texels = 0;  // sum of tile texture areas (without pads)
  uint32_t atlas_width = 0, atlas_height = 0;
  double atlas_occupancy = 0;                       // tile_texels / atlas area, percent
  double texels_per_degree = 0, texture_scale = 1;  // the density used and the fit-down factor
  double solid_threshold = 0;                       // the threshold used (options' 0 resolved)
  // Wall seconds per stage (informative).
  double seconds_merge = 0, seconds_candidates = 0, seconds_select = 0, seconds_texture = 0,
         seconds_atlas = 0, seconds_measure = 0, seconds_total = 0;
};

// Checks every option's range (CALF-E250 naming the option and its range).
Status validate_tiles_build_options(const TilesBuildOptions& options);

// Builds the tile set of frame `frame` of `reader`'s capture set for its view volume.
// Errors: E250 an option out of range; E251 `frame` outside the set; E252 an empty capture (no
// finite depth in the frame); E253 the budget cannot cover the captured directions (even one tile
// per covered root cell breaks a bound; the message names the bound and the least it needs);
// E254 the atlas cannot hold the textures at the smallest tile size; the reader's errors (E135 -
// E140) for unreadable images.
Expected<TileSet> build_tiles(const capture::CaptureSetReader& reader, uint32_t frame,
                              const TilesBuildOptions& options, TilesBuildReport* report = nullptr);

// The report as a few lines of text (stage seconds, triangles, overdraw against the bounds,
// texels, atlas), for commands and benches.
std::string format_tiles_report(const TilesBuildReport& report);

}  // namespace calf::encoder
