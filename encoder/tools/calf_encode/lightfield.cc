#include "calf_encode/lightfield.h"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include <fmt/format.h>

#include "calf/capture/capture_set.h"
#include "command_line.h"

namespace calf::tools {

namespace {

inline constexpr EnumTable<encoder::ColourCoding, 6> kColourFormats = {
    {{"auto", encoder::ColourCoding::kAuto},
     {"bc1", encoder::ColourCoding::kBc1},
     {"bc7", encoder::ColourCoding::kBc7},
     {"bc6h", encoder::ColourCoding::kBc6h},
     {"rgba8", encoder::ColourCoding::kRgba8},
     {"rgba16f", encoder::ColourCoding::kRgba16f}}};

inline constexpr EnumTable<encoder::DepthCoding, 4> kDepthFormats = {
    {{"raw16", encoder::DepthCoding::kRaw16},
     {"pred16", encoder::DepthCoding::kRaw16Predicted},
     {"pred16m", encoder::DepthCoding::kRaw16PredictedMasked},
     {"bc5", encoder::DepthCoding::kBc5}}};

inline constexpr EnumTable<encoder::Bc1Fit, 3> kBc1Fits = {
    {{"range", encoder::Bc1Fit::kRange},
     {"refined", encoder::Bc1Fit::kRefined},
     {"cluster", encoder::Bc1Fit::kCluster}}};

inline constexpr EnumTable<ColourCodec, 2> kColourCodecs = {
    {{"bc", ColourCodec::kBc}, {"av1", ColourCodec::kAv1}}};

// Av1ColourOptions::chroma444.
inline constexpr EnumTable<bool, 2> kAv1Chroma = {{{"420", false}, {"444", true}}};

// --psnr auto: estimates the render noise of the capture set at `dir` (calf/encoder/
// noise_estimate.h) and sets o->min_psnr_db from it, and with `denoise_auto` the pre-filter's
// window (on with the noise-aware test, BC colour only); prints the estimate and Q unless
// `quiet`. Returns 0, or the exit status of the error it printed.
int resolve_auto_psnr(const std::filesystem::path& dir, double margin, bool denoise_auto,
                      bool quiet, encoder::LightfieldEncodeOptions* o) {
  const auto t0 = std::chrono::steady_clock::now();
  auto noise = encoder::apply_auto_psnr(dir, margin, denoise_auto, o);
  if (!noise.ok()) return fail(noise.status());
  if (quiet) return 0;
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const char* metric = noise->metric == encoder::NoiseMetric::kLog2 ? "log2-PSNR" : "sRGB PSNR";
  if (!noise->set.psnr_db) {
    std::fprintf(stderr,
                 "calf-encode: colour noise: no estimate (%llu samples of frame-to-frame change on "
                 "static geometry, %.2f s); --psnr auto: Q = %.2f dB\n",
                 static_cast<unsigned long long>(noise->set.samples), seconds, o->min_psnr_db);
    return 0;
  }
  double lo = 1e9, hi = -1e9;
  for (const encoder::NoiseEstimate& v : noise->views) {
    if (!v.psnr_db) continue;
    lo = std::min(lo, *v.psnr_db);
    hi = std::max(hi, *v.psnr_db);
  }
  const std::string views =
      lo <= hi ? fmt::format("views {:.2f}-{:.2f}; ", lo, hi) : std::string("no view alone; ");
  std::fprintf(
      stderr,
      "calf-encode: colour noise %.2f dB %s (%s%llu samples of frame-to-frame change on "
      "static geometry, %.2f s); --psnr auto: Q = %.2f dB (min(50, estimate - margin "
      "%g))%s%s\n",
      *noise->set.psnr_db, metric, views.c_str(),
      static_cast<unsigned long long>(noise->set.samples), seconds, o->min_psnr_db, margin,
      o->noise_psnr_db > 0 ? fmt::format(", noise-aware (factor {:g})", o->noise_factor).c_str()
                           : "",
      o->denoise_window > 1
          ? fmt::format(", static texels averaged over {} frames", o->denoise_window).c_str()
          : "");
  return 0;
}

bool given(const CLI::App& app, const char* name) {
  return app.get_option(name)->count() > 0;
}

// The AV1 colour options, one block: the codec choice and SVT-AV1's settings.
void add_av1_options(CLI::App& app, LightfieldOptions& o) {
  add_enum_option(app, "--colour-codec", o.colour_codec, kColourCodecs,
                  "bc (colour keyframes in --color-format with interpolation weights) or av1 (per "
                  "colour cell one AV1 stream, decoded by dav1d: 8-bit sRGB, or for HDR input "
                  "10-bit codes of half floats; "
                  "format/SPEC.md 11.1.12, docs/ENCODER.md \"AV1 colour\")")
      ->group(kAv1Group);
  encoder::Av1ColourOptions& av1 = o.encode.av1;
  app.add_option("--av1-crf", av1.crf,
                 "av1: constant rate factor 1..63, lower is better and larger")
      ->check(CLI::Range(1u, 63u))
      ->group(kAv1Group);
  app.add_option("--av1-qp", av1.qp,
                 "av1: a fixed quantiser 1..63 instead of --av1-crf (default: none, CRF)")
      ->check(CLI::Range(1u, 63u))
      ->default_str("")
      ->group(kAv1Group);
  app.add_option("--av1-preset", av1.preset,
                 "av1: SVT-AV1 preset 0..13, or with --av1-chroma 444 libaom's cpu-used 0..9; "
                 "higher is faster and larger (docs/ENCODER.md measures 5 and 8 against x265)")
      ->check(CLI::Range(0u, 13u))
      ->group(kAv1Group);
  add_enum_option(app, "--av1-chroma", av1.chroma444, kAv1Chroma,
                  "av1: 420 (SVT-AV1, the AV1 Main profile every browser and hardware decoder "
                  "plays) or 444 (libaom, the High profile: colour at every texel, container 1.5; "
                  "fewer bytes at matched PSNR on noisy renders, docs/ENCODER.md \"AV1 colour\")")
      ->group(kAv1Group);
  app.add_option("--av1-keyframe-interval", av1.keyframe_interval,
                 "av1: a key frame every K frames, K >= 1: the random-access granularity, a seek "
                 "decodes at most K frames of each visible cell")
      ->check(CLI::Range(1u, 16777216u))
      ->group(kAv1Group);
}

// Usage errors of the AV1 block: its options without --colour-codec av1, and the options of the
// BC colour path with it. Returns -1 to go on, else the exit status.
int check_av1_options(const CLI::App& app, const LightfieldOptions& o) {
  if (o.colour_codec == ColourCodec::kAv1) {
    for (const char* opt : {"--colour-format", "--colour-rdo", "--bc1-fit", "--segment-frames",
                            "--analysis-only", "--analysis"}) {
      if (given(app, opt))
        return usage_error("calf-encode", std::string(opt) + " needs --colour-codec bc");
    }
    if (given(app, "--av1-crf") && given(app, "--av1-qp")) {
      return usage_error("calf-encode", "--av1-crf and --av1-qp exclude each other");
    }
    if (o.encode.av1.chroma444 && o.encode.av1.preset > 9) {
      return usage_error("calf-encode", "--av1-preset " + std::to_string(o.encode.av1.preset) +
                                            " with --av1-chroma 444: expected 0..9 (libaom "
                                            "cpu-used)");
    }
    return -1;
  }
  for (const char* opt :
       {"--av1-crf", "--av1-qp", "--av1-preset", "--av1-keyframe-interval", "--av1-chroma"}) {
    if (given(app, opt))
      return usage_error("calf-encode", std::string(opt) + " needs --colour-codec av1");
  }
  return -1;
}

}  // namespace

void add_options(CLI::App& app, LightfieldOptions& o) {
  encoder::LightfieldEncodeOptions& e = o.encode;
  app.add_option("--cell", e.cell_size, "colour cell side in px, multiple of 4")
      ->group(kLightfieldGroup);
  app.add_option(
         "--psnr", o.psnr,
         "Q: min dB of every interpolated frame vs. the frame as the spatial codec shows it; "
         "sRGB PSNR for LDR, log2-PSNR (8-stop peak) for HDR; a number in (0, 200] or auto: "
         "Q = min(50, the capture's render-noise estimate - --psnr-noise-margin), 50 when there "
         "is no estimate (one frame, or no colour change on static geometry); the estimate "
         "and Q are printed (docs/ENCODER.md \"Keyframes and render noise\")")
      ->group(kLightfieldGroup);
  app.add_option("--psnr-noise-margin", o.psnr_noise_margin,
                 "with --psnr auto: dB Q stays below the render-noise estimate, 0..50")
      ->check(CLI::Range(0.0, 50.0))
      ->group(kLightfieldGroup);
  app.add_option("--psnr-noise-factor", e.noise_factor,
                 "with --psnr auto and Q below 50: the keyframe test does not count this many "
                 "times each 8 x 8 block's measured render noise in an interpolated frame's "
                 "error, 0..16 (0: the plain test)")
      ->check(CLI::Range(0.0, 16.0))
      ->group(kLightfieldGroup);
  app.add_option("--denoise-window", o.denoise_window,
                 "temporal pre-filter of render noise: before colour coding, each texel on static "
                 "geometry (depth and material unchanged) takes the mean of up to W frames around "
                 "it where its change, at the texel and over its 3 x 3 neighbourhood, is within "
                 "3 standard deviations of its 8 x 8 block's measured frame-to-frame noise; "
                 "0..64 (0 or 1: off) or auto: " +
                     std::to_string(encoder::kDefaultDenoiseWindow) +
                     " where --psnr auto finds render noise (Q below 50, BC colour), else off "
                     "(docs/ENCODER.md \"Keyframes and render noise\")")
      ->group(kLightfieldGroup);
  add_enum_option(app, "--colour-format,--color-format", e.colour, kColourFormats,
                  "auto (BC1 for LDR input, BC6H for HDR), bc1, bc7, bc6h, rgba8, rgba16f")
      ->group(kLightfieldGroup);
  add_av1_options(app, o);
  add_enum_option(
      app, "--depth-format", e.depth, kDepthFormats,
      "pred16m (log-16 codes, exact after quantisation, as spatial-prediction residuals; "
      "P-frame rectangles store only their changed texels behind a change mask: format "
      "r16pm, the smallest lossless depth; material raw), pred16 (the same without masks: "
      "format r16p), raw16 (the codes as plain 16-bit planes: the largest, the cheapest to "
      "decode; format r16, which 1.0 readers know) or bc5 (hi/lo bytes, lossy; material BC1; "
      "the error is printed)")
      ->group(kLightfieldGroup);
  app.add_option("--depth-window", e.depth_window,
                 "W: a P-frame holds texels differing from any of the previous W frames")
      ->group(kLightfieldGroup);
  app.add_option("--max-aabbs", e.max_aabbs, "A: most rectangles per depth P-frame")
      ->group(kLightfieldGroup);
  app.add_option("--depth-keyframe-interval", e.depth_keyframe_interval,
                 "a depth / material keyframe every K frames")
      ->group(kLightfieldGroup);
  app.add_option("--segment-frames", e.segment_frames,
                 "closed colour segments of N frames, like a closed GOP: the colour keyframe "
                 "search restarts every N frames (frame N, 2N, ... is a keyframe), so frame-range "
                 "shards (--frame-range) code apart into the bytes of one encode; a multiple of "
                 "--depth-keyframe-interval; costs bytes (docs/FARM.md); 0: no segments")
      ->group(kLightfieldGroup);
  app.add_flag("--no-coverage", o.no_coverage,
               "leave a capture set's coverage (format/CAPTURE.md \"Coverage\") out of the clip: "
               "no coverage stream, a 1.1 file as for a set without coverage; without it a set "
               "with coverage gets the track's coverage stream (SPEC 11.1.11, a 1.2 file)")
      ->group(kLightfieldGroup);
  app.add_option("--coverage-unmix", o.coverage_unmix,
                 "bake unmixed colour into the clip: before colour coding, each texel on a depth "
                 "edge of a capture set with coverage is solved for its own surface's colour "
                 "(its anti-aliased colour less its neighbours' across the edge, by the shares "
                 "coverage gives; docs/RENDERING.md \"Coverage\"), so that every player shows it; "
                 "the value, 0..1, is the least share of its own surface a texel needs to be "
                 "solved (below it the texel takes a neighbour's colour of its surface); "
                 "0.25 with --coverage-unmix-jump 1000 (sky edges only) is the measured setting "
                 "(docs/SILHOUETTES.md \"Unmixed colour at sky edges\"); without it colour is "
                 "coded as captured")
      ->group(kLightfieldGroup);
  app.add_option("--coverage-unmix-jump", o.coverage_unmix_jump,
                 "with --coverage-unmix: only neighbours at least this relative depth nearer or "
                 "farther (beyond the capture's own-surface tolerance, min(4 / face size, 0.05)) "
                 "count as the other side of an edge; 0..1e6, 0 by default; 1000: only the sky")
      ->group(kLightfieldGroup);
  app.add_flag("--depth-fixed-groups", o.fixed_groups,
               "one depth / material chunk per K frames even where a tile does not change (the "
               "layout without static groups); without it a tile unchanged over whole "
               "groups of K frames keeps one chunk, one keyframe, across them (SPEC 11.1.2)")
      ->group(kLightfieldGroup);
  app.add_option(
         "--colour-rdo", o.colour_rdo,
         "colour rate-distortion strength lambda, 0..1e6, or auto: BC1 / BC6H / BC7 "
         "keyframe blocks are rewritten towards bytes zstd / LZMA find again (copies of a "
         "neighbour block's bytes; BC1: its endpoints or indices) where the added error "
         "(squared, in 8-bit sRGB units; BC6H on the sRGB curve extended above 1) is below "
         "lambda per estimated bit saved; 0 = off, the blocks exactly as the BCn encoder "
         "made them; rgba8 / rgba16f ignore it; auto = 0.5 for BC6H / BC7 (31-69 % fewer "
         "BC6H colour bytes on the built-in scenes for <= 0.02 dB against ground truth) and "
         "12 for BC1 (32-46 % with the default --bc1-fit, within 0.02 dB); 2 for BC6H "
         "where --psnr auto measures render noise and --denoise-window is on (docs/ENCODER.md "
         "\"Keyframes and render noise\") "
         "(docs/ENCODER.md; the measurements: git log -p docs/ENCODER.md)")
      ->group(kLightfieldGroup);
  add_enum_option(app, "--bc1-fit", e.bc1_fit, kBc1Fits,
                  "how BC1 colour blocks are fitted: range (libsquish's range fit, the fastest; "
                  "the least accurate), refined (range fit, then least-squares endpoints "
                  "for its indices: +0.1 dB for ~1.3x the BC1 encode time) or cluster "
                  "(libsquish's cluster fit: +0.2-0.3 dB for 1.1-2.6x the encode time) (git log "
                  "-p docs/ENCODER.md \"BC1 fit\")")
      ->group(kLightfieldGroup);
  add_options(app, o.shard);
}

int resolve(const CLI::App& app, const CommonOptions& common, LightfieldOptions* options) {
  LightfieldOptions& lf = *options;
  encoder::LightfieldEncodeOptions& o = lf.encode;
  if (int rc = check_av1_options(app, lf); rc >= 0) return rc;
  if (lf.colour_codec == ColourCodec::kAv1) o.colour = encoder::ColourCoding::kAv1;
  if (lf.colour_rdo == "auto") {
    o.colour_rdo = encoder::kColourRdoAuto;
  } else {
    char* end = nullptr;
    o.colour_rdo = std::strtod(lf.colour_rdo.c_str(), &end);
    if (lf.colour_rdo.empty() || *end != '\0' || !(o.colour_rdo >= 0 && o.colour_rdo <= 1e6)) {
      return usage_error("calf-encode", "--colour-rdo " + lf.colour_rdo +
                                            ": expected a number in [0, 1e6] or auto");
    }
  }
  if (lf.denoise_window != "auto") {
    char* end = nullptr;
    const unsigned long w = std::strtoul(lf.denoise_window.c_str(), &end, 10);
    if (lf.denoise_window.empty() || *end != '\0' || lf.denoise_window[0] == '-' ||
        w > encoder::kMaxDenoiseWindow) {
      return usage_error("calf-encode",
                         "--denoise-window " + lf.denoise_window + ": expected a number in [0, " +
                             std::to_string(encoder::kMaxDenoiseWindow) + "] or auto");
    }
    o.denoise_window = static_cast<uint32_t>(w);
  }
  if (lf.psnr != "auto") {
    char* end = nullptr;
    o.min_psnr_db = std::strtod(lf.psnr.c_str(), &end);
    if (lf.psnr.empty() || *end != '\0' || !std::isfinite(o.min_psnr_db)) {
      return usage_error("calf-encode", "--psnr " + lf.psnr + ": expected a number of dB or auto");
    }
    if (given(app, "--psnr-noise-margin")) {
      return usage_error("calf-encode", "--psnr-noise-margin needs --psnr auto");
    }
    if (given(app, "--psnr-noise-factor")) {
      return usage_error("calf-encode", "--psnr-noise-factor needs --psnr auto");
    }
  }
  o.merge_static_groups = !lf.fixed_groups;
  o.coverage = !lf.no_coverage;
  if (given(app, "--coverage-unmix-jump") && !given(app, "--coverage-unmix")) {
    return usage_error("calf-encode", "--coverage-unmix-jump needs --coverage-unmix");
  }
  if (given(app, "--coverage-unmix")) {
    if (lf.no_coverage) {
      return usage_error("calf-encode", "--coverage-unmix needs coverage; --no-coverage drops it");
    }
    if (!(lf.coverage_unmix >= 0 && lf.coverage_unmix <= 1)) {
      return usage_error("calf-encode", "--coverage-unmix " + std::to_string(lf.coverage_unmix) +
                                            ": expected a share in [0, 1]");
    }
    capture::CoverageUnmixOptions unmix;
    unmix.min_share = lf.coverage_unmix;
    if (given(app, "--coverage-unmix-jump")) {
      if (!(lf.coverage_unmix_jump >= 0 && lf.coverage_unmix_jump <= 1e6)) {
        return usage_error("calf-encode", "--coverage-unmix-jump " +
                                              std::to_string(lf.coverage_unmix_jump) +
                                              ": expected a relative depth in [0, 1e6]");
      }
      unmix.min_jump = lf.coverage_unmix_jump;
    }
    o.coverage_unmix = unmix;
  }
  o.levels.compress_directory = !common.plain_directory;
  o.supercompression = common.supercompression;
  o.threads = common.threads;
  o.max_image_pixels = common.max_image_pixels;

  const ShardOptions& shard = lf.shard;
  if (shard.analysis_only && !shard.analysis.empty()) {
    return usage_error("calf-encode", "--analysis-only and --analysis exclude each other");
  }
  if (shard.analysis.empty() != shard.views.empty() ||
      (shard.analysis.empty() && !shard.frame_range.empty())) {
    return usage_error("calf-encode",
                       "--analysis and --views go together; --frame-range needs them");
  }
  if (shard.analysis_only && common.plain_directory) {
    return usage_error("calf-encode",
                       "--plain-directory with --analysis-only: sharded encodes write 1.1 files");
  }
  if (!shard.analysis.empty()) {
    // A shard codes with the analysis file's options: the lightfield options, supercompression
    // and the directory may not be given again.
    for (const CLI::Option* opt : app.get_options()) {
      const std::string& name = opt->get_name();
      if (opt->count() == 0) continue;
      if (opt->get_group() == kLightfieldGroup || name == "--supercompression" ||
          name == "--plain-directory") {
        return usage_error("calf-encode",
                           name + " with --analysis: the options are the analysis file's");
      }
    }
  }
  return -1;
}

int run(const CommonOptions& common, const LightfieldOptions& options) {
  encoder::LightfieldEncodeOptions o = options.encode;
  const std::filesystem::path dir = input_folder(common.input, capture::kManifestFileName);
  const ShardOptions& shard = options.shard;
  if (options.psnr == "auto" && shard.analysis.empty()) {
    // Q from the capture's render noise, decided before pass 1 so that an analysis file records
    // the number and its shards code with it.
    if (int rc = resolve_auto_psnr(dir, options.psnr_noise_margin, options.denoise_window == "auto",
                                   common.quiet, &o);
        rc != 0)
      return rc;
  }
  if (shard.analysis_only) return run_analysis(common, dir, o);
  if (!shard.analysis.empty()) return run_shard(common, dir, shard);

  const bool tty = isatty(2) != 0;
  const auto start = std::chrono::steady_clock::now();
  int next_percent = 0;
  if (!common.quiet) {
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
  auto stats = encoder::encode_lightfield_file(dir, common.output, o);
  if (!stats.ok()) return fail(stats.status());
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  auto line = [](const char* name, const encoder::StreamBytes& b) {
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
               common.output.c_str(), seconds, container::pixel_format_name(stats->colour_format),
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
  if (o.denoise_window > 1) {
    std::fprintf(stderr, "  denoise: %llu of %llu texel-frames averaged over up to %u frames\n",
                 static_cast<unsigned long long>(stats->colour_denoised),
                 static_cast<unsigned long long>(stats->depth.raw / 2), o.denoise_window);
  }
  if (o.coverage_unmix) {
    std::fprintf(stderr, "  unmix: %llu of %llu texel-frames unmixed\n",
                 static_cast<unsigned long long>(stats->colour_unmixed),
                 static_cast<unsigned long long>(stats->depth.raw / 2));
  }
  if (o.depth == encoder::DepthCoding::kBc5) {
    std::fprintf(stderr,
                 "  BC5 depth error: max relative %.3g, mean relative %.3g, sky mismatches %llu\n",
                 stats->depth_max_rel_error, stats->depth_mean_rel_error,
                 static_cast<unsigned long long>(stats->depth_sky_mismatches));
  }
  std::fprintf(stderr, "calf-encode: peak RSS %.1f MiB\n", peak_rss_mib());
  return 0;
}

}  // namespace calf::tools
