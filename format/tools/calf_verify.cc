// calf-verify: full validation of .calf files (format/SPEC.md): header, directory, limits, every
// chunk's hash and decompression, every padding byte, then each lightfield track's layout by
// decoding every face of every view at every frame (calf/decoder/lightfield_verify.h) and each
// mesh track's by decoding every prototype and object (calf/decoder/mesh_verify.h), and each
// surfels track's by decoding every prototype's buffer (calf/decoder/surfels_verify.h), and each
// tiles track's by decoding its quads and atlas (calf/decoder/tiles_verify.h). Prints one
// line per problem, each with its stable id, and exits 0 only when every file is good. With
// --decode it prints the conformance hash of every decoded face (SPEC §14).
#include <fmt/core.h>
#include <CLI/CLI.hpp>

#include "calf/decoder/lightfield_verify.h"
#include "calf/decoder/mesh_verify.h"
#include "calf/decoder/surfels_verify.h"
#include "calf/decoder/tiles_verify.h"
#include "calf/format/container.h"
#include "calf/format/track_kinds.h"
#include "calf/format/version.h"
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
  app.set_version_flag("--version", std::string("calf ") + calf::kVersionString);
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
    uint64_t faces = 0, mesh_parts = 0, surfel_prototypes = 0, surfels = 0, tiles = 0,
             tile_tracks = 0;
    std::vector<std::string> hash_lines;
    for (const auto& track : reader->tracks()) {
      if (container_only || !problems.empty()) break;
      if (track.record.kind == static_cast<uint16_t>(calf::container::TrackKind::kMesh)) {
        const auto result =
            calf::decoder::verify_mesh_track(*reader, track.id, decode, max_problems);
        problems.insert(problems.end(), result.problems.begin(), result.problems.end());
        mesh_parts += result.prototypes_decoded + result.objects_decoded;
        hash_lines.insert(hash_lines.end(), result.hash_lines.begin(), result.hash_lines.end());
        continue;
      }
      if (track.record.kind == static_cast<uint16_t>(calf::container::TrackKind::kSurfels)) {
        const auto result =
            calf::decoder::verify_surfels_track(*reader, track.id, decode, max_problems);
        problems.insert(problems.end(), result.problems.begin(), result.problems.end());
        surfel_prototypes += result.prototypes_decoded;
        surfels += result.surfels_decoded;
        hash_lines.insert(hash_lines.end(), result.hash_lines.begin(), result.hash_lines.end());
        continue;
      }
      if (track.record.kind == static_cast<uint16_t>(calf::container::TrackKind::kTiles)) {
        const auto result =
            calf::decoder::verify_tiles_track(*reader, track.id, decode, max_problems);
        problems.insert(problems.end(), result.problems.begin(), result.problems.end());
        tiles += result.tiles_decoded;
        tile_tracks += result.skipped ? 0 : 1;
        hash_lines.insert(hash_lines.end(), result.hash_lines.begin(), result.hash_lines.end());
        continue;
      }
      if (track.record.kind != static_cast<uint16_t>(calf::container::TrackKind::kLightfield))
        continue;
      const auto result =
          calf::decoder::verify_lightfield_track(*reader, track.id, decode, max_problems);
      problems.insert(problems.end(), result.problems.begin(), result.problems.end());
      faces += result.faces_decoded;
      for (const auto& h : result.hashes) {
        hash_lines.push_back(calf::decoder::face_hash_line(track.id, h));
      }
    }
    if (problems.size() > max_problems) problems.resize(max_problems);
    for (const auto& p : problems) fmt::print("{}\n", p.with_context(path).to_string());
    if (!problems.empty()) {
      rc = 1;
      continue;
    }
    for (const auto& line : hash_lines) fmt::print("{}\n", line);
    if (!quiet) {
      fmt::print(
          "{}: ok ({} tracks, {} chunks, {} bytes verified{})\n", path, reader->tracks().size(),
          reader->chunks().size(), reader->header().file_size,
          container_only
              ? ", layouts not checked"
              : fmt::format(", {} faces decoded{}", faces,
                            mesh_parts ? fmt::format(", {} mesh prototypes and "
                                                     "objects decoded",
                                                     mesh_parts)
                                       : "") +
                    (surfel_prototypes ? fmt::format(", {} surfel prototypes ({} surfels) "
                                                     "decoded",
                                                     surfel_prototypes, surfels)
                                       : "") +
                    (tile_tracks ? fmt::format(", {} tiles and their atlas decoded", tiles) : ""));
    }
  }
  return rc;
}

int main(int argc, char** argv) {
  return calf::tools::run_command("calf-verify", [&] { return command_main(argc, argv); });
}
