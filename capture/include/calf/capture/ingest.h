// Ingest: other renderers' captures converted into calf capture sets (format/CAPTURE.md, "Ingest").
//
// Two inputs are read:
//  - Seurat capture manifests (googlevr/seurat's JSON, written by its Maya, Unity and Unreal
//    capture tools): `view_groups` of `views`, each a projective camera (row-major 4x4
//    `clip_from_eye_matrix` and `world_from_eye_matrix`, OpenGL eye space looking down -Z, image
//    row 0 at the top) with a colour and a depth image (EXR or PNG, channels chosen by name). A
//    view group is one viewpoint; it becomes one calf viewpoint whose cube faces are resampled
//    from the group's views. Depth (WINDOW_Z, EYE_Z or RAY_DEPTH) becomes calf's radial depth.
//  - Equirectangular colour + radial depth per viewpoint and frame (a calf-style manifest with
//    `"format": "calf-equirect-set"`), resampled into cube faces.
// Both write a capture set with CaptureSetWriter: every file whole, manifest.json last.
//
// Sampling: every calf texel takes the ray through its centre (calf/format/cube.h). Colour is
// filtered (bilinear in a Seurat view; in an equirectangular image sharpened, then Catmull-Rom
// by default, and supersampled per texel), depth is the nearest source pixel's (equirectangular:
// optionally edge-aware), so no depth is ever invented between a foreground and a background. Where
// a Seurat view's pixel centre falls on calf's texel centre (within 1e-3 of a pixel: a group that
// is an exact cube map of the same size, whatever its face order or orientation, even with matrices
// rounded to float), the sample is that pixel's, bit for bit: the conversion is then a permutation
// of pixels.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "calf/capture/image_budget.h"
#include "calf/format/geometry.h"
#include "calf/format/status.h"

namespace calf::capture {

// How a Seurat depth value is read (Seurat's ProjectiveCamera::DepthType).
enum class SeuratDepthType : uint8_t {
  kWindowZ,   // window-space z in [0, 1] (the GL depth buffer); 1 = far plane = no surface
  kEyeZ,      // -z in eye space, >= near; 0 and +inf = no surface
  kRayDepth,  // distance from the eye along the pixel's ray; 0 and +inf = no surface
};

// An image and the names of the channels read from it. A name is an image channel ("R", "Z",
// "depth.Z") or one of CONSTANT_ZERO / CONSTANT_ONE.
struct SeuratImageFile {
  std::string path;  // relative to the manifest's directory (no "..", not absolute)
  std::vector<std::string> channels;
};

struct SeuratView {
  uint32_t image_width = 0, image_height = 0;
  std::array<double, 16> clip_from_eye{};   // row-major: element 4 * row + column
  std::array<double, 16> world_from_eye{};  // row-major
  SeuratDepthType depth_type = SeuratDepthType::kEyeZ;
  SeuratImageFile color;  // 4 channels: R, G, B, alpha (alpha 0 = no sample: sky)
  SeuratImageFile depth;  // 1 channel
};

struct SeuratCapture {
  std::optional<Vec3> headbox_center;
  std::vector<std::vector<SeuratView>> view_groups;
};

// Parses and checks a Seurat manifest (field types, matrices affine / perspective, depth type,
// channel names, image paths). Errors: E130 syntax, E143 fields; `source` prefixes messages.
Expected<SeuratCapture> parse_seurat_manifest(std::string_view json, std::string_view source);

// How an equirectangular colour sample between pixel centres is read (after the sharpening of
// IngestOptions::equirect_sharpen). Either way a sample below zero (the kernel's or the
// sharpening's lobes next to an HDR edge) is clamped to zero.
enum class EquirectFilter : uint8_t {
  kBilinear,    // the 2 x 2 nearest pixels (a tent: softer)
  kCatmullRom,  // Catmull-Rom bicubic over the 4 x 4 nearest pixels
};

// How an equirectangular texel's depth is read.
enum class EquirectDepth : uint8_t {
  kNearest,  // the nearest pixel's: no depth is ever invented between a foreground and background
  // Bilinear between the 2 x 2 nearest pixels where their depths agree within 2 % (one surface),
  // else the nearest pixel's: smooth surfaces lose the half-pixel position error of kNearest.
  kEdgeAware,
};

struct IngestOptions {
  // Texels per cube face side; 0 chooses it from the input: Seurat, the largest pixel density at
  // any view's centre (an exact cube map keeps its size); equirectangular, round(width / pi),
  // the equirectangular image's density at the equator (pixels per radian) at each face centre.
  // Either way the six faces (6 x face_size^2 pixels) must fit `max_image_pixels` (E012).
  uint32_t face_size = 0;
  // The image budget (image_budget.h): the most pixels of one input image, checked from its
  // header before it is decoded, and of one viewpoint's six faces.
  uint64_t max_image_pixels = kDefaultMaxImagePixels;
  // Seurat: the side of the view volume (the headbox), centred on `headbox_center` (else on the
  // box of the view groups). 0: the box of the view-group positions, which must not be a point.
  double headbox_size = 0;
  // Seurat: frames per second written to the manifest (a Seurat capture is one frame).
  double fps = 30;
  // Equirectangular: colour samples per texel side (k x k samples of the filter below), 1..8.
  uint32_t supersample = 2;
  // Equirectangular: how a colour sample reads the image (EquirectFilter).
  EquirectFilter equirect_filter = EquirectFilter::kCatmullRom;
  // Equirectangular: each pixel is first sharpened by [-a, 1 + 2a, -a] along each axis, 0..0.25.
  // An anti-aliased renderer's pixel is a box average; resampling it into cube texels blurs by that
  // box once more, which a = 1/24 undoes to second order. The default 1/8 is measured: the
  // interior scene at faces of 16 and 64 played closest to its native capture there (CAPTURE.md
  // "Ingest").
  double equirect_sharpen = 0.125;
  // Equirectangular: how a texel's depth is read (EquirectDepth).
  EquirectDepth equirect_depth = EquirectDepth::kNearest;
};

// What a conversion did, for the command's summary line.
struct IngestReport {
  uint32_t viewpoints = 0, frames = 0, face_size = 0;
  uint32_t exact_groups = 0;  // Seurat: groups whose every texel was an exact pixel copy
};

// The manifests of a sequence, one per frame (or, equirectangular, one per run of frames):
// `pattern` holds one printf-style frame number, `%d` or `%0Nd` (N in 1..9; no other `%`), replaced
// by first, first + 1, ...: `count` of them, or with count 0 every one that exists up to the first
// missing number (at least one must exist, else E002 naming it). A pattern without `%` is the one
// manifest it names. Errors: E001 a malformed pattern, a count over 1 000 000 frames; E002.
Expected<std::vector<std::filesystem::path>> frame_manifests(std::string_view pattern,
                                                             uint32_t first, uint32_t count);

// Converts the Seurat manifest at `manifest_path` into a capture set in `out_dir`.
// Errors: E130/E143 manifest, E144 headbox, E145 group, E146 channel, E147 sizes (an image's
// header against its camera, before it is decoded), E148 depth, E135/E136 images, E012 budget,
// E137/E138 converted pixels, E004 writing.
Status ingest_seurat(const std::filesystem::path& manifest_path,
                     const std::filesystem::path& out_dir, const IngestOptions& options,
                     IngestReport* report = nullptr);

// A sequence: manifest k is frame k of one animated capture set (a Seurat capture is one frame).
// Every frame must be the same rig: as many view groups, each of as many views of the same image
// sizes at the same centre (within 10^-5 relative) as frame 0's (E145 for the groups and centres,
// E147 for the sizes, naming both manifests). The view volume and the face size are frame 0's.
// The report's exact_groups counts groups copied exactly in every frame.
Status ingest_seurat(const std::vector<std::filesystem::path>& manifests,
                     const std::filesystem::path& out_dir, const IngestOptions& options,
                     IngestReport* report = nullptr);

// Converts the equirectangular set at `manifest_path` into a capture set in `out_dir`. The
// manifest follows CAPTURE.md's manifest rules with `"format": "calf-equirect-set"` and without
// `face_size` and `material`; each image is an OpenEXR of W x W/2 with R, G, B and Z (radial
// depth, +inf sky). Pixel (i, j) looks along longitude phi = 2 pi (i + 0.5) / W - pi and latitude
// theta = pi / 2 - pi (j + 0.5) / H: direction (cos theta sin phi, sin theta, -cos theta cos phi),
// so the image centre looks down -Z with +Y up and +X on the right (upright, unmirrored).
// Errors: E130-E134 and E149 manifest, E135/E136/E149 images, E012 budget, E137/E138 pixels,
// E004 writing.
Status ingest_equirect(const std::filesystem::path& manifest_path,
                       const std::filesystem::path& out_dir, const IngestOptions& options,
                       IngestReport* report = nullptr);
// A sequence: the frames of every manifest in turn, one animated capture set. Every manifest must
// have frame 0's viewpoints (names and positions), view volume and fps, and every image the first
// image's size (E149 naming both manifests, or the image).
Status ingest_equirect(const std::vector<std::filesystem::path>& manifests,
                       const std::filesystem::path& out_dir, const IngestOptions& options,
                       IngestReport* report = nullptr);

// The direction of equirectangular position (u, v) in pixel units of a W x H image (pixel
// centres at half-integers), and back; the one place the layout above is written in code.
Vec3 direction_from_equirect(double u, double v, uint32_t width, uint32_t height);
void equirect_from_direction(const Vec3& d, uint32_t width, uint32_t height, double* u, double* v);

}  // namespace calf::capture
