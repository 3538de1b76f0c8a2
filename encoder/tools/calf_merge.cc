// calf-merge: joins the shard files of a sharded light-field encode (calf-encode --analysis-only,
// then calf-encode --analysis --views per shard) into one clip, byte-identical to a one-machine
// encode with the same options (docs/FARM.md). Errors are one line with a stable id and exit
// status 1 (no output is left behind); usage errors exit 2 (command_line.h).
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "calf/encoder/lightfield_shard.h"
#include "command_line.h"

static int command_main(int argc, char** argv) {
  CLI::App app{
      "calf-merge: join the shard files of a sharded light-field encode into one .calf clip "
      "(docs/FARM.md).\n"
      "Every shard must come from the given analysis file (CALF-E163 otherwise), no view-frame "
      "may be in two shards (CALF-E164) and every view-frame must be in one (CALF-E165); the "
      "stored chunks are copied view by view without recompression (the t chunks of frame-range "
      "shards are joined and compressed as one encode does), so the clip is byte for byte the one "
      "calf-encode writes on one machine with the options recorded in the analysis file. The "
      "output is written whole or not at all (a temporary file renamed into place; removed on an "
      "error or on SIGINT / SIGTERM / SIGHUP); an output that is one of the inputs is refused "
      "(CALF-E007).\n" +
          std::string(calf::tools::kExitStatusHelp),
      "calf-merge"};
  std::string analysis_path, out;
  std::vector<std::string> shards;
  bool quiet = false;
  app.add_option("SHARD", shards,
                 "shard files (calf-encode --analysis FILE --views LIST -o SHARD), in any order")
      ->required();
  app.add_option("--analysis", analysis_path,
                 "the analysis file the shards were coded with (calf-encode --analysis-only); "
                 "required")
      ->required();
  app.add_option("-o,--output", out, "output .calf clip (written whole or not at all); required")
      ->required();
  app.add_flag("-q,--quiet", quiet, "no summary line (default off)");
  if (int rc = calf::tools::parse_command_line(app, "calf-merge", argc, argv); rc >= 0) return rc;

  const auto start = std::chrono::steady_clock::now();
  auto analysis = calf::encoder::read_lightfield_analysis(analysis_path);
  if (!analysis.ok()) return calf::tools::print_error("calf-merge", analysis.status());
  if (calf::Status s = calf::encoder::merge_lightfield_shards(*analysis, shards, out); !s.ok()) {
    return calf::tools::print_error("calf-merge", s);
  }
  if (!quiet) {
    std::fprintf(stderr, "calf-merge: wrote %s from %zu shards (%u views) in %.2f s\n", out.c_str(),
                 shards.size(), analysis->analysis.header.view_count,
                 std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  return 0;
}

int main(int argc, char** argv) {
  return calf::tools::run_command("calf-merge", [&] { return command_main(argc, argv); });
}
