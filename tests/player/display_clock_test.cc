// DisplayClock: the fps figure comes from the wall time between displayed frames only.
#include "calf/player/display_clock.h"

#include <gtest/gtest.h>

#include <chrono>

namespace calf::player {
namespace {

using std::chrono::milliseconds;
const DisplayClock::Clock::time_point kT0{};

TEST(DisplayClock, NoFigureBeforeTheSecondFrame) {
  DisplayClock c;
  EXPECT_FALSE(c.has_interval());
  EXPECT_EQ(c.fps(), 0);
  c.displayed(kT0);
  EXPECT_FALSE(c.has_interval());
  EXPECT_EQ(c.fps(), 0);
  EXPECT_EQ(c.last_frame_ms(), 0);
}

// A slow renderer: frames of 4.8 s on llvmpipe must read 0.21 fps, not thousands.
TEST(DisplayClock, SlowFramesReadAsSlow) {
  DisplayClock c;
  for (int i = 0; i < 5; ++i) c.displayed(kT0 + milliseconds(4800 * i));
  EXPECT_TRUE(c.has_interval());
  EXPECT_DOUBLE_EQ(c.last_frame_ms(), 4800);
  EXPECT_NEAR(c.fps(), 1 / 4.8, 1e-12);
}

TEST(DisplayClock, AveragesOverAboutASecond) {
  DisplayClock c;
  // 100 frames 10 ms apart (100 fps), then one of 500 ms.
  for (int i = 0; i < 100; ++i) c.displayed(kT0 + milliseconds(10 * i));
  EXPECT_NEAR(c.fps(), 100, 1e-9);
  c.displayed(kT0 + milliseconds(990 + 500));
  EXPECT_DOUBLE_EQ(c.last_frame_ms(), 500);
  // Kept: the frames from 0.49 s on (the last that is >= 1 s before the newest, and later):
  // 51 frames from 490 ms to 990 ms plus the one at 1490 ms, 51 intervals over 1000 ms.
  EXPECT_NEAR(c.fps(), 51.0, 1e-9);
}

}  // namespace
}  // namespace calf::player
