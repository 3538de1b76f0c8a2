// calf-encode: a capture set in, a .calf with a lightfield track out (paper 002, Sec. 5;
// format/SPEC.md §11.1); with --mode mesh, surfels or tiles a mesh, surfels or tiles track. Each
// mode is a file of calf_encode/ (its options struct, add_options, run); this file parses the
// command line and runs the mode --mode names. Errors are one line with a stable id and exit
// status 1 (no output file is left behind, also when SIGINT / SIGTERM / SIGHUP end it); usage
// errors exit 2 (command_line.h).
#include <cstdlib>
#include <string>

#include <CLI/CLI.hpp>

#include "calf_encode/common.h"
#include "calf_encode/lightfield.h"
#include "calf_encode/mesh.h"
#include "calf_encode/surfels.h"
#include "calf_encode/tiles.h"
#include "command_line.h"

namespace calf::tools {
namespace {

// The option groups of each mode: an option of one given with another --mode is a usage error.
struct ModeGroup {
  const char* group;
  EncodeMode mode;
};
constexpr ModeGroup kModeGroups[] = {
    {kLightfieldGroup, EncodeMode::kLightfield}, {kAv1Group, EncodeMode::kLightfield},
    {kShardGroup, EncodeMode::kLightfield},      {kMeshGroup, EncodeMode::kMesh},
    {kSurfelsGroup, EncodeMode::kSurfels},       {kTilesGroup, EncodeMode::kTiles}};

// Exit status 2 and its line when `app` holds an option of a mode other than `mode`; -1 if none.
int check_mode_options(const CLI::App& app, EncodeMode mode) {
  for (const CLI::Option* opt : app.get_options()) {
    if (opt->count() == 0) continue;
    for (const ModeGroup& g : kModeGroups) {
      if (opt->get_group() != g.group || g.mode == mode) continue;
      if (g.mode == EncodeMode::kTiles) {
        return usage_error("calf-encode", "--tiles-* options need --mode tiles");
      }
      return usage_error("calf-encode",
                         opt->get_name() + " needs --mode " + enum_name(kEncodeModes, g.mode));
    }
  }
  return -1;
}

int command_main(int argc, char** argv) {
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
      "docs/ERRORS.md).\n"
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
      "CALF-E250..E254.\n"
      "The options below are grouped by mode; an option of another mode's group (e.g. --cell or "
      "--analysis with --mode mesh, --surfels without --mode surfels, --tiles-* without --mode "
      "tiles, --visible-set without --mode mesh) is a usage error (exit 2).\n" +
      std::string(kExitStatusHelp)};
  app.option_defaults()->always_capture_default();
  CommonOptions common;
  LightfieldOptions lightfield;
  MeshOptions mesh;
  SurfelsOptions surfels;
  TilesOptions tiles;
  add_options(app, common);
  add_options(app, lightfield);
  add_options(app, mesh);
  add_options(app, surfels);
  add_options(app, tiles);
  if (int rc = parse_command_line(app, "calf-encode", argc, argv); rc >= 0) return rc;
  if (int rc = check_mode_options(app, common.mode); rc >= 0) return rc;
  switch (common.mode) {
    case EncodeMode::kTiles:
      return run(common, tiles);
    case EncodeMode::kSurfels:
      if (surfels.candidates.empty()) {
        return usage_error("calf-encode",
                           "--mode surfels needs --surfel-candidates and takes no --visible-set");
      }
      return run(common, surfels);
    case EncodeMode::kMesh:
      return run(common, mesh);
    case EncodeMode::kLightfield:
      break;
  }
  if (int rc = resolve(app, common, &lightfield); rc >= 0) return rc;
  return run(common, lightfield);
}

}  // namespace
}  // namespace calf::tools

int main(int argc, char** argv) {
  // SVT-AV1 (--colour-codec av1) prints its banner and settings to stderr unless SVT_LOG says
  // otherwise; set before any thread starts, and a user's own setting is kept.
  setenv("SVT_LOG", "0", 0);
  return calf::tools::run_command("calf-encode",
                                  [&] { return calf::tools::command_main(argc, argv); });
}
