// calf-play's window (compiled into calf-play only): a GLFW window (OpenGL 4.5 core) showing a
// clip played by Playback, with fly and orbit cameras, side-by-side stereo and a Dear ImGui HUD:
// the fps of displayed frames (wall time between buffer swaps, DisplayClock) and every
// representation's statistics (for a light field: active views, culled views and cells, Mbps at
// 24 fps, decode / upload / render times, RR).
//
// Keys: drag with the left button to look (fly) or turn around the volume centre (orbit);
// W/A/S/D/Q/E move (fly) or zoom (orbit, W/S); O fly <-> orbit; R toggles the RR variant; V
// distance <-> angle priority; + / - the most active views; Shift+S stereo; space pauses; H hides
// the HUD; Esc quits.
#pragma once

#include <cstdint>
#include <string>

#include "calf/format/status.h"
#include "calf/player/playback.h"

namespace calf::player {

struct WindowOptions {
  uint32_t width = 1280, height = 720;
  double fov_y_degrees = 75;
  bool stereo = false;
  double ipd = 0.064;       // scene units between the eyes
  uint32_t max_frames = 0;  // quit after this many displayed frames (0 = never); for tests
};

// One stderr warning per light-field view the decoder dropped at open (its index chunk unusable):
// the clip plays without it. Called by the window and the headless mode.
void warn_dropped_views(const Playback& play);

// Opens the window, plays until it is closed (or max_frames). Errors: CALF-E404 when no window or
// GL 4.5 context can be had (e.g. no display: the message says so), the playback's errors.
Status run_window(const std::string& clip_path, const PlaybackOptions& options,
                  const WindowOptions& window);

}  // namespace calf::player
