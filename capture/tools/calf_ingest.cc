// calf-ingest: converts other renderers' captures into calf capture sets (format/CAPTURE.md,
// "Ingest"); the library calls are calf/capture/ingest.h.
#include <cstdio>
#include <string>

#include <fmt/core.h>
#include <CLI/CLI.hpp>

#include "calf/capture/ingest.h"
#include "command_line.h"

static int command_main(int argc, char** argv) {
  CLI::App app{std::string("calf-ingest: convert a capture made by another renderer into a calf "
                           "capture set (format/CAPTURE.md, \"Ingest\") that calf-encode reads.\n"
                           "  calf-ingest seurat MANIFEST OUT_DIR     a Seurat capture manifest "
                           "(Maya, Unity, Unreal): one viewpoint per view group\n"
                           "  calf-ingest equirect MANIFEST OUT_DIR   equirectangular colour + "
                           "radial depth per viewpoint and frame\n"
                           "A MANIFEST holding a frame number, %d or %0Nd (e.g. "
                           "frame_%04d/manifest.json), is a sequence: one manifest per frame "
                           "(equirect: per run of frames) from --first-frame on, all made one "
                           "animated capture set; every frame must be the same rig.\n") +
               calf::tools::kExitStatusHelp};
  app.require_subcommand(1);
  app.fallthrough();  // --quiet may follow the subcommand
  calf::capture::IngestOptions options;
  std::string manifest, out, filter = "catmull-rom", depth = "nearest";
  bool quiet = false;
  uint32_t first_frame = 0, frame_count = 0;
  app.add_flag("--quiet", quiet, "print no summary line (default: print one)");
  const auto add_sequence_options = [&](CLI::App* sub) {
    sub->add_option("--first-frame", first_frame,
                    "with a MANIFEST pattern: the number of its first frame; default 0")
        ->check(CLI::Range(0u, 999999999u));
    sub->add_option("--frame-count", frame_count,
                    "with a MANIFEST pattern: how many manifests; default 0 = every one from "
                    "--first-frame up to the first number with no file")
        ->check(CLI::Range(0u, 1000000u));
  };

  CLI::App* seurat = app.add_subcommand(
      "seurat",
      "Seurat manifest -> capture set: each view group becomes a viewpoint at its views' "
      "common centre, its faces resampled from the views (an exact cube map is copied "
      "texel for texel); colour bilinear, depth from the nearest pixel, made radial.");
  seurat
      ->add_option("MANIFEST", manifest,
                   "the Seurat JSON manifest, or a pattern naming one per frame (%d or %0Nd); "
                   "image paths are relative to each manifest")
      ->required();
  seurat->add_option("OUT_DIR", out, "the capture set to write (created; manifest.json last)")
      ->required();
  seurat
      ->add_option("--face-size", options.face_size,
                   "texels per face side, 0..16384; default 0 = the largest pixel density of "
                   "any view (an exact cube map keeps its size); the six faces must fit "
                   "--max-image-pixels (by default a face size of at most 3344)")
      ->check(CLI::Range(0, 16384));
  seurat
      ->add_option("--headbox-size", options.headbox_size,
                   "side of the view volume, centred on headbox_center (else on the groups' "
                   "box); default 0 = the box of the view-group positions, which must not be a "
                   "point")
      ->check(CLI::Range(0.0, 1e12));
  seurat->add_option("--fps", options.fps, "frames per second written to the manifest; default 30")
      ->check(CLI::Range(1e-3, 1000.0));
  seurat
      ->add_option("--max-image-pixels", options.max_image_pixels,
                   calf::capture::kMaxImagePixelsHelp)
      ->check(CLI::Range(uint64_t{1}, calf::capture::kMaxImagePixelsLimit));

  CLI::App* equirect =
      app.add_subcommand("equirect",
                         "equirectangular set -> capture set: colour is the mean of k x k filtered "
                         "samples per texel, depth the nearest pixel's.");
  equirect
      ->add_option("MANIFEST", manifest,
                   "the calf-equirect-set manifest (CAPTURE.md), or a pattern naming several "
                   "(%d or %0Nd) whose frames follow each other; images relative to each")
      ->required();
  equirect->add_option("OUT_DIR", out, "the capture set to write (created; manifest.json last)")
      ->required();
  equirect
      ->add_option("--face-size", options.face_size,
                   "texels per face side, 0..16384; default 0 = round(width / pi), the "
                   "input's equatorial density at each face centre; the six faces must fit "
                   "--max-image-pixels (by default a face size of at most 3344)")
      ->check(CLI::Range(0, 16384));
  equirect
      ->add_option("--supersample", options.supersample,
                   "colour samples per texel side (k x k); default 2")
      ->check(CLI::Range(1, 8));
  equirect
      ->add_option("--filter", filter,
                   "how a colour sample reads the (sharpened) image: catmull-rom (default: "
                   "bicubic over 4 x 4 pixels, clamped at 0) or bilinear (softer)")
      ->check(CLI::IsMember({"catmull-rom", "bilinear"}));
  equirect
      ->add_option("--sharpen", options.equirect_sharpen,
                   "sharpen each pixel by [-a, 1 + 2a, -a] per axis before sampling, undoing the "
                   "renderer's pixel box (1/24 undoes it to second order); default 0.125, "
                   "measured best on the interior scene; 0 = none")
      ->check(CLI::Range(0.0, 0.25));
  equirect
      ->add_option("--depth", depth,
                   "how a texel's depth is read: nearest (default: the nearest pixel's, never a "
                   "depth between two surfaces) or edge-aware (bilinear where the 2 x 2 nearest "
                   "pixels agree within 2 %, else nearest)")
      ->check(CLI::IsMember({"nearest", "edge-aware"}));
  equirect
      ->add_option("--max-image-pixels", options.max_image_pixels,
                   calf::capture::kMaxImagePixelsHelp)
      ->check(CLI::Range(uint64_t{1}, calf::capture::kMaxImagePixelsLimit));

  add_sequence_options(seurat);
  add_sequence_options(equirect);
  if (int rc = calf::tools::parse_command_line(app, "calf-ingest", argc, argv); rc >= 0) return rc;
  options.equirect_filter = filter == "bilinear" ? calf::capture::EquirectFilter::kBilinear
                                                 : calf::capture::EquirectFilter::kCatmullRom;
  options.equirect_depth = depth == "edge-aware" ? calf::capture::EquirectDepth::kEdgeAware
                                                 : calf::capture::EquirectDepth::kNearest;
  calf::capture::IngestReport report;
  const bool is_seurat = seurat->parsed();
  if (manifest.find('%') == std::string::npos && (first_frame || frame_count)) {
    return calf::tools::usage_error("calf-ingest",
                                    "--first-frame and --frame-count need a MANIFEST pattern "
                                    "(%d or %0Nd)");
  }
  auto manifests = calf::capture::frame_manifests(manifest, first_frame, frame_count);
  if (!manifests.ok()) {
    // A malformed pattern is a bad argument (exit 2); a missing first manifest an error.
    if (manifests.status().id() == calf::ErrorId::kInvalidArgument) {
      return calf::tools::usage_error("calf-ingest", manifests.status().message());
    }
    return calf::tools::print_error("calf-ingest", manifests.status());
  }
  const calf::Status s = is_seurat
                             ? calf::capture::ingest_seurat(*manifests, out, options, &report)
                             : calf::capture::ingest_equirect(*manifests, out, options, &report);
  if (!s.ok()) return calf::tools::print_error("calf-ingest", s);
  if (!quiet) {
    fmt::print("calf-ingest: wrote {} viewpoint(s) x {} frame(s), face size {}{} to {}\n",
               report.viewpoints, report.frames, report.face_size,
               is_seurat ? fmt::format(", {} group(s) copied exactly", report.exact_groups) : "",
               out);
  }
  return 0;
}

int main(int argc, char** argv) {
  return calf::tools::run_command("calf-ingest", [&] { return command_main(argc, argv); });
}
