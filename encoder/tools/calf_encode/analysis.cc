#include "calf_encode/analysis.h"

#include <chrono>
#include <cstdio>

#include "calf/capture/capture_shard.h"
#include "calf/encoder/lightfield_shard.h"
#include "command_line.h"

namespace calf::tools {

void add_options(CLI::App& app, ShardOptions& o) {
  app.add_flag("--analysis-only", o.analysis_only,
               "sharded encode step 1: run only the analysis pass over the whole capture set and "
               "write the analysis file (a small .calf: the track header, every view's depth "
               "range, material and HDR facts, these options) to -o")
      ->group(kShardGroup);
  app.add_option("--analysis", o.analysis,
                 "sharded encode step 2: code only --views with the options recorded in this "
                 "analysis file (giving lightfield options too is a usage error) and write a "
                 "shard file to -o; calf-merge joins the shards into the clip, byte-identical to "
                 "a one-machine encode")
      ->group(kShardGroup);
  app.add_option("--views", o.views,
                 "with --analysis: the views of the shard, e.g. 0-2,5 (inclusive ranges, "
                 "ascending, 0-based manifest order)")
      ->group(kShardGroup);
  app.add_option("--frame-range", o.frame_range,
                 "with --analysis: the shard's frames FIRST-LAST (inclusive), whole segments of "
                 "the analysis's --segment-frames (default: every frame)")
      ->group(kShardGroup);
}

int run_analysis(const CommonOptions& common, const std::filesystem::path& dir,
                 const encoder::LightfieldEncodeOptions& encode) {
  const auto t0 = std::chrono::steady_clock::now();
  auto a = encoder::write_lightfield_analysis(dir, common.output, encode);
  if (!a.ok()) return fail(a.status());
  if (!common.quiet) {
    std::fprintf(stderr, "calf-encode: analysis %s of %u views in %.2f s, peak RSS %.1f MiB\n",
                 a->id.c_str(), a->analysis.header.view_count,
                 std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(),
                 peak_rss_mib());
  }
  return 0;
}

int run_shard(const CommonOptions& common, const std::filesystem::path& dir,
              const ShardOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  auto a = encoder::read_lightfield_analysis(options.analysis);
  if (!a.ok()) return fail(a.status());
  auto views = capture::parse_index_list(options.views, a->analysis.header.view_count, "views");
  if (!views.ok()) return print_error("calf-encode", views.status(), kExitUsage);
  uint32_t first = 0, count = a->analysis.header.frame_count;
  if (!options.frame_range.empty()) {
    auto f = capture::parse_index_list(options.frame_range, count, "frames");
    if (!f.ok() || f->back() - f->front() + 1 != f->size()) {
      return print_error(
          "calf-encode",
          f.ok() ? Status(ErrorId::kShardRange,
                          "--frame-range '" + options.frame_range + "' is not one range")
                 : f.status(),
          kExitUsage);
    }
    first = f->front();
    count = static_cast<uint32_t>(f->size());
  }
  auto s = encoder::encode_lightfield_shard(dir, *a, *views, first, count, common.threads,
                                            common.output, common.max_image_pixels);
  if (!s.ok()) return fail(s.status());
  if (!common.quiet) {
    std::fprintf(stderr,
                 "calf-encode: shard %s (views %s, %llu colour keyframes, %llu bytes stored) in "
                 "%.2f s, peak RSS %.1f MiB\n",
                 common.output.c_str(), capture::index_list_text(*views).c_str(),
                 static_cast<unsigned long long>(s->colour_keyframes),
                 static_cast<unsigned long long>(s->colour.stored + s->depth.stored +
                                                 s->material.stored + s->coverage.stored),
                 std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(),
                 peak_rss_mib());
  }
  return 0;
}

}  // namespace calf::tools
