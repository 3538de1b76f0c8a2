#include "calf_encode/common.h"

#include <sys/resource.h>

#include "command_line.h"

namespace calf::tools {

void add_options(CLI::App& app, CommonOptions& o) {
  app.add_option("MANIFEST", o.input,
                 "lightfield, tiles: the capture set (its manifest.json or the directory holding "
                 "it); mesh, surfels: the scene file (its scene.json or folder)")
      ->required();
  add_enum_option(app, "--mode", o.mode, kEncodeModes,
                  "lightfield (a capture set into a lightfield track), mesh (a scene file into "
                  "a mesh track) or surfels (a scene file and its surfel candidates into a mesh "
                  "track and a surfels track) or tiles (one frame of a capture set into a tiles "
                  "track)");
  app.add_option("-o,--output", o.output, "output .calf (written whole or not at all)")->required();
  app.add_option("--threads", o.threads,
                 "worker threads 0..256, 0 = all cores; output is identical for any count")
      ->check(CLI::Range(0u, kMaxThreads));
  app.add_option("--max-image-pixels", o.max_image_pixels,
                 std::string("every mode: ") + capture::kMaxImagePixelsHelp +
                     " (lightfield, tiles: a capture set's face size counts 6 x its square; "
                     "mesh, surfels: scene-file textures)")
      ->check(CLI::Range(uint64_t{1}, capture::kMaxImagePixelsLimit));
  add_enum_option(app, "--supercompression", o.supercompression, kSupercompressions,
                  "every mode, per chunk: zstd (level 19), lzma2 (preset 6), none");
  app.add_flag("--plain-directory", o.plain_directory,
               "every mode: write a container 1.0 file (plain 64-byte chunk index entries) that "
               "calf 1.0 readers open, instead of 1.1's directory compressed as one zstd frame "
               "(format/SPEC.md 4.1: 2-43 % smaller lightfield clips, git log -p docs/ENCODER.md "
               "\"Compressed directory\"); sharded encodes always write 1.1");
  app.add_flag("-q,--quiet", o.quiet, "no progress line");
}

std::filesystem::path input_folder(const std::string& input, const char* manifest) {
  std::filesystem::path dir = input;
  if (dir.filename() == manifest) dir = dir.parent_path();
  if (dir.empty()) dir = ".";
  return dir;
}

int fail(const Status& status) {
  return print_error("calf-encode", status);
}

double peak_rss_mib() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_maxrss) / 1024.0;  // Linux: KiB
}

}  // namespace calf::tools
