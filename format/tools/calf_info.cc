// calf-info: prints what a .calf clip holds. Until the container reader lands (issue 3) it only
// answers --version.
#include <CLI/CLI.hpp>
#include <fmt/core.h>

#include "calf/format/version.h"

int main(int argc, char** argv) {
  CLI::App app{"calf-info: summarise a calf clip (version, tracks, frames, views, sizes)"};
  app.set_version_flag("--version", std::string("calf ") + calf::kVersionString);
  CLI11_PARSE(app, argc, argv);
  fmt::print("calf {}\n", calf::kVersionString);
  return 0;
}
