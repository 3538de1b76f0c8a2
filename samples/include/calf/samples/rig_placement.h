// Camera placement (paper 002 Sec. 4, Alg. 1): `--rig auto:...` chooses capture viewpoints inside
// a view volume greedily by coverage gain, and `--rig hammersley:N` places N viewpoints in the
// same volume at the points of a 3D Hammersley set (the Seurat-style placement it is compared
// with). docs/CAMERA_PLACEMENT.md gives the model, the defaults and measured figures.
//
// The coverage model (Eqs. 2-7). The surfaces S are sampled uniformly by area (surface_points.h):
// `samples` points spread over `frames` frames of the scene (Eq. 7: the integral over time is a
// mean over those frames). For a viewpoint O and a surface point x,
//   I_suit(O, x) = V(O, x) exp(-k max(|x - O| - Z(x), 0))                              (Eq. 2)
// with V the visibility (an occlusion ray from O stopping just short of x) and Z(x) the distance
// from x to the view volume (the paper's minimum viewer distance: no viewer gets closer), or,
// where the rig keeps viewers out of a ball around an object (Rig::keep_out_radius), the larger
// of that and x's distance to the ball's surface; k is per Scene::length_scale (1 for the
// built-in scenes; a model file's bounding radius, so that its file's unit does not matter). The
// gain of adding O to the chosen set C is
//   f(O, C) = integral over S of max(I_suit(O, x) - max_{i in C'} I_suit(C_i, x), 0)  (Eqs. 3-4)
// where C' is every chosen camera in the diffuse variant, and in the specular variant (Eq. 6)
// only the chosen cameras whose direction seen from x is within theta of O's: a camera at a
// larger angle sees x from another direction and leaves O's view of it uncovered. Eq. 7 as
// printed multiplies the integrand by I_suit once more; calf does not, so that one frame of the
// dynamic objective is exactly the static one. Alg. 1 adds the best candidate (Eq. 5 over a grid
// of about `candidates` points spanning the volume, ties to the lowest index) while its gain is at
// least `stop` times the reference R = integral over S of max over all evaluated points of
// I_suit (what the best viewpoint could give each point): the paper's "y > 0" never stops in
// practice, since a new camera nearer some point always gains a little. Coverage after n cameras
// is the sum of their gains over R: in the diffuse variant that is integral of max_i I_suit / R,
// at most 1; in the specular variant a point seen from several directions counts once per
// direction, so it may exceed 1.
//
// Candidates inside geometry at any of the capture's frames (FrameTracer::inside_geometry) or
// inside the keep-out ball are never chosen, and Hammersley points there are skipped (the set
// grows, up to 2N, until N are outside). Deterministic: every candidate's gain is a sum in a fixed
// order, whatever `threads`.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "calf/format/geometry.h"
#include "calf/format/status.h"
#include "calf/samples/scene.h"

namespace calf::samples {

struct PlacementOptions {
  enum class Kind { kAuto, kHammersley };
  Kind kind = Kind::kAuto;
  uint32_t max_cameras = 16;  // auto: the most cameras, 1..256; hammersley: N
  uint32_t candidates = 512;  // about this many grid points span the volume, 1..65536
  uint32_t samples = 16384;   // surface points over all frames, 16..4194304
  uint32_t frames = 1;        // frames of Eq. 7 (evenly spread over the capture), 1..256
  double k = 1;               // proximity decay per Scene::length_scale, >= 0 (0: visibility)
  double stop = 0.01;         // stop when a gain is below stop x R, [0, 1]; 0: only at gain 0
  bool specular = false;      // Eq. 6
  double theta_degrees = 50;  // the specular variant's minimum view angle, (0, 180]
  bool has_volume = false;    // false: the scene's default rig's view volume
  Box3 volume;
  uint64_t seed = 1;     // surface sample positions
  uint32_t threads = 0;  // 0: all hardware threads
  std::string text;      // the --rig text
};

// Whether a --rig text asks for placement ("auto", "auto:...", "hammersley:...").
bool is_placement_rig(std::string_view text);
// Parses "auto[:KEY=VALUE]..." or "hammersley:N[:KEY=VALUE]..." (kPlacementSyntaxHelp). Errors:
// E195, one line naming the item.
Expected<PlacementOptions> parse_placement(std::string_view text);
extern const char* const kPlacementSyntaxHelp;

// One row of the coverage-versus-count curve: n cameras.
struct CoverageRow {
  uint32_t cameras = 0;
  Vec3 position;          // Alg. 1's n-th camera
  double gain = 0;        // its gain over R
  double coverage = 0;    // Alg. 1's first n cameras
  double hammersley = 0;  // a Hammersley set of n points in the same volume
  double hand_made = -1;  // the scene's default rig's first n viewpoints; -1 beyond its size
};

struct PlacementResult {
  Rig rig;                         // the rig asked for (Alg. 1's or Hammersley's)
  std::vector<CoverageRow> curve;  // Alg. 1 until it stopped (n = 1..)
  std::string stop_reason;         // why Alg. 1 stopped
  double hammersley_coverage = 0;  // coverage of a Hammersley rig (kHammersley: the one returned)
  double hand_made_coverage = 0;   // the scene's default rig's, all of it
  uint32_t hand_made_count = 0;
  uint32_t candidates = 0;  // grid points outside geometry and the rig's keep-out ball
  double length_scale = 1;  // the scene's: k was applied per this many scene units
  uint32_t surface_samples = 0;
  uint64_t rays = 0;
  double seconds = 0;
};

// Runs the placement on `capture_frames` frames of `scene` (inside-geometry checks use all of
// them; Eq. 7 uses `options.frames` of them). Errors: E196 when no grid point or not enough
// Hammersley points lie outside geometry, or no evaluated point sees any surface; E174 / E178
// from the tracer.
Expected<PlacementResult> place_cameras(const Scene& scene, const PlacementOptions& options,
                                        uint32_t capture_frames);

// The curve as a tab-separated table (a header line, then one row per count) and as an SVG plot.
std::string placement_table(const PlacementResult& result);
std::string placement_svg(const PlacementResult& result, std::string_view title);

// Point i of the n-point 3D Hammersley set (i / n, radical inverse base 2, base 3 of i) mapped
// into `volume` (an axis of zero extent stays at its value).
Vec3 hammersley_point(uint32_t i, uint32_t n, const Box3& volume);

}  // namespace calf::samples
