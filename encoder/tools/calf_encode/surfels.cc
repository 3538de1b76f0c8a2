#include "calf_encode/surfels.h"

#include <chrono>
#include <cstdio>
#include <filesystem>

#include "calf/capture/scene_file.h"
#include "calf/encoder/mesh_encode.h"

namespace calf::tools {

namespace {

inline constexpr EnumTable<encoder::SurfelOrderMethod, 4> kSurfelSamplers = {
    {{"greedy-tree", encoder::SurfelOrderMethod::kGreedyTree},
     {"progressive", encoder::SurfelOrderMethod::kProgressive},
     {"exact", encoder::SurfelOrderMethod::kExactGreedy},
     {"random", encoder::SurfelOrderMethod::kRandom}}};

}  // namespace

void add_options(CLI::App& app, SurfelsOptions& o) {
  app.add_option("--surfel-candidates", o.candidates,
                 "surfels: the candidate file of the scene (calf-capture --surfel-candidates)")
      ->group(kSurfelsGroup);
  app.add_option("--surfels", o.build.max_surfels,
                 "surfels: most surfels per prototype, 1..2^26 (fewer when it has fewer "
                 "candidates)")
      ->check(CLI::Range(1u, 1u << 26))
      ->group(kSurfelsGroup);
  add_enum_option(app, "--surfel-sampler", o.build.sampler.method, kSurfelSamplers,
                  "surfels: greedy-tree (the greedy permutation through a tree of boxes, about "
                  "O(N log n)), progressive (paper 001's approximate greedy permutation), exact "
                  "(the same order as greedy-tree, plain O(n N): slow) or random")
      ->group(kSurfelsGroup);
}

int run(const CommonOptions& common, const SurfelsOptions& options) {
  encoder::SurfelBuildOptions build = options.build;
  build.sampler.threads = common.threads;
  encoder::MeshEncodeOptions mesh;
  mesh.max_image_pixels = common.max_image_pixels;
  encoder::SurfelsEncodeOptions surfels;
  mesh.threads = surfels.threads = common.threads;
  mesh.levels.compress_directory = surfels.levels.compress_directory = !common.plain_directory;
  mesh.supercompression = surfels.supercompression = common.supercompression;
  const std::filesystem::path dir = input_folder(common.input, capture::kSceneManifestFileName);
  const std::string& out = common.output;
  const auto start = std::chrono::steady_clock::now();
  encoder::SurfelsEncodeStats encoded;
  auto stats =
      encoder::encode_surfel_file(dir, options.candidates, out, build, mesh, surfels, &encoded);
  if (!stats.ok()) return fail(stats.status());
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::fprintf(stderr,
               "calf-encode: wrote %s in %.2f s (surfels: %u of %u prototypes, %llu surfels of "
               "%llu candidates, %s sampler %.2f s; %.2f bytes per surfel stored)\n",
               out.c_str(), seconds, stats->prototypes_with_surfels, stats->prototypes,
               static_cast<unsigned long long>(stats->surfels),
               static_cast<unsigned long long>(stats->candidates),
               encoder::surfel_order_method_name(build.sampler.method), stats->sample_seconds,
               stats->surfels ? static_cast<double>(encoded.surfels_stored) /
                                    static_cast<double>(stats->surfels)
                              : 0.0);
  std::fprintf(stderr, "calf-encode: peak RSS %.1f MiB\n", peak_rss_mib());
  return 0;
}

}  // namespace calf::tools
