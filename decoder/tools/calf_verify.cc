// calf-verify: full validation of .calf files (format/SPEC.md): header, directory, limits, every
// chunk's hash and decompression, every padding byte, then each track's layout by decoding all
// of it through its kind's entry in the decoder table (calf/decoder/kind_table.h, one
// <kind>_verify.h each). Prints one line per problem, each with its stable id, and exits 0 only
// when every file is good. With --decode it prints the conformance hashes of what it decoded
// (SPEC §14 and each kind's §11 section).
#include <fmt/core.h>
#include <CLI/CLI.hpp>

#include <algorithm>

#include "calf/decoder/kind_table.h"
#include "calf/format/container.h"
#include "command_line.h"

static int command_main(int argc, char** argv) {
  CLI::App app{std::string(
      "calf-verify: check .calf files completely: header, directory, every chunk "
      "hash and decompression, padding, then every lightfield, mesh, surfels and tiles track's "
      "layout "
      "by decoding all of it. Problems are listed on stdout, one line each with its CALF "
      "id.\nExit status: 0 all files good; 1 a problem was found (or a file could not "
      "be opened); 2 a usage error (bad option or argument), one line with CALF-E006 "
      "on stderr.")};
  std::vector<std::string> files;
  bool quiet = false, container_only = false, decode = false;
  size_t max_problems = 100;
  app.add_option("FILE", files, "the .calf files to verify (regular files)")->required();
  app.add_flag("-q,--quiet", quiet, "print problems only, no 'ok' line");
  app.add_flag("--container-only", container_only,
               "check the container alone (SPEC §2-§10), not the tracks' layouts (§11)");
  app.add_flag("--decode", decode,
               "also print the conformance hash of every decoded face, one line each: "
               "'track T frame F view V face X <XXH3-64 hex>' (SPEC §14), and of every mesh "
               "prototype and object: 'track T prototype P <hex>', 'track T object O <hex>' "
               "(SPEC §11.4.7), and of every surfels prototype: 'track T surfels P <hex>' "
               "(SPEC §11.3.6), and of every tiles track's quads and atlas: 'track T tiles quads "
               "<hex>', 'track T tiles atlas <hex>' (SPEC §11.2.6); a file with problems prints "
               "none")
      ->excludes("--container-only");
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
    auto problems = reader->verify(max_problems);
    // Layouts only of a sound container: damaged chunks would only repeat the problems above.
    // Each track through its kind's entry in the decoder table; a kind it lacks is skipped.
    const auto kinds = calf::decoder::decoder_kinds();
    std::vector<calf::decoder::VerifiedTotals> totals(kinds.size());
    std::vector<std::string> hash_lines;
    for (const auto& track : reader->tracks()) {
      if (container_only || !problems.empty()) break;
      const auto* entry = calf::decoder::find_decoder_kind(track.record.kind);
      if (entry == nullptr) continue;
      auto result = entry->verify(*reader, track.id, decode, max_problems);
      problems.insert(problems.end(), result.problems.begin(), result.problems.end());
      hash_lines.insert(hash_lines.end(), result.hash_lines.begin(), result.hash_lines.end());
      auto& sum =
          totals[static_cast<size_t>(std::find(kinds.begin(), kinds.end(), entry) - kinds.begin())];
      sum.decoded[0] += result.decoded[0];
      sum.decoded[1] += result.decoded[1];
      sum.tracks += result.skipped ? 0 : 1;
    }
    if (problems.size() > max_problems) problems.resize(max_problems);
    for (const auto& p : problems) fmt::print("{}\n", p.with_context(path).to_string());
    if (!problems.empty()) {
      rc = 1;
      continue;
    }
    for (const auto& line : hash_lines) fmt::print("{}\n", line);
    if (!quiet) {
      std::string decoded;
      for (size_t k = 0; k < kinds.size(); ++k) decoded += kinds[k]->verified_summary(totals[k]);
      fmt::print("{}: ok ({} tracks, {} chunks, {} bytes verified{})\n", path,
                 reader->tracks().size(), reader->chunks().size(), reader->header().file_size,
                 container_only ? ", layouts not checked" : decoded);
    }
  }
  return rc;
}

int main(int argc, char** argv) {
  return calf::tools::run_command("calf-verify", [&] { return command_main(argc, argv); });
}
