// The surfel builder (paper 001 Sec. 3): a scene file and its surfel candidates
// (format/SURFEL_CANDIDATES.md, written by calf-capture --surfel-candidates) in, the ordered
// surfel buffers of a surfels track out. Per prototype of the mesh track (a scene mesh some object
// places, in mesh order — encode_mesh_track's numbering): up to `max_surfels` of the mesh's
// candidates ordered by the sampler (surfel_sampler.h: every prefix a level of detail), with its
// r_m / p_m. Colours: with one colour set (one material places the mesh) the candidates' colours
// are the surface's base colour (kColourIsBase); with several, the first set divided by its
// material's base colour, which the player multiplies back per object (its material).
//
// encode_surfel_file writes one clip: the mesh track (track 0, every triangle) and the surfels
// track paired with it (track 1), whole or not at all. Deterministic for any thread count.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>

#include "calf/capture/scene_file.h"
#include "calf/capture/surfel_candidates.h"
#include "calf/encoder/mesh_encode.h"
#include "calf/encoder/surfel_sampler.h"
#include "calf/encoder/surfels_encode.h"
#include "calf/format/status.h"

namespace calf::encoder {

struct SurfelBuildOptions {
  // The most surfels kept per prototype (fewer when it has fewer candidates), >= 1.
  uint32_t max_surfels = 65536;
  SurfelSamplerOptions sampler;
};

struct SurfelBuildStats {
  uint32_t prototypes = 0, prototypes_with_surfels = 0;
  uint64_t candidates = 0, surfels = 0;
  double sample_seconds = 0;  // wall time in the sampler (informative)
};

// The surfels track input for `scene` from `candidates` (which must match it: CALF-E189 from
// check_surfel_candidates_match otherwise). Errors: the reader's (E180 - E189), the sampler's
// (E240 - E243), kEncoderOption for max_surfels = 0.
Expected<SurfelsTrackInput> build_surfels(const capture::SceneFile& scene,
                                          const capture::SurfelCandidateReader& candidates,
                                          const SurfelBuildOptions& options,
                                          SurfelBuildStats* stats = nullptr);

// Reads the scene folder and the candidate file and writes the clip (mesh track + surfels track)
// to `out_path` through encode_mesh_file (its metadata and output checks; the candidate file is
// an input too).
Expected<SurfelBuildStats> encode_surfel_file(const std::filesystem::path& scene_dir,
                                              const std::string& candidates_path,
                                              const std::string& out_path,
                                              const SurfelBuildOptions& options,
                                              const MeshEncodeOptions& mesh_options,
                                              const SurfelsEncodeOptions& surfels_options,
                                              SurfelsEncodeStats* surfels_stats = nullptr);

}  // namespace calf::encoder
