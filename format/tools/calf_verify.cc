// calf-verify: full validation of .calf files (format/SPEC.md): header, directory, limits, every
// chunk's hash and decompression, every padding byte. Prints one line per problem, each with
// its stable id, and exits 0 only when every file is good.
#include <fmt/core.h>
#include <CLI/CLI.hpp>

#include "calf/format/container.h"
#include "calf/format/version.h"

int main(int argc, char** argv) {
  CLI::App app{
      "calf-verify: check .calf files completely (header, directory, every chunk hash and "
      "decompression, padding).\nExit status: 0 all files good, 1 a problem was found, "
      "2 bad command line."};
  app.set_version_flag("--version", std::string("calf ") + calf::kVersionString);
  std::vector<std::string> files;
  bool quiet = false;
  size_t max_problems = 100;
  app.add_option("FILE", files, "the .calf files to verify")->required();
  app.add_flag("-q,--quiet", quiet, "print problems only, no 'ok' line");
  app.add_option("--max-problems", max_problems, "stop listing a file's problems after N")
      ->check(CLI::PositiveNumber);
  CLI11_PARSE(app, argc, argv);

  int rc = 0;
  for (const auto& path : files) {
    auto reader = calf::container::Reader::open(path);
    if (!reader.ok()) {
      // Errors opening the file already name it; later ones (header, directory) get it added.
      const calf::Status& s = reader.status();
      fmt::print(
          "{}\n",
          (s.message().find(path) == std::string::npos ? s.with_context(path) : s).to_string());
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
