// The calf-capture ray tracer (Embree 3) and the drivers that render capture sets and ground truth.
//
// Shading, per primary ray (paper 002's challenges: shading that changes where depth does not,
// mirrors and glass):
//   - diffuse reflectance = material albedo x base-colour texture, the texture filtered
//     trilinearly at the hit's UV with a mip level from the ray cone's footprint (texture.h; the
//     cone starts with the pixel's angular width and widens over mirror / glass bounces);
//   - direct light from point lights and the sun, with shadow rays;
//   - ambient occlusion: `ao_samples` cosine-distributed rays per diffuse hit, each lit by the
//     scene's ambient radiance when it travels ao_distance unobstructed;
//   - mirror and glass by recursion up to `max_bounces` (total internal reflection reflects);
//   - optional multiplicative noise, uniform in [-noise, +noise], that mimics a path tracer's
//     per-frame noise.
// Anti-aliasing and convergence (docs/RENDERING.md "Converged capture"): a pixel's colour is the
// mean over its square (a texel's square in face coordinates, a perspective pixel's in the image
// plane: a box filter) of up to `spp` samples at stratified positions, taken in rounds that
// double the count, from min(min_spp, spp) on, until the standard error of the mean, estimated
// from the samples' sRGB-encoded values, is at most `tolerance` in every channel. Positions and AO
// directions are points of a per-pixel scrambled (0, 2)-sequence (calf/samples/pixel_samples.h):
// every round's samples, and the AO rays of all of a pixel's samples at a surface together, are
// stratified. spp = 1 is one sample through the texel centre with a fixed AO pattern, bit for bit
// the colours tests/samples/antialias_legacy_colours.inc holds.
// Depth is the radial distance of the primary hit of the ray through the pixel centre from the
// ray origin (the viewpoint centre), whatever `spp`: the player re-projects each texel along its
// centre direction at its depth, so the depth must be the surface on that very ray (a mean of
// depths across an edge would be a point in mid-air, the nearest sample's would move slanted
// surfaces towards the viewer and grow silhouettes by half a texel beyond what the player's own
// depth footprint already allows). For mirror and glass it is the depth of the mirror or glass
// surface; material channels are the centre ray's surface's (reflect, refract, ior), (0, 0, 1)
// where nothing reflective is hit or on sky.
//
// Determinism: every pixel is a pure function of (scene, time, viewpoint, texel, seed): its random
// numbers come from a counter-based hash of (seed, view, face, x, y) and the sample's index, AO
// patterns are the same every frame (static surfaces stay bit-identical) and only the noise option
// also hashes the frame. Threads share no mutable state, so output bytes do not depend on the
// thread count. They can depend on the host, in the last bits of some hits: Embree picks its
// kernels for the CPU it runs on (SSE4.2, AVX2 or AVX-512), and their float arithmetic differs
// (measured: the same build forced to SSE4.2 on an AVX2 host changes every file of a 128² interior
// set; two calf-bench runs of the same code on two hosts gave clips within 0.13 % in bytes and
// 0.013 dB).
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "calf/capture/capture_set.h"
#include "calf/capture/eye_path.h"
#include "calf/format/status.h"
#include "calf/samples/scene.h"

namespace calf::samples {

struct LightfieldRenderOptions {
  uint32_t threads = 0;      // 0: all hardware threads; 1..256 otherwise
  uint64_t seed = 1;         // seeds AO directions and noise
  uint32_t ao_samples = 4;   // per diffuse hit of each sample, 0..256; 0: no ambient occlusion
  uint32_t max_bounces = 6;  // mirror / glass recursion depth, 0..32
  float noise = 0;           // per-frame colour noise amplitude in [0, 1]
  // Anti-aliasing and convergence (above; defaults measured in docs/RENDERING.md).
  uint32_t spp = 64;         // most samples per pixel, 1..4096; 1: the texel-centre ray alone
  uint32_t min_spp = 8;      // samples of the first round, 1..4096 (at most spp are taken)
  float tolerance = 0.004f;  // target standard error of a pixel's sRGB-encoded mean, [0, 1];
                             // 0: always spp samples
};
// E177 when an option is outside its range.
Status validate_render_options(const LightfieldRenderOptions& options);

inline constexpr uint32_t kCoverageCells = 4;  // cells per texel side

// Rays traced (primary, shadow, AO, secondary) and wall time, for Mrays/s.
struct RenderStats {
  uint64_t rays = 0;
  uint64_t images = 0;   // view-frames or poses rendered
  uint64_t pixels = 0;   // pixels (texels) shaded
  uint64_t samples = 0;  // colour samples taken over them (samples / pixels: the mean spp)
  double seconds = 0;
  double mrays_per_second() const { return seconds > 0 ? rays / seconds * 1e-6 : 0; }
};

// A scene frozen at one time and built into an Embree BVH, ready to trace from any thread.
class FrameTracer {
 public:
  // Builds the scene at `time` seconds: vertex states at that time, every shared mesh once as an
  // Embree scene of its own, instanced by the objects that place it. E174 for non-finite
  // transformed geometry, E178 when Embree fails.
  static Expected<std::unique_ptr<FrameTracer>> create(const Scene& scene, double time,
                                                       const LightfieldRenderOptions& options);
  ~FrameTracer();
  FrameTracer(const FrameTracer&) = delete;
  FrameTracer& operator=(const FrameTracer&) = delete;

  // Renders the cube map centred at `center` into `out` (resized to `face_size`, with material
  // channels when `with_material`). `view` and `frame` only seed random numbers. Each texel's
  // centre ray (depth, material; the colour when spp is 1) is calf::direction_from_texel(face, x,
  // y, face_size); colour samples lie in its square, calf::direction_from_texel_coord.
  // `with_coverage`: also the coverage channels (format/CAPTURE.md "Coverage") from the first
  // hits of cell rays: a cell shows the texel's surface when its first hit is within a
  // relative depth of capture::coverage_tolerance(face_size) of the centre ray's (both sky, or both
  // not), else nearer or farther. Coverage takes 16 intersection rays per texel, at the centres of
  // a 4 x 4 grid of cells over the texel's square.
  RenderStats render_cube(const Vec3& center, uint32_t view, uint32_t frame, uint32_t face_size,
                          bool with_material, capture::ViewFrame* out,
                          bool with_coverage = false) const;

  // Renders one perspective ground-truth image (the camera convention of eye_path.h).
  RenderStats render_perspective(const capture::EyePose& pose, uint32_t width, uint32_t height,
                                 uint32_t pose_index, capture::PerspectiveImage* out) const;

  // Whether `point` is inside closed geometry: along most of 26 probe rays (axes, edge and corner
  // directions) the point's winding number (back-face minus front-face crossings) is positive, or
  // a surface lies closer than 1e-4 scene units. Needs consistently wound closed meshes.
  bool inside_geometry(const Vec3& point) const;

  // Whether nothing lies between `from` and `to`: one occlusion ray from `from` that stops
  // 1e-4 x (1 + distance) short of `to`, so that a point sampled on a surface does not hide
  // itself (camera placement's visibility, rig_placement.h).
  bool segment_clear(const Vec3& from, const Vec3& to) const;

 private:
  struct Impl;
  explicit FrameTracer(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

// A capture to render: faces of `face_size` texels, `frames` frames (0: the scene's default) of
// the scene from every viewpoint of `rig`.
struct CaptureRequest {
  uint32_t face_size = 256;  // 1..4096
  bool coverage = false;     // write the coverage channels (manifest version 2)
  uint32_t frames = 0;       // 0: scene.frame_count; else 1..100000
  Rig rig;
  LightfieldRenderOptions render;
  std::string generator = "calf-capture";  // recorded in the manifest
  // A capture shard (calf/capture/capture_shard.h, docs/FARM.md): only these views (ascending;
  // empty = every view) x frames [first_frame, last_frame] (last_frame 0 with first_frame 0 =
  // every frame). A shard writes its images and a shard marker, never manifest.json.
  std::vector<uint32_t> views;
  uint32_t first_frame = 0, last_frame = 0;
  bool shard = false;
};

// Called after each view-frame or pose with (done, total); used for progress lines.
using ProgressFn = std::function<void(uint64_t done, uint64_t total)>;

// Fails with E176 when a viewpoint is inside geometry at any frame (checked before anything is
// rendered), naming the viewpoint, its position and the frame.
Status check_viewpoints(const Scene& scene, const Rig& rig, uint32_t frames, double fps,
                        const LightfieldRenderOptions& options);

// Renders a complete capture set into `directory` (format/CAPTURE.md): checks options, scene and
// viewpoints first, writes each view-frame as it is done and manifest.json last; on failure
// removes the images it wrote, so no partial set remains that looks complete. Material channels
// are written when the scene has mirror or glass.
Expected<RenderStats> render_capture_set(const Scene& scene, const CaptureRequest& request,
                                         const std::filesystem::path& directory,
                                         const ProgressFn& progress);

// Renders ground truth along `path` into `directory`: one EXR per pose named by the path's image
// pattern (kDefaultImagePattern when empty), then eye_path.json (with that pattern) last. Poses
// must not be inside geometry (E176).
Expected<RenderStats> render_ground_truth(const Scene& scene, const capture::EyePath& path,
                                          const LightfieldRenderOptions& options,
                                          const std::filesystem::path& directory,
                                          const ProgressFn& progress);

}  // namespace calf::samples
