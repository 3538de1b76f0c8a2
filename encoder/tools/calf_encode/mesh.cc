#include "calf_encode/mesh.h"

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "calf/capture/scene_file.h"
#include "calf/encoder/mesh_encode.h"

namespace calf::tools {

namespace {

inline constexpr EnumTable<encoder::VisibilityMotion, 2> kVisibilityMotions = {
    {{"per-frame", encoder::VisibilityMotion::kPerFrame},
     {"coupled", encoder::VisibilityMotion::kCoupled}}};

// Computes the visible set of `scene` from its view region's perimeter (calf/encoder/
// visible_set.h), showing what it solves on a terminal; `summary` receives the summary line (the
// caller prints it once the clip is written, so that an error stays the only line). The set's
// errors (E110-E115) pass through.
Expected<encoder::VisibleSet> visible_set_of(const capture::SceneFile& scene,
                                             const MeshOptions& mesh,
                                             const encoder::VisibleSetOptions& options, bool quiet,
                                             uint32_t* segment_count, std::string* summary) {
  const Box3& region = scene.view_volume;
  const double eye_height = mesh.eye_height.value_or(0.5 * (region.min.y + region.max.y));
  const auto segments = encoder::perimeter_segments(region, eye_height, mesh.segments_per_edge);
  double perimeter = 0;
  for (const auto& g : segments) {
    const double dx = g.b.x - g.a.x, dy = g.b.y - g.a.y, dz = g.b.z - g.a.z;
    perimeter += std::sqrt(dx * dx + dy * dy + dz * dz);
  }
  *segment_count = static_cast<uint32_t>(segments.size());
  // The builder reports no progress: on a terminal, say what is being solved until it returns
  // (erased then, so an error stays the one line calf-encode prints).
  const bool tty = !quiet && isatty(2) != 0;
  if (tty) {
    std::fprintf(
        stderr, "calf-encode: visible set: solving %zu segments x 6 faces of %u px x %u frames ...",
        segments.size(), options.face_size, scene.frame_count);
    std::fflush(stderr);
  }
  auto set = encoder::compute_visible_set(scene, segments, options);
  if (tty) std::fprintf(stderr, "\r\033[K");
  if (!set.ok()) return set;
  if (!quiet) {
    const bool coupled = options.motion == encoder::VisibilityMotion::kCoupled;
    const auto& st = set->stats;
    char line[1024];
    std::snprintf(
        line, sizeof line,
        "calf-encode: visible set: %zu segments (%.3f of perimeter at eye height %.3f), 6 faces "
        "of %u px, %s granularity%s: %llu of %llu triangles (%.3f %%) in %.2f s; %llu of %u %s "
        "solved, %llu (triangle, pixel) pairs, %.3g pairs/s\n",
        segments.size(), perimeter, eye_height, options.face_size,
        options.object_granularity ? "object" : "triangle", coupled ? ", coupled motion" : "",
        static_cast<unsigned long long>(st.visible_triangles),
        static_cast<unsigned long long>(st.scene_triangles),
        st.scene_triangles ? 100.0 * static_cast<double>(st.visible_triangles) /
                                 static_cast<double>(st.scene_triangles)
                           : 0.0,
        st.seconds, static_cast<unsigned long long>(st.frames_solved), scene.frame_count,
        coupled ? "frames: motion steps" : "frames",
        static_cast<unsigned long long>(st.triangle_pixel_pairs),
        st.seconds > 0 ? static_cast<double>(st.triangle_pixel_pairs) / st.seconds : 0.0);
    *summary = line;
  }
  return set;
}

}  // namespace

void add_options(CLI::App& app, MeshOptions& o) {
  auto* vs_flag =
      app.add_flag("--visible-set", o.visible_set,
                   "mesh: keep only the triangles visible from some point of the scene's view "
                   "region (paper 004 from-segment visibility on the perimeter of its rectangle "
                   "at --eye-height, every frame of the scene; docs/VISIBILITY.md); off: the "
                   "whole scene")
          ->group(kMeshGroup);
  const auto needs_vs = [&](CLI::Option* opt) { opt->needs(vs_flag)->group(kMeshGroup); };
  needs_vs(app.add_option("--eye-height", o.eye_height,
                          "with --visible-set: height (y) of the perimeter rectangle; must lie in "
                          "the scene's bounds (default: the middle of the view region's y range)"));
  needs_vs(app.add_option("--segments-per-edge", o.segments_per_edge,
                          "with --visible-set: segments each of the rectangle's 4 edges is cut "
                          "into, 1..1024")
               ->check(CLI::Range(1u, 1024u)));
  needs_vs(app.add_option("--visibility-face-size", o.visibility.face_size,
                          "with --visible-set: side in px of the 6 cube faces rasterised per "
                          "segment, 1..8192 (paper 004: 800)")
               ->check(CLI::Range(1u, encoder::kVisibleSetMaxFaceSize)));
  needs_vs(app.add_flag("--object-granularity", o.visibility.object_granularity,
                        "with --visible-set: keep an object whole as soon as one of its triangles "
                        "is visible (off: single triangles)"));
  needs_vs(add_enum_option(app, "--visibility-motion", o.visibility.motion, kVisibilityMotions,
                           "with --visible-set: per-frame: every frame is a static scene and the "
                           "eye sweeps each segment at every frame (what can be seen from some "
                           "point at some frame); coupled: paper 004 Sec. 3.2, the eye walks each "
                           "segment while the scene moves from frame f to f + 1, vertices on "
                           "straight lines (what an eye moving with the scene sees); "
                           "docs/VISIBILITY.md"));
}

int run(const CommonOptions& common, const MeshOptions& mesh) {
  encoder::MeshEncodeOptions o;
  o.threads = common.threads;
  o.levels.compress_directory = !common.plain_directory;
  o.supercompression = common.supercompression;
  const std::filesystem::path dir = input_folder(common.input, capture::kSceneManifestFileName);
  const std::string& out = common.output;
  const auto start = std::chrono::steady_clock::now();
  auto scene = capture::read_scene_file(dir, common.max_image_pixels);
  if (!scene.ok()) return fail(scene.status());
  std::optional<encoder::VisibleSet> set;
  std::string vs_summary;
  std::vector<std::pair<std::string, std::string>> metadata;
  if (mesh.visible_set) {
    // The scene the mesh track refuses is refused before the set is solved (and its line printed).
    if (Status s = encoder::check_mesh_scene(*scene); !s.ok()) return fail(s);
    encoder::VisibleSetOptions visibility = mesh.visibility;
    visibility.threads = common.threads;
    auto computed =
        visible_set_of(*scene, mesh, visibility, common.quiet, &o.segment_count, &vs_summary);
    if (!computed.ok()) return fail(computed.status());
    set = std::move(*computed);
    // How the set was made (no time: the bytes depend on the scene and the options only).
    metadata.emplace_back(
        "visible_set",
        fmt::format("segments {} face_size {} granularity {} triangles {} of {}", o.segment_count,
                    visibility.face_size, visibility.object_granularity ? "object" : "triangle",
                    set->stats.visible_triangles, set->stats.scene_triangles));
    if (visibility.motion == encoder::VisibilityMotion::kCoupled)
      metadata.back().second += " motion coupled";
  }
  auto stats =
      encoder::encode_mesh_file(*scene, dir, out, set ? &set->triangles : nullptr, o, metadata);
  if (!stats.ok()) return fail(stats.status());
  std::fputs(vs_summary.c_str(), stderr);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const uint64_t stored = stats->index.stored + stats->vertices_stream.stored +
                          stats->triangles_stream.stored + stats->visibility.stored;
  std::fprintf(stderr,
               "calf-encode: wrote %s in %.2f s (mesh: %u objects, %u prototypes, %u materials, "
               "%llu triangles of %llu, %llu vertices)\n",
               out.c_str(), seconds, stats->objects, stats->prototypes, stats->materials,
               static_cast<unsigned long long>(stats->triangles),
               static_cast<unsigned long long>(stats->scene_triangles),
               static_cast<unsigned long long>(stats->vertices));
  auto line = [](const char* name, const encoder::MeshStreamBytes& b) {
    std::fprintf(stderr, "  %-10s raw %llu  stored %llu  (%.2fx)  %llu chunks\n", name,
                 static_cast<unsigned long long>(b.raw), static_cast<unsigned long long>(b.stored),
                 b.stored ? static_cast<double>(b.raw) / static_cast<double>(b.stored) : 0.0,
                 static_cast<unsigned long long>(b.chunks));
  };
  line("index", stats->index);
  line("vertices", stats->vertices_stream);
  line("triangles", stats->triangles_stream);
  line("visibility", stats->visibility);
  std::fprintf(
      stderr, "  plain f32/u32 arrays %llu bytes, stored %llu (%.2fx)\n",
      static_cast<unsigned long long>(stats->plain_bytes), static_cast<unsigned long long>(stored),
      stored ? static_cast<double>(stats->plain_bytes) / static_cast<double>(stored) : 0.0);
  std::fprintf(stderr, "calf-encode: peak RSS %.1f MiB\n", peak_rss_mib());
  return 0;
}

}  // namespace calf::tools
