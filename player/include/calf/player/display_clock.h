// The wall-clock rate of displayed frames, for a HUD's fps figure and a frame budget's reports
// (frame_controller.h). Only the instants at which frames were displayed count: a figure computed
// from anything else (the time between two polls of the event loop, a render call alone) can
// claim thousands of frames per second while each frame takes seconds.
#pragma once

#include <chrono>
#include <cstddef>
#include <deque>

namespace calf::player {

class DisplayClock {
 public:
  using Clock = std::chrono::steady_clock;

  // A frame was displayed at `t` (after its buffer swap); instants must not decrease.
  void displayed(Clock::time_point t);
  // Whether two frames were displayed, so that an interval is known.
  bool has_interval() const { return times_.size() >= 2; }
  // Wall time in ms between the last two displayed frames; 0 before the second frame.
  double last_frame_ms() const;
  // Displayed frames per second over about the last `window` (at least the last interval): the
  // intervals between the frames kept, divided by their total wall time; 0 before the second
  // frame.
  double fps() const;

  // How far back fps() looks.
  static constexpr std::chrono::milliseconds kWindow{1000};

 private:
  std::deque<Clock::time_point> times_;  // displayed instants within kWindow of the last, >= 2
};

}  // namespace calf::player
