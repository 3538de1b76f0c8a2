// The tiles builder's driver: options, errors, the stages in order, the report (tiles_build.h).
#include "calf/encoder/tiles_build.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <string>

#include <cstdarg>
#include <cstdio>

#include "tiles_internal.h"

namespace calf::encoder {

namespace {

// printf into a std::string (the library layers do not link fmt).
std::string sformat(const char* format, ...) __attribute__((format(printf, 1, 2)));
std::string sformat(const char* format, ...) {
  va_list args;
  va_start(args, format);
  va_list copy;
  va_copy(copy, args);
  const int n = std::vsnprintf(nullptr, 0, format, copy);
  va_end(copy);
  std::string out(n > 0 ? size_t(n) : 0, '\0');
  if (n > 0) std::vsnprintf(out.data(), out.size() + 1, format, args);
  va_end(args);
  return out;
}

// Upper bounds of the iteration and trial counts (docs/TILES.md; CALF-E250 above them): each is
// tens to hundreds of times its default, far past where the result stops changing, and keeps a
// build's time bounded.
constexpr uint32_t kTilesMaxRansacTrials = 4096;
constexpr uint32_t kTilesMaxRefineIterations = 256;
constexpr uint32_t kTilesMaxSelectionIterations = 20000;
// The farthest a captured surface (or the view region's corner) may lie from the view region's
// centre, in scene units (CALF-E201 beyond): tiles reach a few times that far and the sky layer
// 100 times, which keeps every corner within the tiles track's +-1e12.
constexpr double kTilesMaxDistance = 1e9;

Status bad_option(const std::string& what) {
  return Status(ErrorId::kTilesOption, what);
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// The share of the merged points' weight (captured samples) inside the view volume.
double share_inside_view_volume(const tiles::MergedPoints& points, const Vec3& origin,
                                const Box3& volume) {
  double inside = 0, total = 0;
  for (size_t i = 0; i < points.position.size(); ++i) {
    total += points.weight[i];
    if (volume.contains(points.position[i] + origin)) inside += points.weight[i];
  }
  return total > 0 ? inside / total : 0;
}

}  // namespace

Status validate_tiles_build_options(const TilesBuildOptions& o) {
  if (o.max_triangles < 2)
    return bad_option(sformat("max_triangles %u is below 2", o.max_triangles));
  if (!(o.max_average_overdraw > 0) || !std::isfinite(o.max_average_overdraw)) {
    return bad_option(
        sformat("max_average_overdraw %g is not a finite number > 0", o.max_average_overdraw));
  }
  if (!(o.max_peak_overdraw > 0) || !std::isfinite(o.max_peak_overdraw)) {
    return bad_option(
        sformat("max_peak_overdraw %g is not a finite number > 0", o.max_peak_overdraw));
  }
  if (o.overdraw_directions < 6 || o.overdraw_directions > 4096) {
    return bad_option(
        sformat("overdraw_directions %u is outside [6, 4096]", o.overdraw_directions));
  }
  if (o.merge_resolution > 16384) {
    return bad_option(sformat("merge_resolution %u is above 16384", o.merge_resolution));
  }
  if (o.min_cell_texels > 16384) {
    return bad_option(sformat("min_cell_texels %u is above 16384", o.min_cell_texels));
  }
  if (o.max_level > 10 || o.min_level > o.max_level) {
    return bad_option(sformat("levels %u .. %u are not 0 <= min_level <= max_level <= 10",
                              o.min_level, o.max_level));
  }
  if (o.max_planes < 1 || o.max_planes > 16) {
    return bad_option(sformat("max_planes %u is outside [1, 16]", o.max_planes));
  }
  if (o.ransac_trials < 1 || o.ransac_trials > kTilesMaxRansacTrials) {
    return bad_option(
        sformat("ransac_trials %u is outside [1, %u]", o.ransac_trials, kTilesMaxRansacTrials));
  }
  if (!(o.ransac_threshold > 0) || !std::isfinite(o.ransac_threshold)) {
    return bad_option(
        sformat("ransac_threshold %g is not a finite number > 0", o.ransac_threshold));
  }
  if (o.min_cell_points < 1) return bad_option("min_cell_points must be >= 1");
  if (o.refine_iterations < 1 || o.refine_iterations > kTilesMaxRefineIterations) {
    return bad_option(sformat("refine_iterations %u is outside [1, %u]", o.refine_iterations,
                              kTilesMaxRefineIterations));
  }
  if (o.refine_sample_limit < 16) {
    return bad_option(sformat("refine_sample_limit %u is below 16", o.refine_sample_limit));
  }
  if (!(o.split_stop_energy >= 0) || !std::isfinite(o.split_stop_energy)) {
    return bad_option(
        sformat("split_stop_energy %g is not a finite number >= 0", o.split_stop_energy));
  }
  if (!(o.tile_dilation >= 0 && o.tile_dilation <= 0.25)) {
    return bad_option(sformat("tile_dilation %g is outside [0, 0.25]", o.tile_dilation));
  }
  if (o.selection_iterations < 1 || o.selection_iterations > kTilesMaxSelectionIterations) {
    return bad_option(sformat("selection_iterations %u is outside [1, %u]", o.selection_iterations,
                              kTilesMaxSelectionIterations));
  }
  if (!(o.texels_per_degree >= 0) || !std::isfinite(o.texels_per_degree) ||
      o.texels_per_degree > 1000) {
    return bad_option(sformat("texels_per_degree %g is outside [0, 1000]", o.texels_per_degree));
  }
  if (o.min_tile_texels < 2 || o.min_tile_texels > o.max_tile_texels || o.max_tile_texels > 1024) {
    return bad_option(sformat("tile texels %u .. %u are not 2 <= min <= max <= 1024",
                              o.min_tile_texels, o.max_tile_texels));
  }
  if (o.max_atlas_size < 16 || o.max_atlas_size > 16384) {
    return bad_option(sformat("max_atlas_size %u is outside [16, 16384]", o.max_atlas_size));
  }
  if (!(o.solid_threshold >= 0 && o.solid_threshold < 1)) {
    return bad_option(sformat("solid_threshold %g is outside [0, 1)", o.solid_threshold));
  }
  if (o.texture_solve_iterations > 1000) {
    return bad_option(
        sformat("texture_solve_iterations %u is above 1000", o.texture_solve_iterations));
  }
  if (!(o.edge_colour_weight >= 0 && o.edge_colour_weight <= 1)) {
    return bad_option(sformat("edge_colour_weight %g is outside [0, 1]", o.edge_colour_weight));
  }
  if (!(o.edge_depth_ratio > 0 && o.edge_depth_ratio <= 100)) {
    return bad_option(sformat("edge_depth_ratio %g is outside (0, 100]", o.edge_depth_ratio));
  }
  if (!(o.secondary_colour_weight >= 0 && o.secondary_colour_weight <= 1)) {
    return bad_option(
        sformat("secondary_colour_weight %g is outside [0, 1]", o.secondary_colour_weight));
  }
  if (!(o.texture_smoothness >= 0 && o.texture_smoothness <= 100)) {
    return bad_option(sformat("texture_smoothness %g is outside [0, 100]", o.texture_smoothness));
  }
  if (o.alpha_supersampling < 1 || o.alpha_supersampling > 8) {
    return bad_option(sformat("alpha_supersampling %u is outside [1, 8]", o.alpha_supersampling));
  }
  if (o.measure_directions < 6 || o.measure_directions > 4096) {
    return bad_option(sformat("measure_directions %u is outside [6, 4096]", o.measure_directions));
  }
  if (o.measure_resolution < 8 || o.measure_resolution > 1024) {
    return bad_option(sformat("measure_resolution %u is outside [8, 1024]", o.measure_resolution));
  }
  if (o.threads < 1 || o.threads > 256) {
    return bad_option(sformat("threads %u is outside [1, 256]", o.threads));
  }
  return Status::Ok();
}

Expected<TileSet> build_tiles(const capture::CaptureSetReader& reader, uint32_t frame,
                              const TilesBuildOptions& requested, TilesBuildReport* report) {
  using namespace tiles;
  const auto t_start = std::chrono::steady_clock::now();
  CALF_RETURN_IF_ERROR(validate_tiles_build_options(requested));
  const capture::CaptureManifest& m = reader.manifest();
  TilesBuildOptions options = requested;
  if (options.min_cell_texels > 0) {
    uint32_t level = 0;
    while (level < 10 && (m.face_size >> (level + 1)) >= options.min_cell_texels) ++level;
    level = std::max(level, options.min_level + 1);
    options.max_level = std::min(options.max_level, level);
  }
  if (frame >= m.frame_count) {
    return Status(ErrorId::kTilesFrame,
                  sformat("%s: frame %u is outside the capture set's %u frames (0 .. %u)",
                          reader.directory().string().c_str(), frame, m.frame_count,
                          m.frame_count == 0 ? 0 : m.frame_count - 1));
  }
  if (m.viewpoints.empty() || m.face_size == 0) {
    return Status(ErrorId::kTilesEmpty,
                  sformat("%s: the capture set has no views", reader.directory().string().c_str()));
  }
  TilesBuildReport r;
  r.views = static_cast<uint32_t>(m.viewpoints.size());
  r.face_size = m.face_size;
  r.min_level = options.min_level;
  r.max_level = options.max_level;
  r.max_triangles = options.max_triangles;
  r.max_average_overdraw = options.max_average_overdraw;
  r.max_peak_overdraw = options.max_peak_overdraw;

  Frame f;
  f.origin = (m.view_volume.min + m.view_volume.max) * 0.5;
  f.region_radius = 0.5 * length(m.view_volume.max - m.view_volume.min);
  f.face_size = m.face_size;
  for (const auto& v : m.viewpoints) f.viewpoints.push_back(v.position);

  // 1. Point merging.
  auto t0 = std::chrono::steady_clock::now();
  CALF_ASSIGN_OR_RETURN(const MergedPoints points, merge_points(reader, frame, f, options));
  r.samples = points.samples;
  r.merged_points = points.position.size();
  r.seconds_merge = seconds_since(t0);
  if (points.position.empty()) {
    return Status(ErrorId::kTilesEmpty,
                  sformat("%s: frame %u has no finite depth outside the view region's core in "
                          "any of its %zu views",
                          reader.directory().string().c_str(), frame, m.viewpoints.size()));
  }

  if (!(std::max(points.max_radius, f.region_radius) <= kTilesMaxDistance)) {
    return Status(ErrorId::kEncoderInput,
                  sformat("%s: frame %u: %s lies %g scene units from the view region's centre, "
                          "beyond the %g a tiles track can hold (its tiles and sky layer would "
                          "leave the track's +-1e12 coordinates); give such far surfaces as sky "
                          "(infinite depth)",
                          reader.directory().string().c_str(), frame,
                          points.max_radius >= f.region_radius ? "a captured surface"
                                                               : "the view region's corner",
                          std::max(points.max_radius, f.region_radius), kTilesMaxDistance));
  }

  // 2. Candidates.
  t0 = std::chrono::steady_clock::now();
  if (options.progress) options.progress("candidates", 0.0);
  const Candidates candidates = generate_candidates(points, f, options);
  r.candidate_cells = candidates.cells.size();
  r.candidate_tilings = candidates.tilings.size();
  r.candidate_tiles = candidates.planes.size();
  r.seconds_candidates = seconds_since(t0);
  if (options.progress) options.progress("candidates", 1.0);

  // The sky layer: one far, opaque tile per root cell in which some view saw sky, so that a model
  // against the sky does not play against black. Its triangles and fill come off the budgets the
  // selection gets: the whole set stays within them.
  std::vector<Selected> sky;
  double sky_area = 0;
  {
    const uint32_t side = 1u << options.min_level;
    // Far enough that moving through the view region barely moves it (1 % parallax at most).
    const double distance = 100.0 * std::max(points.max_radius, f.region_radius);
    for (size_t k = 0; k < points.sky_roots.size(); ++k) {
      if (!points.sky_roots[k]) continue;
      Selected s;
      s.cell = {static_cast<uint8_t>(k / (size_t{side} * side)),
                static_cast<uint8_t>(options.min_level), static_cast<uint32_t>(k % side),
                static_cast<uint32_t>((k / side) % side)};
      FaceCoord c;
      c.face = cube_face_from_index(s.cell.face);
      c.s = (s.cell.i + 0.5) / side;
      c.t = (s.cell.j + 0.5) / side;
      s.plane = {direction_from_face_coord(c), distance};
      s.sky = true;
      sky.push_back(s);
      sky_area += cell_solid_angle(s.cell, options.tile_dilation) / (4 * 3.14159265358979323846);
    }
  }
  r.sky_tiles = static_cast<uint32_t>(sky.size());
  TilesBuildOptions selection_options = options;
  if (!sky.empty()) {
    const uint64_t sky_triangles = 2 * uint64_t{sky.size()};
    if (sky_triangles + 2 * candidates.roots.size() > options.max_triangles ||
        sky_area >= options.max_average_overdraw || options.max_peak_overdraw <= 1) {
      return Status(
          ErrorId::kTilesBudget,
          sformat("budget too small to cover the view region and its sky: the sky "
                  "layer needs %llu triangles, average overdraw %.3f and peak overdraw "
                  "1 besides the %zu tiles of the coarsest tiling (budgets: %u "
                  "triangles, average %g, peak %g; --tiles-no-sky leaves the sky out)",
                  (unsigned long long)sky_triangles, sky_area, candidates.roots.size(),
                  options.max_triangles, options.max_average_overdraw, options.max_peak_overdraw));
    }
    selection_options.max_triangles = options.max_triangles - static_cast<uint32_t>(sky_triangles);
    selection_options.max_average_overdraw = options.max_average_overdraw - sky_area;
    // A sky tile adds one layer to any view at most.
    selection_options.max_peak_overdraw = options.max_peak_overdraw - 1;
  }

  // 3. Selection.
  t0 = std::chrono::steady_clock::now();
  Expected<Selection> selected = select_tiles(candidates, f, selection_options);
  if (!selected.ok() && selected.status().id() == ErrorId::kTilesBudget) {
    // A capture around a model (a model file's default ring, turntable's sphere) puts the model
    // inside the view region, where Seurat's model is not defined: say so rather than leave the
    // user to raise budgets that no setting meets.
    const double inside = share_inside_view_volume(points, f.origin, m.view_volume);
    if (inside >= 0.01) {
      return Status(
          ErrorId::kTilesBudget,
          selected.status().message() +
              sformat("; %.0f %% of the captured surface lies inside the view region (%g,%g,%g "
                      ".. %g,%g,%g), where layered tiles are not defined: capture from a rig "
                      "beside the model, e.g. --rig box:..., not around it (docs/TILES.md, "
                      "\"Content from outside the project\")",
                      100 * inside, m.view_volume.min.x, m.view_volume.min.y, m.view_volume.min.z,
                      m.view_volume.max.x, m.view_volume.max.y, m.view_volume.max.z));
    }
  }
  if (!selected.ok()) return selected.status();
  Selection selection = std::move(*selected);
  selection.tiles.insert(selection.tiles.end(), sky.begin(), sky.end());
  if (!sky.empty()) {
    selection.average_overdraw += sky_area;
    selection.peak_overdraw += 1;
  }
  r.tiles = static_cast<uint32_t>(selection.tiles.size());
  r.triangles = 2 * r.tiles;
  r.distortion = selection.distortion;
  r.dual_bound = selection.dual_bound;
  r.selection_evaluations = selection.evaluations;
  r.model_average_overdraw = selection.average_overdraw;
  r.model_peak_overdraw = selection.peak_overdraw;
  r.seconds_select = seconds_since(t0);

  // 4. Texture sizes by angular extent, scaled down uniformly until the atlas fits.
  t0 = std::chrono::steady_clock::now();
  const double tpd = options.texels_per_degree > 0 ? options.texels_per_degree : m.face_size / 45.0;
  r.texels_per_degree = tpd;
  std::vector<double> degrees(selection.tiles.size());
  for (size_t k = 0; k < selection.tiles.size(); ++k) {
    const CellId& c = selection.tiles[k].cell;
    const Vec3 a = cell_corner_direction(c, options.tile_dilation, 0);
    const Vec3 b = cell_corner_direction(c, options.tile_dilation, 1);
    const Vec3 d = cell_corner_direction(c, options.tile_dilation, 3);
    degrees[k] =
        std::max(angle_between(a, b), angle_between(a, d)) * (180.0 / 3.14159265358979323846);
  }
  std::vector<uint32_t> sides(selection.tiles.size());
  std::vector<AtlasPlacement> placements;
  uint32_t width = 0, height = 0;
  double scale = 1;
  for (int attempt = 0;; ++attempt) {
    bool all_min = true;
    uint64_t area = 0;
    for (size_t k = 0; k < sides.size(); ++k) {
      const double want = std::ceil(degrees[k] * tpd * scale) + 1;
      sides[k] = static_cast<uint32_t>(
          std::clamp(want, double(options.min_tile_texels), double(options.max_tile_texels)));
      all_min &= sides[k] == options.min_tile_texels;
      area += uint64_t{sides[k] + 2} * (sides[k] + 2);
    }
    if (pack_atlas(sides, options.max_atlas_size, &placements, &width, &height)) break;
    if (all_min || attempt >= 40) {
      return Status(ErrorId::kTilesAtlas,
                    sformat("%zu tiles of at least %u^2 texels (with pads) do not fit a %u^2 "
                            "atlas (max_atlas_size)",
                            sides.size(), options.min_tile_texels + 2, options.max_atlas_size));
    }
    const double fill = double(options.max_atlas_size) * options.max_atlas_size / double(area);
    scale *= std::min(0.9, std::sqrt(fill) * 0.95);
  }
  r.texture_scale = scale;
  // 0: the plane fit's tolerance plus the depth change across one texel at 45 degrees.
  TilesBuildOptions texture_options = options;
  if (texture_options.solid_threshold == 0) {
    texture_options.solid_threshold =
        std::min(0.5, options.ransac_threshold + 1.25 * (std::numbers::pi / 2) / m.face_size);
  }
  r.solid_threshold = texture_options.solid_threshold;
  for (uint32_t s : sides) r.tile_texels += uint64_t{s} * s;
  CALF_ASSIGN_OR_RETURN(const std::vector<TileTexture> textures,
                        texture_tiles(reader, frame, f, selection, sides, texture_options));
  r.seconds_texture = seconds_since(t0);

  // 5. Atlas.
  t0 = std::chrono::steady_clock::now();
  TileSet set = write_tile_set(f, m.view_volume, selection, textures, placements, width, height,
                               options.tile_dilation);
  r.atlas_width = width;
  r.atlas_height = height;
  r.atlas_occupancy = 100.0 * double(r.tile_texels) / (double(width) * height);
  r.seconds_atlas = seconds_since(t0);

  // 6. Measured overdraw from O and every capture viewpoint.
  t0 = std::chrono::steady_clock::now();
  if (options.progress) options.progress("measure", 0.0);
  std::vector<Vec3> eyes{f.origin};
  for (const Vec3& v : f.viewpoints) {
    if (!(v == f.origin)) eyes.push_back(v);
  }
  const OverdrawMeasure od = measure_overdraw(set, eyes, options.measure_directions,
                                              options.measure_resolution, options.threads);
  r.measured_mean_overdraw = od.mean;
  r.measured_peak_overdraw = od.peak;
  r.measured_max_layers = od.max_layers;
  r.measured_views = od.views;
  r.seconds_measure = seconds_since(t0);
  if (options.progress) options.progress("measure", 1.0);
  r.seconds_total = seconds_since(t_start);
  if (report) *report = r;
  return set;
}

std::string format_tiles_report(const TilesBuildReport& r) {
  std::string s;
  s += sformat("input      %u views x 6 x %u^2, %llu samples -> %llu merged points\n", r.views,
               r.face_size, (unsigned long long)r.samples, (unsigned long long)r.merged_points);
  s += sformat("candidates %llu cells at levels %u .. %u, %llu tilings, %llu tiles\n",
               (unsigned long long)r.candidate_cells, r.min_level, r.max_level,
               (unsigned long long)r.candidate_tilings, (unsigned long long)r.candidate_tiles);
  s += sformat(
      "selection  %u tiles (%u of them the sky layer), %u triangles (bound %u), distortion %.6g "
      "(dual bound %.6g), %u evaluations\n",
      r.tiles, r.sky_tiles, r.triangles, r.max_triangles, r.distortion, r.dual_bound,
      r.selection_evaluations);
  s += sformat("overdraw   modelled: average %.3f (bound %g), peak %.3f (bound %g)\n",
               r.model_average_overdraw, r.max_average_overdraw, r.model_peak_overdraw,
               r.max_peak_overdraw);
  s += sformat(
      "overdraw   measured over %u views: mean %.3f (bound %g), peak %.3f (bound %g), "
      "most layers on a pixel %u\n",
      r.measured_views, r.measured_mean_overdraw, r.max_average_overdraw, r.measured_peak_overdraw,
      r.max_peak_overdraw, r.measured_max_layers);
  s += sformat(
      "texture    %llu tile texels at %.2f texels/degree (scale %.3f), atlas %u x %u, "
      "occupancy %.1f %%, solid threshold %.4f\n",
      (unsigned long long)r.tile_texels, r.texels_per_degree, r.texture_scale, r.atlas_width,
      r.atlas_height, r.atlas_occupancy, r.solid_threshold);
  s += sformat(
      "seconds    merge %.2f, candidates %.2f, select %.2f, texture %.2f, atlas %.2f, "
      "measure %.2f, total %.2f\n",
      r.seconds_merge, r.seconds_candidates, r.seconds_select, r.seconds_texture, r.seconds_atlas,
      r.seconds_measure, r.seconds_total);
  return s;
}

}  // namespace calf::encoder
