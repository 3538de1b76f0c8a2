// Capture sets: the input of the encoder (format/CAPTURE.md is the specification).
//
// A capture set is a directory holding `manifest.json` and one OpenEXR image per view-frame. Each
// image holds all six cube faces of one viewpoint at one frame as a vertical strip N texels wide
// and 6N tall, faces in OpenGL order (+X, -X, +Y, -Y, +Z, -Z; calf/format/cube.h), with channels
//   R, G, B                      linear colour, half float (HDR values kept)
//   Z                            radial depth from the viewpoint centre, float; +inf = sky
//   material.reflect/refract/ior optional (manifest "material": true), half float
//   coverage.near/far            optional (manifest version 2, "coverage": true), half float: the
//                                share of the texel's square whose first surface lies nearer /
//                                farther than the texel's depth (CAPTURE.md "Coverage")
//   coverage.mask                optional (with coverage), float holding an integer 0..65535: the
//                                4 x 4 cells of the texel that show its own surface
// The manifest is written last, so a set without one is incomplete by definition: a renderer that
// fails half-way never leaves a set that looks complete.
//
// The reader is made for streaming encoders: open() parses and validates only the manifest;
// read() decodes one view-frame into a caller-owned ViewFrame that is reused from call to call, and
// validates every pixel it returns. Errors name the file, the JSON field, or the face and texel.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "calf/capture/image_budget.h"
#include "calf/format/cube.h"
#include "calf/format/geometry.h"
#include "calf/format/status.h"

namespace calf::capture {

// Limits (CAPTURE.md "Limits"); larger sets are rejected with CALF-E134 before any allocation.
inline constexpr uint32_t kMaxFrames = 1000000;
inline constexpr uint32_t kMaxViewpoints = 4096;
// The largest face a capture set may use (the container's kMaxFaceSize, calf/format/grid.h).
inline constexpr uint32_t kMaxCaptureFaceSize = 16384;
inline constexpr uint32_t kCaptureFormatVersion = 1;
// Version 2 adds the optional coverage channels; a set without them is written as version 1.
inline constexpr uint32_t kCaptureCoverageVersion = 2;
// CAPTURE.md "Coverage": the relative depth within which a first hit counts as the texel's own
// surface, |ln(z / d)| <= min(4 / N, 0.05): two texel angles of an N-texel face (a surface at up
// to 76 degrees incidence stays within it across the texel), at most 5 %. Face size 0 counts as 1.
double coverage_tolerance(uint32_t face_size);
inline constexpr const char* kManifestFileName = "manifest.json";
inline constexpr const char* kDefaultFilePattern = "view{view:03}_frame{frame:05}.exr";

// Points are calf::Vec3 and boxes calf::Box3 (calf/format/geometry.h), in scene units.

// One 360-degree camera: a cube map centred at `position` (no orientation: faces are world-axis
// aligned). `name` is informative ("centre", "corner-+x+y-z"); unique within a set.
struct Viewpoint {
  std::string name;
  Vec3 position;
  friend bool operator==(const Viewpoint&, const Viewpoint&) = default;
};

// Everything manifest.json declares. Field names match the JSON keys (CAPTURE.md).
struct CaptureManifest {
  uint32_t version = kCaptureFormatVersion;
  uint32_t frame_count = 0;
  double fps = 30;
  uint32_t face_size = 0;
  // Where the viewer may move during playback; the encoder and player use it for culling and
  // view selection. Viewpoints usually lie inside or on it.
  Box3 view_volume;
  std::vector<Viewpoint> viewpoints;
  // The image of view v, frame f is the pattern with "{view}" / "{frame}" replaced by the decimal
  // index, "{view:0N}" zero-padded to N digits (N in 1..9). See validate rules in CAPTURE.md.
  std::string file_pattern = kDefaultFilePattern;
  // Whether every image has the three material channels.
  bool material = false;
  // Whether every image has the three coverage channels (version 2 only).
  bool coverage = false;
  // Informative: the scene and program that made the set ("" when absent).
  std::string scene;
  std::string generator;
  friend bool operator==(const CaptureManifest&, const CaptureManifest&) = default;
};

// Parses and validates manifest JSON. `source_name` (a path) prefixes every error message.
// Errors: CALF-E130 syntax, E131 field, E132 format/version, E133 inconsistency, E134 limits.
Expected<CaptureManifest> parse_manifest(std::string_view json, std::string_view source_name);
// Checks a manifest built in memory against the same rules parse_manifest applies.
Status validate_manifest(const CaptureManifest& manifest);
// Canonical JSON for a valid manifest (2-space indent, fixed key order, doubles written so that
// they parse back to the same bits): parse_manifest(serialize_manifest(m)) == m.
std::string serialize_manifest(const CaptureManifest& manifest);
// The image file name of view `view`, frame `frame` (no directory). Indices are not checked.
std::string capture_file_name(const CaptureManifest& manifest, uint32_t view, uint32_t frame);

// The pixels of one view-frame: six N x N faces, face-major then row-major, exactly the order of
// the image's vertical strip. Texel (face, x, y) is element texel_index(face, x, y) of depth and
// element 3 * texel_index(...) + c of color (c = R, G, B) and of material (c = reflect, refract,
// ior) and element 3 * texel_index(...) + c of coverage (c = near, far, mask). The caller owns
// it; the reader resizes it only when face size, material or coverage change.
struct ViewFrame {
  uint32_t face_size = 0;
  bool has_material = false;
  bool has_coverage = false;
  std::vector<float> color;     // 3 per texel, linear RGB, >= 0 and finite
  std::vector<float> depth;     // 1 per texel, radial distance > 0, or +inf for sky
  std::vector<float> material;  // 3 per texel when has_material, else empty
  // 3 per texel when has_coverage, else empty: the shares of the texel's square (a box over its
  // face coordinates) whose first surface lies nearer than `depth` and farther than it (or is
  // sky), each in [0, 1], summing to at most 1 (the rest is the surface `depth` names), and the
  // 4 x 4 cell mask of format/CAPTURE.md "Coverage" as an integer 0..65535.
  std::vector<float> coverage;

  // Sizes the buffers for faces of `face_size` texels (contents unspecified).
  void resize(uint32_t face_size, bool with_material, bool with_coverage = false);
  size_t texel_count() const { return size_t{6} * face_size * face_size; }
  size_t texel_index(CubeFace face, uint32_t x, uint32_t y) const {
    return (static_cast<size_t>(cube_face_index(face)) * face_size + y) * face_size + x;
  }
};

// Checks every pixel of a view-frame: depth classified by calf/format/log_depth.h (NaN, -inf and
// values <= 0 are errors, +inf is sky), colour finite and >= 0, material weights in [0, 1] with
// reflect + refract <= 1 and IOR finite and > 0, coverage shares in [0, 1] summing to <= 1 and an
// integer mask 0..65535 (E136). Errors (E137/E138/E139/E136) name face, x and y; `context` (a file
// name) prefixes them.
Status validate_view_frame(const ViewFrame& frame, std::string_view context);

// Reads a capture set one view-frame at a time. Movable, not copyable; no shared state, so
// several readers (one per thread) may read one set concurrently.
class CaptureSetReader {
 public:
  // Reads and validates `directory`/manifest.json. Does not touch the images (see check_files).
  // A view-frame's six faces, 6 face_size^2 pixels, must fit `max_image_pixels`
  // (calf/capture/image_budget.h), else E012 naming the manifest, before any frame is allocated.
  static Expected<CaptureSetReader> open(const std::filesystem::path& directory,
                                         uint64_t max_image_pixels = kDefaultMaxImagePixels);

  const CaptureManifest& manifest() const { return manifest_; }
  const std::filesystem::path& directory() const { return directory_; }
  std::filesystem::path image_path(uint32_t view, uint32_t frame) const;

  // Whether every image the manifest names exists (CALF-E135 names the first missing one) and is
  // a regular file (CALF-E002 for a directory or FIFO under an image's name).
  // Cheap (directory look-ups only); call it before a long encode to fail early.
  Status check_files() const;

  // Decodes view `view`, frame `frame` into `out` and validates its size, channels and pixels.
  // Colour may be stored as half or float; depth must be float or half. Errors: E140 index,
  // E135 missing, E136 format, E137-E139 pixels.
  Status read(uint32_t view, uint32_t frame, ViewFrame* out) const;

 private:
  CaptureSetReader(std::filesystem::path directory, CaptureManifest manifest)
      : directory_(std::move(directory)), manifest_(std::move(manifest)) {}
  std::filesystem::path directory_;
  CaptureManifest manifest_;
};

// Writes a capture set. Each image is written whole (temporary file, then rename); manifest.json
// is written by finish() only once every view-frame is present, so an interrupted or failed run
// leaves no set that looks complete. create() deletes a stale manifest.json in the directory for
// the same reason.
class CaptureSetWriter {
 public:
  // Validates `manifest`, creates `directory` (and parents) if needed.
  static Expected<CaptureSetWriter> create(const std::filesystem::path& directory,
                                           CaptureManifest manifest);

  const CaptureManifest& manifest() const { return manifest_; }

  // Validates and writes one view-frame (colour as half, depth as float, material as half).
  // `frame_data` must match the manifest's face size and material flag (E141); indices must be
  // in range (E140). Each view-frame may be written once, in any order, from any one thread at a
  // time.
  Status write(uint32_t view, uint32_t frame, const ViewFrame& frame_data);

  // Writes manifest.json. Fails (E141) when a view-frame is missing.
  Status finish();

  // Removes every image this writer wrote (best effort): for a caller giving up after an error.
  void abandon();

 private:
  CaptureSetWriter(std::filesystem::path directory, CaptureManifest manifest);
  std::filesystem::path directory_;
  CaptureManifest manifest_;
  std::vector<bool> written_;  // view-major: view * frame_count + frame
  bool finished_ = false;
};

// Writes `bytes` to `path` whole: a temporary file beside it, flushed, then renamed over `path`
// (calf/format/files.h: an existing `path` must be a regular file, not a link or a FIFO).
// Errors: CALF-E004 naming the file and the system's reason. Shared by manifest, eye path and
// image writers.
Status write_file_atomically(const std::filesystem::path& path, std::string_view bytes);

// Reads a whole small file (a manifest, an eye path) into a string. Errors: CALF-E002 when it
// cannot be opened or is not a regular file (a directory, a FIFO), CALF-E003 when a read fails,
// each naming the file; `what_if_missing` is appended to the open error (e.g. why it is needed).
Expected<std::string> read_small_file(const std::filesystem::path& path,
                                      std::string_view what_if_missing = {});

}  // namespace calf::capture
