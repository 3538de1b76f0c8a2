#include "calf/player/display_clock.h"

namespace calf::player {

void DisplayClock::displayed(Clock::time_point t) {
  times_.push_back(t);
  // Keep the last two always (one interval), then whatever lies within the window.
  while (times_.size() > 2 && t - times_[1] >= kWindow) times_.pop_front();
}

double DisplayClock::last_frame_ms() const {
  if (times_.size() < 2) return 0;
  return std::chrono::duration<double, std::milli>(times_.back() - times_[times_.size() - 2])
      .count();
}

double DisplayClock::fps() const {
  if (times_.size() < 2) return 0;
  const double seconds = std::chrono::duration<double>(times_.back() - times_.front()).count();
  return seconds > 0 ? static_cast<double>(times_.size() - 1) / seconds : 0;
}

}  // namespace calf::player
