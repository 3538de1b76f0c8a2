// calf-encode: a capture set in, a .calf with a lightfield track out (paper 002, Sec. 5;
// format/SPEC.md §11.1); with --mode mesh a scene file in, a mesh track out (§11.4). Errors are one
// line with a stable id and exit status 1 (no output file is left behind, also when SIGINT /
// SIGTERM / SIGHUP end it); usage errors exit 2 (command_line.h).
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include "calf/capture/capture_shard.h"
#include "calf/encoder/lightfield_encode.h"
#include "calf/encoder/lightfield_shard.h"
#include "calf/encoder/mesh_encode.h"
#include "calf/encoder/noise_estimate.h"
#include "calf/encoder/surfels_build.h"
#include "calf/encoder/visible_set.h"
#include "calf_encode/tiles_mode.h"
#include "command_line.h"

namespace {

int fail(const calf::Status& status) {
  return calf::tools::print_error("calf-encode", status);
}

double peak_rss_mib() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_maxrss) / 1024.0;  // Linux: KiB
}

}  // namespace

// The --visible-set options of --mode mesh (docs/VISIBILITY.md).
struct VisibleSetFlags {
  bool enabled = false;
  std::optional<double> eye_height;  // none: the middle of the view region's y range
  uint32_t segments_per_edge = 1;
  calf::encoder::VisibleSetOptions options;
  bool quiet = false;
};

// Computes the visible set of `scene` from its view region's perimeter (calf/encoder/
// visible_set.h), showing what it solves on a terminal; `summary` receives the summary line (the
// caller prints it once the clip is written, so that an error stays the only line). The set's
// errors (E110-E115) pass through.
calf::Expected<calf::encoder::VisibleSet> visible_set_of(const calf::capture::SceneFile& scene,
                                                         const VisibleSetFlags& flags,
                                                         uint32_t* segment_count,
                                                         std::string* summary) {
  const calf::Box3& region = scene.view_volume;
  const double eye_height = flags.eye_height.value_or(0.5 * (region.min.y + region.max.y));
  const auto segments =
      calf::encoder::perimeter_segments(region, eye_height, flags.segments_per_edge);
  double perimeter = 0;
  for (const auto& g : segments) {
    const double dx = g.b.x - g.a.x, dy = g.b.y - g.a.y, dz = g.b.z - g.a.z;
    perimeter += std::sqrt(dx * dx + dy * dy + dz * dz);
  }
  *segment_count = static_cast<uint32_t>(segments.size());
  // The builder reports no progress: on a terminal, say what is being solved until it returns
  // (erased then, so an error stays the one line calf-encode prints).
  const bool tty = !flags.quiet && isatty(2) != 0;
  if (tty) {
    std::fprintf(
        stderr, "calf-encode: visible set: solving %zu segments x 6 faces of %u px x %u frames ...",
        segments.size(), flags.options.face_size, scene.frame_count);
    std::fflush(stderr);
  }
  auto set = calf::encoder::compute_visible_set(scene, segments, flags.options);
  if (tty) std::fprintf(stderr, "\r\033[K");
  if (!set.ok()) return set;
  if (!flags.quiet) {
    const bool coupled = flags.options.motion == calf::encoder::VisibilityMotion::kCoupled;
    const auto& st = set->stats;
    char line[1024];
    std::snprintf(
        line, sizeof line,
        "calf-encode: visible set: %zu segments (%.3f of perimeter at eye height %.3f), 6 faces "
        "of %u px, %s granularity%s: %llu of %llu triangles (%.3f %%) in %.2f s; %llu of %u %s "
        "solved, %llu (triangle, pixel) pairs, %.3g pairs/s\n",
        segments.size(), perimeter, eye_height, flags.options.face_size,
        flags.options.object_granularity ? "object" : "triangle", coupled ? ", coupled motion" : "",
        static_cast<unsigned long long>(st.visible_triangles),
        static_cast<unsigned long long>(st.scene_triangles),
        st.scene_triangles ? 100.0 * static_cast<double>(st.visible_triangles) /
                                 static_cast<double>(st.scene_triangles)
                           : 0.0,
        st.seconds, static_cast<unsigned long long>(st.frames_solved), scene.frame_count,
        coupled ? "frames: motion steps" : "frames",
        static_cast<unsigned long long>(st.triangle_pixel_pairs),
        st.seconds > 0 ? static_cast<double>(st.triangle_pixel_pairs) / st.seconds : 0.0);
    *summary = line;
  }
  return set;
}

// --mode mesh: the scene file at `input` (its folder or scene.json) into a mesh track of the
// whole scene or, with --visible-set, of the triangles visible from its view region.
int encode_mesh(const std::string& input, const std::string& out, const std::string& super,
                bool plain_directory, uint32_t threads, const VisibleSetFlags& vs,
                uint64_t max_image_pixels) {
  calf::encoder::MeshEncodeOptions o;
  o.threads = threads;
  o.levels.compress_directory = !plain_directory;
  o.supercompression = super == "lzma2"  ? calf::container::Compression::kLzma2
                       : super == "none" ? calf::container::Compression::kNone
                                         : calf::container::Compression::kZstd;
  std::filesystem::path dir = input;
  if (dir.filename() == calf::capture::kSceneManifestFileName) dir = dir.parent_path();
  if (dir.empty()) dir = ".";
  const auto start = std::chrono::steady_clock::now();
  auto scene = calf::capture::read_scene_file(dir, max_image_pixels);
  if (!scene.ok()) return fail(scene.status());
  std::optional<calf::encoder::VisibleSet> set;
  std::string vs_summary;
  std::vector<std::pair<std::string, std::string>> metadata;
  if (vs.enabled) {
    // The scene the mesh track refuses is refused before the set is solved (and its line printed).
    if (calf::Status s = calf::encoder::check_mesh_scene(*scene); !s.ok()) return fail(s);
    auto computed = visible_set_of(*scene, vs, &o.segment_count, &vs_summary);
    if (!computed.ok()) return fail(computed.status());
    set = std::move(*computed);
    // How the set was made (no time: the bytes depend on the scene and the options only).
    metadata.emplace_back(
        "visible_set",
        fmt::format("segments {} face_size {} granularity {} triangles {} of {}", o.segment_count,
                    vs.options.face_size, vs.options.object_granularity ? "object" : "triangle",
                    set->stats.visible_triangles, set->stats.scene_triangles));
    if (vs.options.motion == calf::encoder::VisibilityMotion::kCoupled)
      metadata.back().second += " motion coupled";
  }
  auto stats = calf::encoder::encode_mesh_file(*scene, dir, out, set ? &set->triangles : nullptr, o,
                                               metadata);
  if (!stats.ok()) return fail(stats.status());
  std::fputs(vs_summary.c_str(), stderr);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const uint64_t stored = stats->index.stored + stats->vertices_stream.stored +
                          stats->triangles_stream.stored + stats->visibility.stored;
  std::fprintf(stderr,
               "calf-encode: wrote %s in %.2f s (mesh: %u objects, %u prototypes, %u materials, "
               "%llu triangles of %llu, %llu vertices)\n",
               out.c_str(), seconds, stats->objects, stats->prototypes, stats->materials,
               static_cast<unsigned long long>(stats->triangles),
               static_cast<unsigned long long>(stats->scene_triangles),
               static_cast<unsigned long long>(stats->vertices));
  auto line = [](const char* name, const calf::encoder::MeshStreamBytes& b) {
    std::fprintf(stderr, "  %-10s raw %llu  stored %llu  (%.2fx)  %llu chunks\n", name,
                 static_cast<unsigned long long>(b.raw), static_cast<unsigned long long>(b.stored),
                 b.stored ? static_cast<double>(b.raw) / static_cast<double>(b.stored) : 0.0,
                 static_cast<unsigned long long>(b.chunks));
  };
  line("index", stats->index);
  line("vertices", stats->vertices_stream);
  line("triangles", stats->triangles_stream);
  line("visibility", stats->visibility);
  std::fprintf(
      stderr, "  plain f32/u32 arrays %llu bytes, stored %llu (%.2fx)\n",
      static_cast<unsigned long long>(stats->plain_bytes), static_cast<unsigned long long>(stored),
      stored ? static_cast<double>(stats->plain_bytes) / static_cast<double>(stored) : 0.0);
  std::fprintf(stderr, "calf-encode: peak RSS %.1f MiB\n", peak_rss_mib());
  return 0;
}

// --mode surfels: the scene file at `input` and its surfel candidates into a mesh track (track 0)
// and the surfels track paired with it (track 1; paper 001, encoder/surfels_build.h).
int encode_surfels(const std::string& input, const std::string& candidates, const std::string& out,
                   const std::string& super, bool plain_directory, uint32_t threads,
                   const calf::encoder::SurfelBuildOptions& build, uint64_t max_image_pixels) {
  calf::encoder::MeshEncodeOptions mesh;
  mesh.max_image_pixels = max_image_pixels;
  calf::encoder::SurfelsEncodeOptions surfels;
  mesh.threads = surfels.threads = threads;
  mesh.levels.compress_directory = surfels.levels.compress_directory = !plain_directory;
  mesh.supercompression = surfels.supercompression =
      super == "lzma2"  ? calf::container::Compression::kLzma2
      : super == "none" ? calf::container::Compression::kNone
                        : calf::container::Compression::kZstd;
  std::filesystem::path dir = input;
  if (dir.filename() == calf::capture::kSceneManifestFileName) dir = dir.parent_path();
  if (dir.empty()) dir = ".";
  const auto start = std::chrono::steady_clock::now();
  calf::encoder::SurfelsEncodeStats encoded;
  auto stats =
      calf::encoder::encode_surfel_file(dir, candidates, out, build, mesh, surfels, &encoded);
  if (!stats.ok()) return fail(stats.status());
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::fprintf(stderr,
               "calf-encode: wrote %s in %.2f s (surfels: %u of %u prototypes, %llu surfels of "
               "%llu candidates, %s sampler %.2f s; %.2f bytes per surfel stored)\n",
               out.c_str(), seconds, stats->prototypes_with_surfels, stats->prototypes,
               static_cast<unsigned long long>(stats->surfels),
               static_cast<unsigned long long>(stats->candidates),
               calf::surfel_order_method_name(build.sampler.method), stats->sample_seconds,
               stats->surfels ? static_cast<double>(encoded.surfels_stored) /
                                    static_cast<double>(stats->surfels)
                              : 0.0);
  std::fprintf(stderr, "calf-encode: peak RSS %.1f MiB\n", peak_rss_mib());
  return 0;
}

// --psnr auto: estimates the render noise of the capture set at `dir` (calf/encoder/
// noise_estimate.h) and sets o->min_psnr_db from it; prints the estimate and Q unless `quiet`.
// Returns 0, or the exit status of the error it printed.
int resolve_auto_psnr(const std::filesystem::path& dir, double margin, bool quiet,
                      calf::LightfieldEncodeOptions* o) {
  if (calf::Status s = calf::check_lightfield_options(*o); !s.ok()) return fail(s);
  const auto t0 = std::chrono::steady_clock::now();
  auto input = calf::capture::CaptureSetReader::open(dir, o->max_image_pixels);
  if (!input.ok()) return fail(input.status());
  calf::NoiseEstimateOptions no;
  no.threads = o->threads;
  no.max_image_pixels = o->max_image_pixels;
  auto noise = calf::estimate_capture_noise(*input, o->colour, no);
  if (!noise.ok()) return fail(noise.status());
  o->min_psnr_db = calf::auto_psnr_db(noise->set, margin);
  if (quiet) return 0;
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const char* metric = noise->metric == calf::NoiseMetric::kLog2 ? "log2-PSNR" : "sRGB PSNR";
  if (!noise->set.psnr_db) {
    std::fprintf(stderr,
                 "calf-encode: colour noise: no estimate (%llu samples of frame-to-frame change on "
                 "static geometry, %.2f s); --psnr auto: Q = %.2f dB\n",
                 static_cast<unsigned long long>(noise->set.samples), seconds, o->min_psnr_db);
    return 0;
  }
  double lo = 1e9, hi = -1e9;
  for (const calf::NoiseEstimate& v : noise->views) {
    if (!v.psnr_db) continue;
    lo = std::min(lo, *v.psnr_db);
    hi = std::max(hi, *v.psnr_db);
  }
  const std::string views =
      lo <= hi ? fmt::format("views {:.2f}-{:.2f}; ", lo, hi) : std::string("no view alone; ");
  std::fprintf(stderr,
               "calf-encode: colour noise %.2f dB %s (%s%llu samples of frame-to-frame change on "
               "static geometry, %.2f s); --psnr auto: Q = %.2f dB (min(50, estimate - margin "
               "%g))\n",
               *noise->set.psnr_db, metric, views.c_str(),
               static_cast<unsigned long long>(noise->set.samples), seconds, o->min_psnr_db,
               margin);
  return 0;
}

static int command_main(int argc, char** argv) {
  CLI::App app{
      "calf-encode: encode a capture set (format/CAPTURE.md) into a .calf lightfield track "
      "(format/SPEC.md 11.1).\nColour: per-cell keyframes + 8-bit t (Alg. 2); depth: log-16 "
      "keyframes + rectangle P-frames (Alg. 3); material coded like depth when present.\n"
      "The output is written whole or not at all (a temporary file beside it, renamed into "
      "place; removed on an error or on SIGINT / SIGTERM / SIGHUP). It may not exist yet or be a "
      "regular file; a directory, FIFO, device node or symbolic link there is refused "
      "(CALF-E004), and so is an output that is one of the inputs (CALF-E007).\n"
      "--mode mesh: INPUT is a scene file (format/SCENE.md: its folder or scene.json) and the "
      "output holds a mesh track of the whole scene (format/SPEC.md 11.4: materials, prototypes "
      "with spheres tessellated, objects with their transforms), or with --visible-set only the "
      "triangles visible from the scene's view region (paper 004; its errors: CALF-E110..E115, "
      "docs/ERRORS.md); only --supercompression, "
      "--threads, --quiet and the visible-set options apply.\n"
      "An option of another mode (a lightfield option such as --cell or --analysis with --mode "
      "mesh, surfels or tiles; --surfels without --mode surfels; --tiles-* without --mode tiles; "
      "--visible-set without --mode mesh) is a usage error (exit 2).\n"
      "--mode surfels: INPUT is a scene file and --surfel-candidates its candidate file "
      "(format/SURFEL_CANDIDATES.md, from calf-capture --surfel-candidates); the output holds the "
      "mesh track of the whole scene and a surfels track (format/SPEC.md 11.3): per prototype up "
      "to --surfels surfels ordered so every prefix is a level of detail (paper 001; "
      "docs/SURFELS.md).\n"
      "--mode tiles: INPUT is a capture set; one frame of it (--tiles-frame) becomes layered quad "
      "tiles with an RGBA atlas for its view volume (paper 000, Seurat: point merging, "
      "candidate tiles on each face's quadtree, selection under --tiles-triangles / "
      "--tiles-overdraw / --tiles-peak-overdraw by Lagrangian relaxation, carving for alpha; "
      "docs/TILES.md), written as a tiles track (format/SPEC.md 11.2); its errors: "
      "CALF-E250..E254.\n" +
      std::string(calf::tools::kExitStatusHelp)};
  calf::LightfieldEncodeOptions o;
  std::string manifest, out;
  std::string colour = "auto", depth = "pred16m", super = "zstd", mode = "lightfield";
  bool quiet = false;
  app.add_option("MANIFEST", manifest,
                 "lightfield: the capture set (its manifest.json or the directory holding it); "
                 "mesh: the scene file (its scene.json or folder)")
      ->required();
  app.add_option("--mode", mode,
                 "lightfield (a capture set into a lightfield track), mesh (a scene file into "
                 "a mesh track) or surfels (a scene file and its surfel candidates into a mesh "
                 "track and a surfels track) or tiles (one frame of a capture set into a tiles "
                 "track) (default lightfield)")
      ->check(CLI::IsMember({"lightfield", "mesh", "surfels", "tiles"}))
      ->default_val("lightfield");
  app.add_option("-o,--output", out, "output .calf (written whole or not at all)")->required();
  app.add_option("--threads", o.threads,
                 "worker threads 0..256, 0 = all cores; output is identical for any count "
                 "(default 0)")
      ->check(CLI::Range(0u, calf::tools::kMaxThreads))
      ->default_val(0);
  uint64_t max_image_pixels = calf::capture::kDefaultMaxImagePixels;
  app.add_option("--max-image-pixels", max_image_pixels,
                 std::string("every mode: ") + calf::capture::kMaxImagePixelsHelp +
                     " (lightfield, tiles: a capture set's face size counts 6 x its square; "
                     "mesh, surfels: scene-file textures)")
      ->check(CLI::Range(uint64_t{1}, calf::capture::kMaxImagePixelsLimit));
  app.add_option("--cell", o.cell_size, "colour cell side in px, multiple of 4 (default 64)")
      ->default_val(64);
  std::string psnr = "auto";
  app.add_option(
         "--psnr", psnr,
         "Q: min dB of every interpolated frame vs. the frame as the spatial codec shows it; "
         "sRGB PSNR for LDR, log2-PSNR (8-stop peak) for HDR; a number in (0, 200] or auto: "
         "Q = min(50, the capture's render-noise estimate - --psnr-noise-margin), 50 when there "
         "is no estimate (one frame, or no colour change on static geometry); the estimate "
         "and Q are printed (docs/ENCODER.md \"Keyframes and render noise\") (default auto)")
      ->default_val("auto");
  double noise_margin = calf::kDefaultPsnrNoiseMargin;
  app.add_option("--psnr-noise-margin", noise_margin,
                 "with --psnr auto: dB Q stays below the render-noise estimate, 0..50 (default " +
                     fmt::format("{:g}", calf::kDefaultPsnrNoiseMargin) + ")")
      ->check(CLI::Range(0.0, 50.0));
  app.add_option(
         "--color-format", colour,
         "auto (BC1 for LDR input, BC6H for HDR), bc1, bc7, bc6h, rgba8, rgba16f (default auto)")
      ->check(CLI::IsMember({"auto", "bc1", "bc7", "bc6h", "rgba8", "rgba16f"}))
      ->default_val("auto");
  std::string colour_codec = "bc";
  app.add_option("--colour-codec", colour_codec,
                 "bc (colour keyframes in --color-format with interpolation weights) or av1 (per "
                 "colour cell one AV1 stream, SVT-AV1 4:2:0, decoded by dav1d: 8-bit sRGB, or for "
                 "HDR input 10-bit codes of half floats; "
                 "format/SPEC.md 11.1.12, docs/ENCODER.md \"AV1 colour\") (default bc)")
      ->check(CLI::IsMember({"bc", "av1"}))
      ->default_val("bc");
  app.add_option("--av1-crf", o.av1.crf,
                 "av1: constant rate factor 1..63, lower is better and larger (default 32)")
      ->check(CLI::Range(1u, 63u))
      ->default_val(32);
  app.add_option("--av1-qp", o.av1.qp,
                 "av1: a fixed quantiser 1..63 instead of --av1-crf (default: none, CRF)")
      ->check(CLI::Range(1u, 63u));
  app.add_option("--av1-preset", o.av1.preset,
                 "av1: SVT-AV1 preset 0..13, higher is faster and larger (default 8)")
      ->check(CLI::Range(0u, 13u))
      ->default_val(8);
  app.add_option("--av1-keyframe-interval", o.av1.keyframe_interval,
                 "av1: a key frame every K frames, K >= 1: the random-access granularity, a seek "
                 "decodes at most K frames of each visible cell (default 30)")
      ->check(CLI::Range(1u, 16777216u))
      ->default_val(30);
  app.add_option(
         "--depth-format", depth,
         "pred16m (log-16 codes, exact after quantisation, as spatial-prediction residuals; "
         "P-frame rectangles store only their changed texels behind a change mask: format "
         "r16pm, the smallest lossless depth; material raw), pred16 (the same without masks: "
         "format r16p), raw16 (the codes as plain 16-bit planes: the largest, the cheapest to "
         "decode; format r16, which 1.0 readers know) or bc5 (hi/lo bytes, lossy; material BC1; "
         "the error is printed) (default pred16m)")
      ->check(CLI::IsMember({"raw16", "pred16", "pred16m", "bc5"}))
      ->default_val("pred16m");
  app.add_option(
         "--depth-window", o.depth_window,
         "W: a P-frame holds texels differing from any of the previous W frames (default 2)")
      ->default_val(2);
  app.add_option("--max-aabbs", o.max_aabbs, "A: most rectangles per depth P-frame (default 2)")
      ->default_val(2);
  app.add_option("--depth-keyframe-interval", o.depth_keyframe_interval,
                 "a depth / material keyframe every K frames (default 30)")
      ->default_val(30);
  app.add_option("--segment-frames", o.segment_frames,
                 "closed colour segments of N frames, like a closed GOP: the colour keyframe "
                 "search restarts every N frames (frame N, 2N, ... is a keyframe), so frame-range "
                 "shards (--frame-range) code apart into the bytes of one encode; a multiple of "
                 "--depth-keyframe-interval; costs bytes (docs/FARM.md) (default 0: no segments)")
      ->default_val(0);
  bool no_coverage = false;
  app.add_flag("--no-coverage", no_coverage,
               "leave a capture set's coverage (format/CAPTURE.md \"Coverage\") out of the clip: "
               "no coverage stream, a 1.1 file as for a set without coverage; default: a set "
               "with coverage gets the track's coverage stream (SPEC 11.1.11, a 1.2 file)");
  bool fixed_groups = false;
  app.add_flag("--depth-fixed-groups", fixed_groups,
               "one depth / material chunk per K frames even where a tile does not change (the "
               "layout without static groups); default off: a tile unchanged over whole "
               "groups of K frames keeps one chunk, one keyframe, across them (SPEC 11.1.2)");
  std::string colour_rdo = "auto";
  app.add_option(
         "--colour-rdo", colour_rdo,
         "colour rate-distortion strength lambda, 0..1e6, or auto: BC1 / BC6H / BC7 "
         "keyframe blocks are rewritten towards bytes zstd / LZMA find again (copies of a "
         "neighbour block's bytes; BC1: its endpoints or indices) where the added error "
         "(squared, in 8-bit sRGB units; BC6H on the sRGB curve extended above 1) is below "
         "lambda per estimated bit saved; 0 = off, the blocks exactly as the BCn encoder "
         "made them; rgba8 / rgba16f ignore it; auto = 0.5 for BC6H / BC7 (31-69 % fewer "
         "BC6H colour bytes on the built-in scenes for <= 0.02 dB against ground truth) and "
         "12 for BC1 (32-46 % with the default --bc1-fit, within 0.02 dB) "
         "(docs/ENCODER.md; the measurements: git log -p docs/ENCODER.md) (default auto)")
      ->default_val("auto");
  std::string bc1_fit = "cluster";
  app.add_option(
         "--bc1-fit", bc1_fit,
         "how BC1 colour blocks are fitted: range (libsquish's range fit, the fastest; "
         "the least accurate), refined (range fit, then least-squares endpoints "
         "for its indices: +0.1 dB for ~1.3x the BC1 encode time) or cluster (libsquish's "
         "cluster fit: +0.2-0.3 dB for 1.1-2.6x the encode time) (git log -p docs/ENCODER.md "
         "\"BC1 fit\") (default cluster)")
      ->check(CLI::IsMember({"range", "refined", "cluster"}))
      ->default_val("cluster");
  app.add_option("--supercompression", super,
                 "per chunk: zstd (level 19), lzma2 (preset 6), none (default zstd)")
      ->check(CLI::IsMember({"zstd", "lzma2", "none"}))
      ->default_val("zstd");
  bool plain_directory = false;
  app.add_flag("--plain-directory", plain_directory,
               "every mode: write a container 1.0 file (plain 64-byte chunk index entries) that "
               "calf 1.0 readers open, instead of 1.1's directory compressed as one zstd frame "
               "(format/SPEC.md 4.1: 2-43 % smaller lightfield clips, git log -p docs/ENCODER.md "
               "\"Compressed directory\"); sharded encodes always write 1.1");
  app.add_flag("-q,--quiet", quiet, "no progress line");
  bool analysis_only = false;
  std::string analysis_path, views_text, frames_text;
  app.add_flag("--analysis-only", analysis_only,
               "lightfield, sharded encode step 1 (docs/FARM.md): run only the analysis pass "
               "over the whole capture set and write the analysis file (a small .calf: the track "
               "header, every view's depth range, material and HDR facts, these options) to -o "
               "(default off)");
  app.add_option("--analysis", analysis_path,
                 "lightfield, sharded encode step 2: code only --views with the options recorded "
                 "in this analysis file (giving lightfield options too is a usage error) and "
                 "write a shard file to -o; calf-merge joins the shards into the clip, "
                 "byte-identical to a one-machine encode");
  app.add_option("--views", views_text,
                 "with --analysis: the views of the shard, e.g. 0-2,5 (inclusive ranges, "
                 "ascending, 0-based manifest order)");
  app.add_option(
      "--frame-range", frames_text,
      "with --analysis: the shard's frames FIRST-LAST (inclusive), whole segments of the "
      "analysis's --segment-frames (default: every frame)");
  VisibleSetFlags vs;
  auto* vs_flag = app.add_flag(
      "--visible-set", vs.enabled,
      "mesh: keep only the triangles visible from some point of the scene's view region "
      "(paper 004 from-segment visibility on the perimeter of its rectangle at --eye-height, "
      "every frame of the scene; docs/VISIBILITY.md) (default off: the whole scene)");
  auto needs_vs = [&](CLI::Option* opt) { return opt->needs(vs_flag); };
  needs_vs(app.add_option("--eye-height", vs.eye_height,
                          "with --visible-set: height (y) of the perimeter rectangle; must lie in "
                          "the scene's bounds (default: the middle of the view region's y range)"));
  needs_vs(app.add_option("--segments-per-edge", vs.segments_per_edge,
                          "with --visible-set: segments each of the rectangle's 4 edges is cut "
                          "into, 1..1024 (default 1)")
               ->check(CLI::Range(1u, 1024u))
               ->default_val(1));
  needs_vs(app.add_option("--visibility-face-size", vs.options.face_size,
                          "with --visible-set: side in px of the 6 cube faces rasterised per "
                          "segment, 1..8192 (default 800, as paper 004)")
               ->check(CLI::Range(1u, calf::encoder::kVisibleSetMaxFaceSize))
               ->default_val(800));
  needs_vs(app.add_flag("--object-granularity", vs.options.object_granularity,
                        "with --visible-set: keep an object whole as soon as one of its triangles "
                        "is visible (default off: single triangles)"));
  std::string vs_motion = "per-frame";
  needs_vs(app.add_option("--visibility-motion", vs_motion,
                          "with --visible-set: per-frame (default): every frame is a static scene "
                          "and the eye sweeps each segment at every frame (what can be seen from "
                          "some point at some frame); coupled: paper 004 Sec. 3.2, the eye walks "
                          "each segment while the scene moves from frame f to f + 1, vertices on "
                          "straight lines (what an eye moving with the scene sees); "
                          "docs/VISIBILITY.md")
               ->check(CLI::IsMember({"per-frame", "coupled"}))
               ->default_val("per-frame"));
  std::string candidates, sampler = "greedy-tree";
  calf::encoder::SurfelBuildOptions surfel_build;
  app.add_option("--surfel-candidates", candidates,
                 "surfels: the candidate file of the scene (calf-capture --surfel-candidates)");
  app.add_option("--surfels", surfel_build.max_surfels,
                 "surfels: most surfels per prototype, 1..2^26 (fewer when it has fewer "
                 "candidates) (default 65536)")
      ->check(CLI::Range(1u, 1u << 26))
      ->default_val(65536);
  app.add_option("--surfel-sampler", sampler,
                 "surfels: greedy-tree (the greedy permutation through a tree of boxes, about "
                 "O(N log n)), progressive (paper 001's approximate greedy permutation), exact "
                 "(the same order as greedy-tree, plain O(n N): slow) or random (default "
                 "greedy-tree)")
      ->check(CLI::IsMember({"greedy-tree", "progressive", "exact", "random"}))
      ->default_val("greedy-tree");
  // --mode tiles (docs/TILES.md): every knob of the builder and the track encoder.
  calf::tools::TilesModeOptions tiles;
  std::string tiles_atlas = "bc7";
  std::string tiles_alpha = "votes";
  std::vector<uint32_t> tiles_levels;
  {
    calf::encoder::TilesBuildOptions& b = tiles.build;
    app.add_option("--tiles-frame", tiles.frame,
                   "tiles: the capture frame the tiles are built from (default 0)")
        ->default_val(0);
    app.add_option("--tiles-triangles", b.max_triangles,
                   "tiles: L_tris, most triangles (2 per tile), respected exactly, >= 2 "
                   "(default 72000)")
        ->default_val(72000);
    app.add_option("--tiles-overdraw", b.max_average_overdraw,
                   "tiles: L_area, most average overdraw (the tiles' solid angle from the view "
                   "region's centre over 4 pi), > 0 (default 3)")
        ->default_val(3.0);
    app.add_option("--tiles-peak-overdraw", b.max_peak_overdraw,
                   "tiles: most modelled overdraw of any 90-degree view, > 0 (default 5)")
        ->default_val(5.0);
    app.add_option("--tiles-directions", b.overdraw_directions,
                   "tiles: F, the 90-degree view directions the peak bound is modelled on, "
                   "6..4096 (default 126)")
        ->default_val(126);
    app.add_option("--tiles-merge-resolution", b.merge_resolution,
                   "tiles: point-merging grid texels across a cube face, 0 = the capture's face "
                   "size (default 0)")
        ->default_val(0);
    app.add_option("--tiles-levels", tiles_levels,
                   "tiles: MIN,MAX quadtree levels of the candidate cells (2^level cells across "
                   "a face), 0 <= MIN <= MAX <= 10 (default 3,7)")
        ->delimiter(',')
        ->expected(2);
    app.add_option("--tiles-min-cell-texels", b.min_cell_texels,
                   "tiles: leaves are never finer than this many capture texels across (the "
                   "leaf level becomes min(MAX, log2(face size / N)), at least MIN + 1); 0 = off "
                   "(default 8: Seurat's levels 3-7 at 1024² faces; finer leaves carve into "
                   "holes or let coarse many-layer cells win)")
        ->default_val(8)
        ->check(CLI::Range(0u, 16384u));
    app.add_option("--tiles-planes", b.max_planes,
                   "tiles: K, most planes (tiles) per cell, 1..16 (default 8)")
        ->default_val(8);
    app.add_option("--tiles-ransac-trials", b.ransac_trials,
                   "tiles: RANSAC trials of each cell's first plane, 1..4096 (default 32)")
        ->default_val(32);
    app.add_option("--tiles-ransac-threshold", b.ransac_threshold,
                   "tiles: RANSAC inlier bound on the relative radial error, > 0 (default 0.01)")
        ->default_val(0.01);
    app.add_option("--tiles-min-cell-points", b.min_cell_points,
                   "tiles: a cell with fewer merged points takes its parent's planes, >= 1 "
                   "(default 16)")
        ->default_val(16);
    app.add_option("--tiles-refine-iterations", b.refine_iterations,
                   "tiles: assign-and-refit iterations after each plane split, 1..256 (default 4)")
        ->default_val(4);
    app.add_option("--tiles-refine-samples", b.refine_sample_limit,
                   "tiles: most points per plane refit, >= 16 (default 2048)")
        ->default_val(2048);
    app.add_option("--tiles-split-stop", b.split_stop_energy,
                   "tiles: a cell stops splitting below this mean energy (relative radial error "
                   "squared), >= 0 (default 1e-6)")
        ->default_val(1e-6);
    app.add_option("--tiles-dilation", b.tile_dilation,
                   "tiles: each tile's cell grows by this fraction of its width per side, so "
                   "neighbours overlap instead of cracking, 0..0.25 (default 0.02)")
        ->default_val(0.02);
    app.add_option(
           "--tiles-selection-iterations", b.selection_iterations,
           "tiles: subgradient iterations of the Lagrangian selection, 1..20000 (default 150)")
        ->default_val(150);
    app.add_option("--tiles-texels-per-degree", b.texels_per_degree,
                   "tiles: texture density per degree of a tile's angular width, 0 = twice "
                   "the capture's (face size / 45) (default 0)")
        ->default_val(0.0);
    app.add_option("--tiles-min-texels", b.min_tile_texels,
                   "tiles: smallest tile texture side in texels, >= 2 (default 2)")
        ->default_val(2);
    app.add_option("--tiles-max-texels", b.max_tile_texels,
                   "tiles: largest tile texture side in texels, <= 1024 (default 64)")
        ->default_val(64);
    app.add_option("--tiles-max-atlas", b.max_atlas_size,
                   "tiles: largest atlas side; textures shrink uniformly to fit, 16..16384 "
                   "(default 8192)")
        ->default_val(8192);
    app.add_option("--tiles-solid-threshold", b.solid_threshold,
                   "tiles: Seurat's thresh_solid, relative distance of solid / free-space "
                   "carving, [0, 1); 0 = the RANSAC threshold plus 1.25 face texel angles in "
                   "radians (0.041 at 64² faces, 0.018 at 256², 0.014 at 512²) (default 0; "
                   "Seurat's 0.01 carves holes into coarse tiles, docs/TILES.md)")
        ->default_val(0.0);
    app.add_flag("!--tiles-no-sky", b.sky_layer,
                 "tiles: no sky layer (by default, where a view saw sky, one far opaque tile per "
                 "root cell holds its colour, within the budgets; without it the set is "
                 "transparent there)");
    app.add_option("--tiles-texture-solve", b.texture_solve_iterations,
                   "tiles: conjugate-gradient steps of the least-squares colour fit (texels "
                   "whose bilinear magnification best reproduces the samples), 0..1000; 0 keeps "
                   "Seurat's filtered splat (default 32)")
        ->default_val(32);
    app.add_option("--tiles-texture-smoothness", b.texture_smoothness,
                   "tiles: membrane weight of the colour fit relative to a texel's sample "
                   "weight, 0..100: larger is smoother, smaller follows the samples (default "
                   "0.2)")
        ->default_val(0.2);
    app.add_option("--tiles-secondary-colour-weight", b.secondary_colour_weight,
                   "tiles: weight of a sample's colour on the other tiles of its cell within "
                   "the solid threshold (Seurat's crack mitigation) against 1 on its own tile, "
                   "0..1: 1 shares it fully (Seurat), smaller lets a tile's own samples "
                   "outweigh a nearby surface's colour, 0 leaves cracks (default 0.5)")
        ->default_val(0.5);
    app.add_option("--tiles-edge-colour-weight", b.edge_colour_weight,
                   "tiles: weight of a colour sample at a view's depth edge (box-filtered "
                   "texels that blend foreground and background) against 1 elsewhere, 0..1; 1 "
                   "takes every sample alike (default 0.3)")
        ->default_val(0.3);
    app.add_option("--tiles-edge-depth-ratio", b.edge_depth_ratio,
                   "tiles: the relative depth step to a neighbouring texel that makes a texel an "
                   "edge texel for --tiles-edge-colour-weight, (0, 100] (default 0.05)")
        ->default_val(0.05);
    app.add_option("--tiles-alpha", tiles_alpha,
                   "tiles: alpha estimate: votes (each view votes solid where it sees the "
                   "tile's surface, free where it sees through it; alpha is the solid share, "
                   "anti-aliased) or constraints (Seurat's: nearest solid or free-space "
                   "constraint, hard) (default votes)")
        ->check(CLI::IsMember({"votes", "constraints"}))
        ->default_val("votes");
    app.add_option("--tiles-alpha-samples", b.alpha_supersampling,
                   "tiles: S x S carving samples per texel for alpha, 1..8 (default 2)")
        ->default_val(2);
    app.add_option("--tiles-measure-directions", b.measure_directions,
                   "tiles: 90-degree views per eye in which the built tiles' overdraw is "
                   "measured, >= 6 (default 126)")
        ->default_val(126);
    app.add_option("--tiles-measure-resolution", b.measure_resolution,
                   "tiles: side in px of each measured view, 8..1024 (default 64)")
        ->default_val(64);
    app.add_option("--tiles-atlas", tiles_atlas,
                   "tiles: atlas coding, bc7 (GPU-native, lossy) or rgba8 (lossless) "
                   "(default bc7)")
        ->check(CLI::IsMember({"bc7", "rgba8"}))
        ->default_val("bc7");
    app.add_option("--tiles-bc7-quality", tiles.encode.bc7_quality,
                   "tiles: BC7 search effort 0 (fast), 1, 2 (slow) (default 1)")
        ->default_val(1);
  }
  if (int rc = calf::tools::parse_command_line(app, "calf-encode", argc, argv); rc >= 0) return rc;
  // An option of another mode is a usage error, never silently ignored.
  const auto given = [&](const char* name) { return app.get_option(name)->count() > 0; };
  if (mode != "lightfield") {
    for (const char* opt : {"--cell",
                            "--psnr",
                            "--psnr-noise-margin",
                            "--color-format",
                            "--depth-format",
                            "--depth-window",
                            "--max-aabbs",
                            "--depth-keyframe-interval",
                            "--segment-frames",
                            "--colour-rdo",
                            "--bc1-fit",
                            "--depth-fixed-groups",
                            "--no-coverage",
                            "--analysis-only",
                            "--analysis",
                            "--views",
                            "--frame-range",
                            "--colour-codec",
                            "--av1-crf",
                            "--av1-qp",
                            "--av1-preset",
                            "--av1-keyframe-interval"}) {
      if (given(opt)) {
        return calf::tools::usage_error("calf-encode",
                                        std::string(opt) + " needs --mode lightfield");
      }
    }
  }
  if (mode != "surfels") {
    for (const char* opt : {"--surfels", "--surfel-sampler"}) {
      if (given(opt)) {
        return calf::tools::usage_error("calf-encode", std::string(opt) + " needs --mode surfels");
      }
    }
  }
  bool tiles_option_given = false;
  for (const CLI::Option* opt : app.get_options()) {
    if (opt->get_name().rfind("--tiles-", 0) == 0 && opt->count() > 0) tiles_option_given = true;
  }
  if (mode == "tiles") {
    if (vs.enabled || !candidates.empty()) {
      return calf::tools::usage_error("calf-encode",
                                      "--mode tiles takes no --visible-set or --surfel-candidates");
    }
    if (!tiles_levels.empty()) {
      tiles.build.min_level = tiles_levels[0];
      tiles.build.max_level = tiles_levels[1];
    }
    tiles.build.threads =
        o.threads > 0 ? o.threads : std::max(1u, std::thread::hardware_concurrency());
    tiles.encode.threads = o.threads;
    tiles.build.alpha_estimate = tiles_alpha == "constraints"
                                     ? calf::encoder::TilesAlphaEstimate::kConstraints
                                     : calf::encoder::TilesAlphaEstimate::kViewVotes;
    tiles.encode.atlas_format = tiles_atlas == "rgba8" ? calf::encoder::TilesAtlasFormat::kRgba8
                                                       : calf::encoder::TilesAtlasFormat::kBc7;
    tiles.encode.supercompression = super == "lzma2"  ? calf::container::Compression::kLzma2
                                    : super == "none" ? calf::container::Compression::kNone
                                                      : calf::container::Compression::kZstd;
    tiles.encode.levels.compress_directory = !plain_directory;
    tiles.quiet = quiet;
    tiles.max_image_pixels = max_image_pixels;
    if (calf::Status s = calf::encoder::validate_tiles_build_options(tiles.build); !s.ok()) {
      return calf::tools::print_error("calf-encode", s, calf::tools::kExitUsage);
    }
    if (calf::Status s = calf::encoder::validate_tiles_encode_options(tiles.encode); !s.ok()) {
      return calf::tools::print_error("calf-encode", s, calf::tools::kExitUsage);
    }
    return calf::tools::encode_tiles(manifest, out, tiles);
  }
  if (tiles_option_given)
    return calf::tools::usage_error("calf-encode", "--tiles-* options need --mode tiles");
  if (mode == "surfels") {
    if (candidates.empty() || vs.enabled) {
      return calf::tools::usage_error(
          "calf-encode", "--mode surfels needs --surfel-candidates and takes no --visible-set");
    }
    surfel_build.sampler.method = sampler == "exact"         ? calf::SurfelOrderMethod::kExactGreedy
                                  : sampler == "random"      ? calf::SurfelOrderMethod::kRandom
                                  : sampler == "progressive" ? calf::SurfelOrderMethod::kProgressive
                                                             : calf::SurfelOrderMethod::kGreedyTree;
    surfel_build.sampler.threads = o.threads;
    return encode_surfels(manifest, candidates, out, super, plain_directory, o.threads,
                          surfel_build, max_image_pixels);
  }
  if (!candidates.empty())
    return calf::tools::usage_error("calf-encode", "--surfel-candidates needs --mode surfels");
  if (vs_motion == "coupled") vs.options.motion = calf::encoder::VisibilityMotion::kCoupled;
  if (mode != "mesh" && vs.enabled)
    return calf::tools::usage_error("calf-encode", "--visible-set needs --mode mesh");
  vs.options.threads = o.threads;
  vs.quiet = quiet;
  if (mode == "mesh") {
    return encode_mesh(manifest, out, super, plain_directory, o.threads, vs, max_image_pixels);
  }

  const std::map<std::string, calf::ColourCoding> colours = {
      {"auto", calf::ColourCoding::kAuto},   {"bc1", calf::ColourCoding::kBc1},
      {"bc7", calf::ColourCoding::kBc7},     {"bc6h", calf::ColourCoding::kBc6h},
      {"rgba8", calf::ColourCoding::kRgba8}, {"rgba16f", calf::ColourCoding::kRgba16f}};
  o.colour = colours.at(colour);
  if (colour_codec == "av1") {
    for (const char* opt : {"--color-format", "--colour-rdo", "--bc1-fit", "--segment-frames",
                            "--analysis-only", "--analysis"}) {
      if (given(opt)) {
        return calf::tools::usage_error("calf-encode",
                                        std::string(opt) + " needs --colour-codec bc");
      }
    }
    if (given("--av1-crf") && given("--av1-qp")) {
      return calf::tools::usage_error("calf-encode", "--av1-crf and --av1-qp exclude each other");
    }
    o.colour = calf::ColourCoding::kAv1;
  } else {
    for (const char* opt : {"--av1-crf", "--av1-qp", "--av1-preset", "--av1-keyframe-interval"}) {
      if (given(opt)) {
        return calf::tools::usage_error("calf-encode",
                                        std::string(opt) + " needs --colour-codec av1");
      }
    }
  }
  if (colour_rdo == "auto") {
    o.colour_rdo = calf::kColourRdoAuto;
  } else {
    char* end = nullptr;
    o.colour_rdo = std::strtod(colour_rdo.c_str(), &end);
    if (colour_rdo.empty() || *end != '\0' || !(o.colour_rdo >= 0 && o.colour_rdo <= 1e6)) {
      return calf::tools::usage_error(
          "calf-encode", "--colour-rdo " + colour_rdo + ": expected a number in [0, 1e6] or auto");
    }
  }
  const bool psnr_auto = psnr == "auto";
  if (!psnr_auto) {
    char* end = nullptr;
    o.min_psnr_db = std::strtod(psnr.c_str(), &end);
    if (psnr.empty() || *end != '\0' || !std::isfinite(o.min_psnr_db)) {
      return calf::tools::usage_error("calf-encode",
                                      "--psnr " + psnr + ": expected a number of dB or auto");
    }
    if (given("--psnr-noise-margin")) {
      return calf::tools::usage_error("calf-encode", "--psnr-noise-margin needs --psnr auto");
    }
  }
  o.bc1_fit = bc1_fit == "range"     ? calf::Bc1Fit::kRange
              : bc1_fit == "refined" ? calf::Bc1Fit::kRefined
                                     : calf::Bc1Fit::kCluster;
  o.depth = depth == "bc5"       ? calf::DepthCoding::kBc5
            : depth == "pred16"  ? calf::DepthCoding::kRaw16Predicted
            : depth == "pred16m" ? calf::DepthCoding::kRaw16PredictedMasked
                                 : calf::DepthCoding::kRaw16;
  o.merge_static_groups = !fixed_groups;
  o.coverage = !no_coverage;
  o.levels.compress_directory = !plain_directory;
  o.supercompression = super == "lzma2"  ? calf::container::Compression::kLzma2
                       : super == "none" ? calf::container::Compression::kNone
                                         : calf::container::Compression::kZstd;

  std::filesystem::path dir = manifest;
  if (dir.filename() == "manifest.json") dir = dir.parent_path();
  if (dir.empty()) dir = ".";

  if (analysis_only && !analysis_path.empty()) {
    return calf::tools::usage_error("calf-encode",
                                    "--analysis-only and --analysis exclude each other");
  }
  if (analysis_path.empty() != views_text.empty() ||
      (analysis_path.empty() && !frames_text.empty())) {
    return calf::tools::usage_error("calf-encode",
                                    "--analysis and --views go together; --frame-range needs them");
  }
  if (analysis_only && plain_directory) {
    return calf::tools::usage_error(
        "calf-encode", "--plain-directory with --analysis-only: sharded encodes write 1.1 files");
  }
  if (psnr_auto && analysis_path.empty()) {
    // Q from the capture's render noise, decided before pass 1 so that an analysis file records
    // the number and its shards code with it.
    o.max_image_pixels = max_image_pixels;
    if (int rc = resolve_auto_psnr(dir, noise_margin, quiet, &o); rc != 0) return rc;
  }
  if (analysis_only) {
    const auto t0 = std::chrono::steady_clock::now();
    o.max_image_pixels = max_image_pixels;
    auto a = calf::write_lightfield_analysis(dir, out, o);
    if (!a.ok()) return fail(a.status());
    if (!quiet) {
      std::fprintf(stderr, "calf-encode: analysis %s of %u views in %.2f s, peak RSS %.1f MiB\n",
                   a->id.c_str(), a->analysis.header.view_count,
                   std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(),
                   peak_rss_mib());
    }
    return 0;
  }
  if (!analysis_path.empty()) {
    for (const char* opt :
         {"--cell", "--psnr", "--psnr-noise-margin", "--color-format", "--depth-format",
          "--depth-window", "--max-aabbs", "--depth-keyframe-interval", "--supercompression",
          "--segment-frames", "--colour-rdo", "--bc1-fit", "--depth-fixed-groups", "--no-coverage",
          "--plain-directory"}) {
      if (app.get_option(opt)->count() > 0) {
        return calf::tools::usage_error(
            "calf-encode",
            std::string(opt) + " with --analysis: the options are the analysis file's");
      }
    }
    const auto t0 = std::chrono::steady_clock::now();
    auto a = calf::read_lightfield_analysis(analysis_path);
    if (!a.ok()) return fail(a.status());
    auto views =
        calf::capture::parse_index_list(views_text, a->analysis.header.view_count, "views");
    if (!views.ok()) {
      return calf::tools::print_error("calf-encode", views.status(), calf::tools::kExitUsage);
    }
    uint32_t first = 0, count = a->analysis.header.frame_count;
    if (!frames_text.empty()) {
      auto f = calf::capture::parse_index_list(frames_text, count, "frames");
      if (!f.ok() || f->back() - f->front() + 1 != f->size()) {
        return calf::tools::print_error(
            "calf-encode",
            f.ok() ? calf::Status(calf::ErrorId::kShardRange,
                                  "--frame-range '" + frames_text + "' is not one range")
                   : f.status(),
            calf::tools::kExitUsage);
      }
      first = f->front();
      count = static_cast<uint32_t>(f->size());
    }
    auto s = calf::encode_lightfield_shard(dir, *a, *views, first, count, o.threads, out,
                                           max_image_pixels);
    if (!s.ok()) return fail(s.status());
    if (!quiet) {
      std::fprintf(stderr,
                   "calf-encode: shard %s (views %s, %llu colour keyframes, %llu bytes stored) in "
                   "%.2f s, peak RSS %.1f MiB\n",
                   out.c_str(), calf::capture::index_list_text(*views).c_str(),
                   static_cast<unsigned long long>(s->colour_keyframes),
                   static_cast<unsigned long long>(s->colour.stored + s->depth.stored +
                                                   s->material.stored + s->coverage.stored),
                   std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(),
                   peak_rss_mib());
    }
    return 0;
  }

  const bool tty = isatty(2) != 0;
  const auto start = std::chrono::steady_clock::now();
  int next_percent = 0;
  if (!quiet) {
    o.progress = [&](uint64_t done, uint64_t total) {
      const double elapsed =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      const double eta = elapsed / static_cast<double>(done) * static_cast<double>(total - done);
      const int percent = static_cast<int>(100 * done / total);
      if (!tty && percent < next_percent && done != total) return;
      next_percent = percent + 10;
      std::fprintf(stderr, "%scalf-encode: view-face %llu/%llu (%d%%) elapsed %.1f s, ETA %.1f s%s",
                   tty ? "\r" : "", static_cast<unsigned long long>(done),
                   static_cast<unsigned long long>(total), percent, elapsed, eta,
                   tty && done != total ? "" : "\n");
      std::fflush(stderr);
    };
  }
  o.max_image_pixels = max_image_pixels;
  auto stats = calf::encode_lightfield_file(dir, out, o);
  if (!stats.ok()) return fail(stats.status());
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  auto line = [](const char* name, const calf::StreamBytes& b) {
    std::fprintf(
        stderr, "  %-8s raw %llu  temporal %llu  +spatial %llu  +%s %llu  (%.1fx)  %llu chunks\n",
        name, static_cast<unsigned long long>(b.raw), static_cast<unsigned long long>(b.temporal),
        static_cast<unsigned long long>(b.spatial), "super",
        static_cast<unsigned long long>(b.stored),
        b.stored ? static_cast<double>(b.raw) / static_cast<double>(b.stored) : 0.0,
        static_cast<unsigned long long>(b.chunks));
  };
  // Encode speed in capture texels (every view, face and frame) per second: the depth stream's
  // raw count is 2 bytes a texel.
  const double mpix = static_cast<double>(stats->depth.raw / 2) / 1e6;
  std::fprintf(stderr, "calf-encode: wrote %s in %.2f s (colour %s, %s; %.1f Mpix, %.2f Mpix/s)\n",
               out.c_str(), seconds, calf::container::pixel_format_name(stats->colour_format),
               stats->hdr ? "HDR" : "LDR", mpix, seconds > 0 ? mpix / seconds : 0.0);
  line("colour", stats->colour);
  line("depth", stats->depth);
  if (stats->material_views) line("material", stats->material);
  if (stats->coverage.chunks) line("coverage", stats->coverage);
  std::fprintf(stderr,
               "  colour: %llu cells, %llu keyframes, min temporal quality %.2f dB; depth: %llu "
               "P-frames (%llu empty)\n",
               static_cast<unsigned long long>(stats->colour_cells),
               static_cast<unsigned long long>(stats->colour_keyframes),
               stats->min_colour_quality_db, static_cast<unsigned long long>(stats->depth_pframes),
               static_cast<unsigned long long>(stats->depth_empty_pframes));
  if (o.depth == calf::DepthCoding::kBc5) {
    std::fprintf(stderr,
                 "  BC5 depth error: max relative %.3g, mean relative %.3g, sky mismatches %llu\n",
                 stats->depth_max_rel_error, stats->depth_mean_rel_error,
                 static_cast<unsigned long long>(stats->depth_sky_mismatches));
  }
  std::fprintf(stderr, "calf-encode: peak RSS %.1f MiB\n", peak_rss_mib());
  return 0;
}

int main(int argc, char** argv) {
  // SVT-AV1 (--colour-codec av1) prints its banner and settings to stderr unless SVT_LOG says
  // otherwise; set before any thread starts, and a user's own setting is kept.
  setenv("SVT_LOG", "0", 0);
  return calf::tools::run_command("calf-encode", [&] { return command_main(argc, argv); });
}
