// The surfel builder; what it does is in surfels_build.h.
#include "calf/encoder/surfels_build.h"

#include <chrono>
#include <cmath>
#include <string>
#include <vector>

#include "calf/format/colour.h"

namespace calf::encoder {

Expected<SurfelsTrackInput> build_surfels(const capture::SceneFile& scene,
                                          const capture::SurfelCandidateReader& candidates,
                                          const SurfelBuildOptions& options,
                                          SurfelBuildStats* stats) {
  if (options.max_surfels == 0) {
    return Status(ErrorId::kEncoderOption, "surfels per prototype must be >= 1");
  }
  CALF_RETURN_IF_ERROR(
      capture::check_surfel_candidates_match(candidates.entries(), scene, "the surfel candidates"));
  SurfelBuildStats s;
  SurfelsTrackInput input;
  input.mesh_track = 0;
  input.frame_count = std::max<uint32_t>(1, scene.frame_count);
  mesh_fps_fraction(scene.fps, &input.fps_numerator, &input.fps_denominator);
  // The mesh track's prototypes: the scene meshes some object places, in mesh order.
  std::vector<bool> used(scene.meshes.size(), false);
  for (const capture::SceneObject& o : scene.objects) used[o.mesh] = true;
  const auto t0 = std::chrono::steady_clock::now();
  for (uint32_t m = 0; m < scene.meshes.size(); ++m) {
    if (!used[m]) continue;
    SurfelPrototypeInput& out = input.prototypes.emplace_back();
    CALF_ASSIGN_OR_RETURN(const capture::SurfelCandidates c, candidates.read(m));
    const size_t count = c.positions.size() / 3;
    s.candidates += count;
    if (count == 0 || c.colour_sets.empty()) continue;  // drawn from the mesh
    std::vector<Vec3> points(count);
    for (size_t i = 0; i < count; ++i) {
      points[i] = {c.positions[3 * i], c.positions[3 * i + 1], c.positions[3 * i + 2]};
    }
    const uint32_t n = static_cast<uint32_t>(std::min<size_t>(options.max_surfels, count));
    CALF_ASSIGN_OR_RETURN(const SurfelOrder order, order_surfels(points, n, options.sampler));
    const capture::SurfelColourSet& set = c.colour_sets.front();
    out.colour_is_base = c.colour_sets.size() == 1;
    const auto& base = scene.materials[set.material].base_color;
    for (uint32_t i : order.order) {
      for (int k = 0; k < 3; ++k) {
        out.positions.push_back(c.positions[3 * size_t{i} + k]);
        out.normals.push_back(c.normals[3 * size_t{i} + k]);
        double colour = linear_from_srgb8(set.colours[3 * size_t{i} + k]);
        // Relative to the material's base colour, which each object's material multiplies back.
        if (!out.colour_is_base) colour = base[k] > 0 ? std::min(1.0, colour / base[k]) : 0.0;
        out.colours.push_back(static_cast<float>(colour));
      }
    }
    out.prefix_count = order.p_m;
    out.prefix_radius = order.r_m;
    if (!(out.prefix_radius > 0)) {
      // Coincident candidates (a speck of a mesh): any disc covers them; a radius of a millionth
      // of the box keeps Eq. 1 finite.
      const double dx = c.box_max[0] - c.box_min[0], dy = c.box_max[1] - c.box_min[1],
                   dz = c.box_max[2] - c.box_min[2];
      out.prefix_radius =
          static_cast<float>(std::max(1e-30, 1e-6 * std::sqrt(dx * dx + dy * dy + dz * dz)));
    }
    ++s.prototypes_with_surfels;
    s.surfels += n;
  }
  s.prototypes = static_cast<uint32_t>(input.prototypes.size());
  s.sample_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (stats) *stats = s;
  return input;
}

Expected<SurfelBuildStats> encode_surfel_file(const std::filesystem::path& scene_dir,
                                              const std::string& candidates_path,
                                              const std::string& out_path,
                                              const SurfelBuildOptions& options,
                                              const MeshEncodeOptions& mesh_options,
                                              const SurfelsEncodeOptions& surfels_options,
                                              SurfelsEncodeStats* surfels_stats) {
  CALF_ASSIGN_OR_RETURN(const capture::SceneFile scene,
                        capture::read_scene_file(scene_dir, mesh_options.max_image_pixels));
  CALF_ASSIGN_OR_RETURN(const capture::SurfelCandidateReader candidates,
                        capture::SurfelCandidateReader::open(candidates_path));
  SurfelBuildStats stats;
  CALF_ASSIGN_OR_RETURN(const SurfelsTrackInput input,
                        build_surfels(scene, candidates, options, &stats));
  const auto add_surfels = [&](container::Writer* writer) {
    return encode_surfels_track(input, surfels_options, writer, surfels_stats);
  };
  CALF_RETURN_IF_ERROR(
      encode_mesh_file(scene, scene_dir, out_path, nullptr, mesh_options,
                       {{"surfels", "candidates " + std::to_string(stats.candidates) + " surfels " +
                                        std::to_string(stats.surfels) + " sampler " +
                                        surfel_order_method_name(options.sampler.method)}},
                       {candidates_path}, add_surfels)
          .status());
  return stats;
}

}  // namespace calf::encoder
