// Headless evaluation of a playback along an eye path (calf-play --headless is a thin command over
// it): every pose of the path is prepared and rendered with the playback's renderer, its frame
// written (PNG, EXR or both) and, with ground truth, compared (PSNR, SSIM, heat maps, the noise
// floor, the error breakdown, a contact sheet); beside a second playback of the full scene it
// measures epsilon (paper 004). Nothing is printed: the report's text (one line per pose, then the
// summary lines, exactly as calf-play prints them) and the notices go to callbacks, and the
// figures come back as records.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "calf/capture/capture_set.h"
#include "calf/capture/eye_path.h"
#include "calf/format/status.h"
#include "calf/player/error_breakdown.h"
#include "calf/player/playback.h"

namespace calf::player {

// Which frame files a session writes into `out`.
enum class FrameFiles : uint8_t { kPng, kExr, kBoth };

struct HeadlessSessionOptions {
  // The eye path (format/CAPTURE.md); empty: `compare`/eye_path.json.
  std::filesystem::path eye_path;
  // Directory for frame_NNNNN.{png,exr}, heat_NNNNN.png and classes_NNNNN.png (created); empty:
  // nothing is written.
  std::filesystem::path out;
  FrameFiles frame_files = FrameFiles::kPng;
  // Ground truth written by calf-capture --ground-truth: per-pose PSNR / SSIM.
  std::filesystem::path compare;
  // With `compare`: heat maps into `out`.
  bool heat_maps = true;
  // With `compare`: ground truth of the same poses with another seed (empty:
  // `compare`/noise-floor when it holds an eye path).
  std::filesystem::path noise_floor;
  // With `compare`: the capture set the clip was made from (the error breakdown).
  std::filesystem::path breakdown;
  // With `compare`: a PNG of `sheet_rows` poses spread along the path (ground truth | calf |
  // heat map).
  std::filesystem::path contact_sheet;
  uint32_t sheet_rows = 8;
  // Report each pose's render time to the surfel point-size controller (the playback's surfel
  // options hold the target; > 0 here says one is set).
  double surfel_target_ms = 0;
  // Mention the peripheral objects of foveated surfels per pose.
  bool surfel_foveation = false;
};

// The figures of one pose.
struct HeadlessPose {
  size_t pose = 0;
  uint32_t frame = 0;
  double render_ms = 0;
  // Against the ground truth (NaN without `compare`); PSNR clamped at 100 dB.
  double psnr = std::nan(""), ssim = std::nan("");
};

// The figures over the path.
struct HeadlessSummary {
  std::vector<HeadlessPose> poses;
  uint32_t compared = 0;  // poses compared with ground truth
  double mean_psnr = 0, mean_ssim = 0, min_psnr = 0, min_ssim = 0;
  size_t min_psnr_pose = 0, min_ssim_pose = 0;
  size_t files_written = 0;  // frames, heat maps, class maps and the contact sheet
};

// Where a session's text goes: `report` gets the report's text in pieces (what calf-play writes
// to stdout, newlines included), `notice` one line per warning or notice (no newline, no command
// name: "warning: pose 3 is outside the clip's view volume; ...").
struct HeadlessSinks {
  std::function<void(std::string_view text)> report;
  std::function<void(std::string_view line)> notice;
};

class HeadlessSession {
 public:
  // Reads the eye path (and the noise floor's, the breakdown's capture set) and creates `out`.
  // `play` (and `full`, the full-scene clip compared with per pose, and `lossless`, a lossless
  // clip of the capture for the breakdown's codec class; both may be null) must outlive the
  // session. Errors: the eye path's (CALF-E002 missing, the JSON reader's), CALF-E461 when
  // neither `eye_path` nor `compare` is given, the path names no ground-truth images but
  // `compare` is given, or the noise floor is not ground truth of the same poses and size; the
  // capture set's; CALF-E004 when `out` cannot be created.
  static Expected<HeadlessSession> open(Playback& play, Playback* full, Playback* lossless,
                                        const HeadlessSessionOptions& options);
  HeadlessSession(HeadlessSession&&) noexcept;
  HeadlessSession& operator=(HeadlessSession&&) noexcept;
  ~HeadlessSession();

  const capture::EyePath& eye_path() const;

  // Walks the whole path. Errors: the playbacks', the ground truth's, file writes'; what was
  // reported up to the error has gone to `sinks`.
  Expected<HeadlessSummary> run(const HeadlessSinks& sinks);

 private:
  struct Impl;
  explicit HeadlessSession(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace calf::player
