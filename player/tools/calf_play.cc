// calf-play: plays a .calf clip — its lightfield tracks (paper 002 Sec. 6) and mesh tracks (paper
// 004's full scene or visible set), composited by depth: in a GLFW window with fly / orbit
// cameras and a Dear ImGui HUD, or headless through OSMesa along an eye path, writing frames and
// comparing them with calf-capture's ground truth. Errors are one line with a stable id and exit
// status 1; usage errors exit 2 (command_line.h).
#include <cstdio>
#include <filesystem>
#include <initializer_list>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <CLI/CLI.hpp>

#include "calf/player/gl_context.h"
#include "calf/player/headless_session.h"
#include "calf/player/playback.h"
#include "calf_play/play_window.h"
#include "command_line.h"
#include "enum_option.h"

namespace {

namespace fs = std::filesystem;
using namespace calf;
using namespace calf::player;

int fail(const Status& status) {
  return tools::print_error("calf-play", status);
}

// Options that contradict each other: E461, exit 2 like every usage error (command_line.h).
int contradiction(const std::string& message) {
  return tools::print_error("calf-play", Status(ErrorId::kPlaybackOption, message),
                            tools::kExitUsage);
}

struct HeadlessArgs {
  std::string eye_path, out, compare, format = "png", contact_sheet;
  // --noise-floor: ground truth of the same path with another seed (default GT_DIR/noise-floor).
  std::string noise_floor;
  // --compare-clip: the full-scene clip played beside CLIP for epsilon (paper 004).
  std::string compare_clip;
  // --breakdown: the capture set the clip was made from (error classes); --breakdown-lossless:
  // a lossless clip of it (the codec class).
  std::string breakdown, breakdown_lossless;
  uint32_t sheet_rows = HeadlessSessionOptions{}.sheet_rows;
  bool heat_maps = HeadlessSessionOptions{}.heat_maps;
  double surfel_target_ms = 0;    // --surfel-target-ms: report render times to the controller
  bool surfel_foveation = false;  // --surfel-foveation: print the peripheral objects per pose
};

// The headless evaluation (player/include/calf/player/headless_session.h): the report on stdout,
// notices on stderr.
int run_headless(Playback& play, Playback* full, Playback* lossless, const HeadlessArgs& a) {
  const HeadlessSessionOptions options{.eye_path = a.eye_path,
                                       .out = a.out,
                                       .frame_files = a.format == "exr"    ? FrameFiles::kExr
                                                      : a.format == "both" ? FrameFiles::kBoth
                                                                           : FrameFiles::kPng,
                                       .compare = a.compare,
                                       .heat_maps = a.heat_maps,
                                       .noise_floor = a.noise_floor,
                                       .breakdown = a.breakdown,
                                       .contact_sheet = a.contact_sheet,
                                       .sheet_rows = a.sheet_rows,
                                       .surfel_target_ms = a.surfel_target_ms,
                                       .surfel_foveation = a.surfel_foveation};
  auto session = HeadlessSession::open(play, full, lossless, options);
  if (!session.ok()) return fail(session.status());
  warn_dropped_views(play);
  const HeadlessSinks sinks{
      .report = [](std::string_view text) { std::fwrite(text.data(), 1, text.size(), stdout); },
      .notice =
          [](std::string_view line) {
            std::fprintf(stderr, "calf-play: %.*s\n", static_cast<int>(line.size()), line.data());
          }};
  auto summary = session->run(sinks);
  if (!summary.ok()) return fail(summary.status());
  return 0;
}

// The names of the enum options: one table each (the first entry is no default: the options
// structs hold the defaults).
constexpr tools::EnumTable<bool, 2> kRenderers = {{{"gl", true}, {"cpu", false}}};
constexpr tools::EnumTable<ViewPriority, 2> kViewPriorities = {
    {{"distance", ViewPriority::kDistance}, {"angle", ViewPriority::kAngle}}};
constexpr tools::EnumTable<SurfelClock, 2> kSurfelClocks = {
    {{"wall", SurfelClock::kWall}, {"cpu", SurfelClock::kCpu}}};

}  // namespace

static int command_main(int argc, char** argv) {
  CLI::App app{
      "calf-play: play a .calf clip: lightfield tracks (paper 002 Sec. 6) by ray-march "
      "reconstruction from the nearest viewpoints' colour + depth cube maps, decoded "
      "view-dependently; mesh tracks (paper 004: a full scene or its visible set) by "
      "rasterising their triangles; composited by depth.\n"
      "Window: drag to look, WASD/QE to fly, O orbit, R reflections/refractions (RR), C coverage "
      "on/off (--coverage's mode, else 3), V priority, +/- active views, Shift+S stereo, space "
      "pause, H HUD, Esc quit.\n"
      "Headless (--headless): renders an eye path (calf-capture writes one with --ground-truth) "
      "through OSMesa, writes frames to --out and, with --compare, prints PSNR / SSIM per pose "
      "and a final 'mean PSNR <x> dB, mean SSIM <y>' line; with --compare-clip FULL.calf it "
      "compares with the full scene instead (epsilon, PSNR, SSIM, frame times). Output files "
      "(frames, heat maps, "
      "contact sheet) are written whole; an existing directory, FIFO, device or symbolic link "
      "in their place is refused (CALF-E004).\n" +
      std::string(tools::kExitStatusHelp)};
  std::string clip;
  HeadlessArgs h;
  bool headless = false;
  bool quality = false;  // --quality: with_quality_setting() under the options given
  PlaybackOptions play_options;
  LightfieldOptions& o =
      play_options.of<LightfieldOptions>();  // the knobs below are the light field's
  WindowOptions w;
  // Every default --help shows is the value the options structs hold.
  app.option_defaults()->always_capture_default();
  app.add_option("CLIP", clip,
                 "the .calf file: every lightfield and mesh track is played, composited by depth")
      ->required();
  app.add_flag("--headless", headless,
               "render --eye-path (or the --compare directory's path) "
               "without a window, through OSMesa");
  app.add_option("--eye-path", h.eye_path,
                 "eye-path JSON (format/CAPTURE.md) to render; default "
                 "with --compare: GT_DIR/eye_path.json");
  app.add_option("--out", h.out,
                 "directory for rendered frames (frame_NNNNN.png / .exr) and error "
                 "heat maps (heat_NNNNN.png)");
  app.add_option("--format", h.format,
                 "frame files: png (8-bit sRGB), exr (half RGB + float Z, "
                 "the ground-truth layout) or both")
      ->check(CLI::IsMember({"png", "exr", "both"}));
  app.add_option("--compare", h.compare,
                 "ground-truth directory written by calf-capture "
                 "--ground-truth: per-pose PSNR / SSIM and heat maps");
  app.add_flag("!--no-heat-maps", h.heat_maps, "with --compare and --out: do not write heat maps");
  app.add_option("--noise-floor", h.noise_floor,
                 "with --compare: ground truth of the same eye path rendered with another seed; "
                 "its PSNR / SSIM against GT_DIR (the noise floor, what no figure can measure "
                 "below) is printed beside every figure (default: GT_DIR/noise-floor, which "
                 "calf-capture --ground-truth writes, when it exists)");
  app.add_option("--compare-clip", h.compare_clip,
                 "headless: also play FULL.calf (the full scene of a visible-set clip) along the "
                 "same eye path with the same renderer and print per pose and overall epsilon "
                 "(paper 004: the share of pixels whose depth lies farther than the full scene's "
                 "by more than 0.1 %, i.e. where a triangle is missing), PSNR and SSIM against it, "
                 "and the frame time of both");
  app.add_option("--breakdown", h.breakdown,
                 "with --compare: the capture set (manifest directory) the clip was made from; "
                 "each pose's squared error is split into disocclusion (the ground truth's "
                 "surface was seen by no capture view), silhouette (a depth edge within 1 pixel), "
                 "geometry (the clip shows another surface: its depth is off by more than 2 %) "
                 "and shading (the rest), printed per pose and over the path, with class maps "
                 "(classes_NNNNN.png: red, yellow, magenta, blue, codec green; brightness the "
                 "error) in --out "
                 "(docs/PLAYER.md \"Error breakdown\")");
  app.add_option(
      "--breakdown-lossless", h.breakdown_lossless,
      "with --breakdown: a lossless clip of the same capture (calf-encode --color-format "
      "rgba16f --depth-format raw16) rendered at every pose too; the error CLIP adds to it is "
      "the codec class (green)");
  app.add_option("--contact-sheet", h.contact_sheet,
                 "with --compare: write a PNG with one row per "
                 "pose: ground truth | calf | error heat map");
  app.add_option("--sheet-rows", h.sheet_rows,
                 "poses on the contact sheet, spread evenly along "
                 "the path, first and last included")
      ->check(CLI::Range(1, 256));
  SurfelOptions& so = play_options.of<SurfelOptions>();
  app.add_option("--surfel-point-size", so.point_size,
                 "surfels: disc diameter in pixels the prefixes are chosen for (the start value "
                 "with --surfel-target-ms), 1..64")
      ->check(CLI::Range(1.0, 64.0));
  app.add_option("--surfel-target-ms", so.target_frame_ms,
                 "surfels: frame-time target in ms, > 0 and <= 10000; the point size follows it "
                 "between 1 and 16 px (headless: each pose's render time counts as its frame "
                 "time); left out: a fixed point size")
      ->default_str("");
  tools::add_enum_option(app, "--surfel-clock", so.controller_clock, kSurfelClocks,
                         "surfels: the time --surfel-target-ms holds: wall (the frame time) or "
                         "cpu (the process CPU time of the renders, all threads; steadier on a "
                         "loaded machine)");
  app.add_option("--surfel-blend", so.blend_share,
                 "surfels: an object whose prefix needs more than this share of its surfels is "
                 "drawn from the mesh as well (0..1; 1: no blend zone)")
      ->check(CLI::Range(0.0, 1.0));
  std::vector<double> foveation;
  app.add_option("--surfel-foveation", foveation,
                 "surfels: fixed foveated rendering (paper 001 Sec. 4.4) as INNER,OUTER,SCALE: "
                 "an object whose centre lies within INNER of the image centre (in units of the "
                 "half-diagonal: 1 at the corners) keeps the point size, beyond OUTER it is "
                 "SCALE times larger (a shorter prefix), linear between; e.g. 0.35,0.75,2; left "
                 "out: off")
      ->default_str("")
      ->expected(3)
      ->delimiter(',');
  std::string tiles_blend = "sort";
  app.add_option("--tiles-blend", tiles_blend,
                 "tiles: sort (back to front by distance from the eye each frame, premultiplied "
                 "over; paper 000) or alpha-test (depth test, texels below 50 % alpha dropped, "
                 "any order; hard silhouettes)")
      ->check(CLI::IsMember({"sort", "alpha-test"}));
  TilesRenderOptions& tr = play_options.of<TilesOptions>().render;
  app.add_option("--tiles-occlusion-alpha", tr.occlusion_alpha,
                 "tiles, sort: an occlusion pre-pass keeps each pixel's nearest fragment at least "
                 "this opaque, and the sorted pass drops fragments behind it (what one sort "
                 "distance per tile gets wrong where tiles cross or abut at an angle); 0.5..1, "
                 "or 0 for none (Seurat's plain sort; about half the render time)");
  app.add_option("--tiles-occlusion-epsilon", tr.occlusion_epsilon,
                 "tiles, sort: how much farther (relative) than that fragment another must be to "
                 "be dropped, so overlapping tiles of one surface never hide each other; (0, 1]");
  tools::add_enum_option(app, "--renderer", play_options.use_gl, kRenderers,
                         "gl (OpenGL 4.5 ray-march, the product) or cpu (the scalar reference; "
                         "headless only)");
  app.add_option("--steps", o.render.steps, "ray-march steps in log depth")
      ->check(CLI::Range(1, 65536));
  app.add_flag("--rr", o.render.rr,
               "reflection / refraction rays from the material stream "
               "(Alg. 4 _RR); ignored with a notice when the clip has no material");
  app.add_flag("!--no-rr-replace", o.render.rr_replace_view_reflection,
               "with --rr: Alg. 4 as written, c = w c_rfl + ... + (1 - w) c_blend, instead of the "
               "default: the best view's colour with its own reflection / refraction replaced by "
               "the eye's (docs/RENDERING.md)");
  app.add_option("--hints", o.render.surface_hints,
                 "surface hint views followed along the march "
                 "(0 = the paper's march alone)")
      ->check(CLI::Range(0, 4));
  app.add_option("--hint-substeps", o.render.surface_hint_substeps, "hint tests per march step")
      ->check(CLI::Range(1, 64));
  app.add_option("--hint-vetoes", o.render.surface_hint_vetoes,
                 "light field: a surface hint's crossing ends the ray unless more than this many "
                 "views see it in front of their surface by more than --hint-margin of their "
                 "texels; 0: one such view rejects it (fewer silhouettes grown into the sky, "
                 "docs/SILHOUETTES.md \"The march's quality knobs\")")
      ->check(CLI::Range(0u, 65536u))
      ->capture_default_str();
  app.add_option("--hint-margin", o.render.surface_hint_margin_texels,
                 "light field: how far in front of its surface, in its own texel angles, a view "
                 "must see a hint crossing to veto it")
      ->check(calf::tools::kFiniteNonNegative)
      ->capture_default_str();
  app.add_option("--depth-decay", o.render.depth_decay,
                 "light field: how fast a view's colour weight falls with its depth's "
                 "disagreement at the hit, w_depth = exp(-D |ln(d_j / r)|); higher keeps views "
                 "that see a slightly different surface out of the blend (docs/SILHOUETTES.md "
                 "\"The march's quality knobs\")")
      ->check(calf::tools::kFinitePositive)
      ->capture_default_str();
  app.add_option("--cam-decay", o.render.cam_decay,
                 "light field: view blending, w_cam = exp(-D |o - P_j| / |p - o|) (the eye's "
                 "distance from viewpoint P_j over the hit's distance); lower blends more views, "
                 "which gains on textured models and loses on glossy content "
                 "(docs/SILHOUETTES.md \"The march's quality knobs\"), and an eye on a "
                 "viewpoint then no longer copies that view alone")
      ->check(calf::tools::kFiniteNonNegative)
      ->capture_default_str();
  app.add_option("--blend-views", o.render.blend_views,
                 "light field: 0 blends views by --cam-decay; K in 1..8 blends the K views "
                 "nearest the eye that see the hit with the Unstructured Lumigraph's weights, "
                 "max(0, 1 - a_j / t) / a_j (a_j = |o - P_j| / |p - o|, t that of the next "
                 "view), which need no scale: one view where the eye stands near it, the "
                 "nearest few where they are alike (docs/SILHOUETTES.md \"The march's quality "
                 "knobs\")")
      ->check(CLI::Range(0u, 8u))
      ->capture_default_str();
  app.add_option("--mixed-texel-penalty", o.render.mixed_texel_penalty,
                 "light field: colour taps on a depth edge of their view (an anti-aliased "
                 "capture mixes both sides' colours there) keep e^-P of their weight, so colour "
                 "comes from texels wholly on one surface; 0..50, 0 = off (docs/RENDERING.md "
                 "\"Mixed texels\")")
      ->check(CLI::Range(0.0, 50.0));
  app.add_option("--colour-sharpen", o.render.colour_sharpen,
                 "light field: sharpened colour taps, giving back what a bilinear tap between "
                 "texel centres blurs: each tap adds K 4 a (1 - a) times its texel's discrete "
                 "Laplacian along each axis (a: the tap's fraction along it) whose neighbours lie "
                 "on the texel's surface, none of them a mixed texel; 0..1, 0 = off; 0.2 gains "
                 "0.4-1.7 dB at the resolution-matched setting on textured content for 1.4x the "
                 "render time or more (docs/RENDERING.md \"Sharpened colour\")")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  app.add_option("--colour-sharpen-jump", o.render.colour_sharpen_jump_texels,
                 "light field, with --colour-sharpen: neighbours whose depth differs by more "
                 "than this many texel angles (2 / face size radians) are another surface and "
                 "stop the sharpening along their axis")
      ->check(calf::tools::kFiniteNonNegative)
      ->capture_default_str();
  app.add_option("--coverage", o.render.coverage,
                 "light field: how the renderer (GL or CPU) uses a clip's coverage stream (SPEC "
                 "11.1.11) in its emptiness test, as bench-player_quality --coverage uses a "
                 "capture set's: 0 off, 1 bilinear front shares, 2 cell mask, 3 grown cell mask, 4 "
                 "every tap's cell, 5 grown cell mask where a texel behind the front answers for "
                 "its own cells; "
                 "clips without coverage play as with 0; the window's C key toggles it")
      ->check(CLI::Range(0u, 5u));
  app.add_option("--coverage-agreement", o.render.coverage_agreement,
                 "light field, with --coverage: a point that a view calls empty only through its "
                 "coverage is empty once this many views say so")
      ->check(CLI::Range(1u, 65536u));
  app.add_option(
         "--hint-coverage", o.render.surface_hint_coverage,
         "light field, with coverage: a surface hint's crossing ends the ray only where the "
         "hint view's coverage covers the ray's direction in its texel (the direction's "
         "cell): 0 off, 1 on (default; clips without coverage play alike at 0 and 1); headless, "
         "--coverage 0 with --hint-coverage 0 leaves a clip's coverage stream undecoded: it "
         "plays and costs as the clip without it")
      ->check(CLI::Range(0u, 1u));
  app.add_option("--supersample", o.render.supersample,
                 "light field: N x N eye rays per pixel on an even grid, colour their mean (a box "
                 "filter, as the ground truth's), depth the nearest; anti-aliases silhouettes and "
                 "texture edges for N^2 the render time (1: the pixel centre's ray)")
      ->check(CLI::Range(1, 8));
  app.add_flag("--quality", quality,
               "light field: the quality setting, for offline renders and measurements: --steps "
               "128 --hints 4 --hint-vetoes 0 --blend-views 3 --colour-sharpen 0.2 "
               "--supersample 4, each unless given; +1.2 dB on the demo's interior clip for 35x "
               "its render time, mostly the 16 eye rays a pixel (docs/SILHOUETTES.md \"The "
               "march's quality knobs\"). Coverage stays --coverage's: which mode suits "
               "depends on the content");
  app.add_option("--views", o.selection.max_active, "most active viewpoints per frame")
      ->check(CLI::Range(1, 65536));
  tools::add_enum_option(app, "--priority", o.selection.priority, kViewPriorities,
                         "view priority: distance or angle");
  app.add_option("--frame-ms", o.selection.budget.target_frame_ms,
                 "frame-time target of performance "
                 "culling in ms, 0 = off (headless: 0 unless given, quality first)");
  app.add_flag(
      "--no-view-dependent", [&](int64_t) { o.decoder.view_dependent = false; },
      "decode every cell of the active views, not only the visible ones");
  app.add_option("--width", w.width, "window width");
  app.add_option("--height", w.height, "window height");
  app.add_option("--fov", w.fov_y_degrees, "window: vertical field of view in degrees")
      ->check(CLI::Range(10.0, 170.0));
  app.add_flag("--stereo", w.stereo, "window: side-by-side stereo (toggle with Shift+S)");
  app.add_option("--ipd", w.ipd, "window: distance between the eyes in scene units");
  app.add_option("--frames", w.max_frames, "window: quit after this many frames (0 = never)");
  // --help groups the options by what they act on.
  const auto group = [&app](const char* name, std::initializer_list<const char*> options) {
    for (const char* option : options) app.get_option(option)->group(name);
  };
  group(
      "Headless evaluation (--headless)",
      {"--eye-path", "--out", "--format", "--compare", "--no-heat-maps", "--noise-floor",
       "--compare-clip", "--breakdown", "--breakdown-lossless", "--contact-sheet", "--sheet-rows"});
  group("Light field renderer",
        {"--steps", "--rr", "--no-rr-replace", "--hints", "--hint-substeps", "--hint-vetoes",
         "--hint-margin", "--depth-decay", "--cam-decay", "--blend-views", "--mixed-texel-penalty",
         "--colour-sharpen", "--colour-sharpen-jump", "--supersample", "--quality", "--views",
         "--priority", "--frame-ms", "--no-view-dependent"});
  group("Light field coverage", {"--coverage", "--coverage-agreement", "--hint-coverage"});
  group("Surfels", {"--surfel-point-size", "--surfel-target-ms", "--surfel-clock", "--surfel-blend",
                    "--surfel-foveation"});
  group("Tiles", {"--tiles-blend", "--tiles-occlusion-alpha", "--tiles-occlusion-epsilon"});
  group("Window", {"--width", "--height", "--fov", "--stereo", "--ipd", "--frames"});
  if (int rc = tools::parse_command_line(app, "calf-play", argc, argv); rc >= 0) return rc;
  if (quality) {
    // The quality setting's knobs, except those given on the command line.
    const LightfieldRenderOptions q = with_quality_setting(o.render);
    const auto unless_given = [&app](const char* option, auto& field, auto value) {
      if (app.count(option) == 0) field = value;
    };
    unless_given("--steps", o.render.steps, q.steps);
    unless_given("--hints", o.render.surface_hints, q.surface_hints);
    unless_given("--hint-vetoes", o.render.surface_hint_vetoes, q.surface_hint_vetoes);
    unless_given("--blend-views", o.render.blend_views, q.blend_views);
    unless_given("--colour-sharpen", o.render.colour_sharpen, q.colour_sharpen);
    unless_given("--supersample", o.render.supersample, q.supersample);
  }

  tr.blend = *tiles_blend_from_name(tiles_blend);  // checked above
  if (Status st = validate_tiles_render_options(tr); !st.ok()) {
    return tools::print_error("calf-play", st, tools::kExitUsage);  // CALF-E478, exit 2
  }
  if (app.count("--surfel-target-ms") > 0 &&
      !(so.target_frame_ms > 0 && so.target_frame_ms <= 10000)) {
    return contradiction("--surfel-target-ms " + std::to_string(so.target_frame_ms) +
                         " is not a frame time in (0, 10000] ms (leave it out for a fixed "
                         "point size)");
  }
  if (!foveation.empty()) {
    so.foveation = {.enabled = true,
                    .inner = foveation[0],
                    .outer = foveation[1],
                    .periphery_scale = foveation[2]};
    if (Status s = validate_surfel_options(so); !s.ok()) {
      return tools::print_error("calf-play", s, tools::kExitUsage);
    }
  }
  if (headless && app.count("--frame-ms") == 0) o.selection.budget.target_frame_ms = 0;
  // Headless options never change while playing: a coverage stream that they do not read is
  // not decoded (the window keeps it for the C key).
  if (headless) o.keep_coverage = false;
  if (headless) {
    if (h.eye_path.empty() && h.compare.empty()) {
      return contradiction("--headless needs --eye-path or --compare");
    }
    if (!h.contact_sheet.empty() && h.compare.empty()) {
      return contradiction("--contact-sheet needs --compare");
    }
    if (!h.noise_floor.empty() && h.compare.empty()) {
      return contradiction("--noise-floor needs --compare");
    }
    if (!h.breakdown.empty() && h.compare.empty()) {
      return contradiction("--breakdown needs --compare");
    }
    if (!h.breakdown_lossless.empty() && h.breakdown.empty()) {
      return contradiction("--breakdown-lossless needs --breakdown");
    }
    if (!h.compare_clip.empty() && fs::path(h.compare_clip) == fs::path(clip)) {
      return contradiction("--compare-clip names CLIP itself");
    }
    std::unique_ptr<OsMesaContext> context;
    const GlFunctions* gl = nullptr;
    if (play_options.use_gl) {
      auto c = OsMesaContext::make();
      if (!c.ok()) return fail(c.status());
      context = std::move(*c);
      gl = &context->gl();
    }
    auto play = Playback::open(clip, play_options, gl);
    if (!play.ok()) return fail(play.status());
    std::unique_ptr<Playback> full;
    if (!h.compare_clip.empty()) {
      auto f = Playback::open(h.compare_clip, play_options, gl);
      if (!f.ok()) return fail(f.status());
      full = std::move(*f);
    }
    std::unique_ptr<Playback> lossless;
    if (!h.breakdown_lossless.empty()) {
      auto f = Playback::open(h.breakdown_lossless, play_options, gl);
      if (!f.ok()) return fail(f.status());
      lossless = std::move(*f);
    }
    h.surfel_target_ms = so.target_frame_ms;
    h.surfel_foveation = so.foveation.enabled;
    return run_headless(**play, full.get(), lossless.get(), h);
  }
  if (!h.breakdown.empty()) {
    return contradiction("--breakdown works only with --headless");
  }
  if (!h.compare_clip.empty()) {
    return contradiction("--compare-clip works only with --headless");
  }
  if (!play_options.use_gl) {
    return contradiction("--renderer cpu works only with --headless");
  }
  if (!h.contact_sheet.empty()) {
    return contradiction("--contact-sheet works only with --headless");
  }
  if (Status s = run_window(clip, play_options, w); !s.ok()) return fail(s);
  return 0;
}

int main(int argc, char** argv) {
  return calf::tools::run_command("calf-play", [&] { return command_main(argc, argv); });
}
