// calf-verify: full validation of .calf files (format/SPEC.md): header, directory, limits, every
// chunk's hash and decompression, every padding byte. Prints one line per problem, each with
// its stable id, and exits 0 only when every file is good.
#include <fmt/core.h>
#include <CLI/CLI.hpp>

#include "calf/format/container.h"
#include "calf/format/version.h"
#include "command_line.h"

int main(int argc, char** argv) {
  CLI::App app{
      std::string("calf-verify: check .calf files completely (header, directory, every chunk "
                  "hash and decompression, padding). Problems are listed on stdout, one line "
                  "each with its CALF id.\nExit status: 0 all files good; 1 a problem was found "
                  "(or a file could not be opened); 2 a usage error (bad option or argument), one "
                  "line with CALF-E006 on stderr.")};
  app.set_version_flag("--version", std::string("calf ") + calf::kVersionString);
  std::vector<std::string> files;
  bool quiet = false;
  size_t max_problems = 100;
  app.add_option("FILE", files, "the .calf files to verify (regular files)")->required();
  app.add_flag("-q,--quiet", quiet, "print problems only, no 'ok' line");
  app.add_option("--max-problems", max_problems,
                 "stop listing a file's problems after N, 1..1000000 (default 100)")
      ->check(CLI::Range(size_t{1}, size_t{1000000}));
  if (int rc = calf::tools::parse_command_line(app, "calf-verify", argc, argv); rc >= 0) return rc;

  int rc = 0;
  for (const auto& path : files) {
    // Reader::open's errors name the file once.
    auto reader = calf::container::Reader::open(path);
    if (!reader.ok()) {
      fmt::print("{}\n", reader.status().to_string());
      rc = 1;
      continue;
    }
    const auto problems = reader->verify(max_problems);
    for (const auto& p : problems) fmt::print("{}\n", p.with_context(path).to_string());
    if (!problems.empty()) {
      rc = 1;
    } else if (!quiet) {
      fmt::print("{}: ok ({} tracks, {} chunks, {} bytes verified)\n", path,
                 reader->tracks().size(), reader->chunks().size(), reader->header().file_size);
    }
  }
  return rc;
}
