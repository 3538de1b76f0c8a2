// calf/format/vertex_states.h: the one interpolation of vertex states, on hand-computed values.
#include "calf/format/vertex_states.h"

#include <vector>

#include <gtest/gtest.h>

namespace calf {
namespace {

std::vector<float> at(const std::vector<float>& rest, const std::vector<float>& times,
                      const std::vector<float>& states, double time) {
  std::vector<float> out(rest.size(), -99.0f);
  vertex_states_at(rest, times, states, time, out);
  return out;
}

TEST(VertexStates, HeldOutsideLinearBetween) {
  const std::vector<float> rest = {7, 7, 7};
  const std::vector<float> times = {1, 3, 4};
  const std::vector<float> states = {0, 10, -2, 4, 20, 2, 8, 0, 0};
  EXPECT_EQ(at(rest, times, states, 0.0), (std::vector<float>{0, 10, -2}));  // before: state 0
  EXPECT_EQ(at(rest, times, states, 1.0), (std::vector<float>{0, 10, -2}));  // at state 0
  EXPECT_EQ(at(rest, times, states, 2.0), (std::vector<float>{2, 15, 0}));   // half way
  EXPECT_EQ(at(rest, times, states, 3.5), (std::vector<float>{6, 10, 1}));   // half way
  EXPECT_EQ(at(rest, times, states, 4.0), (std::vector<float>{8, 0, 0}));    // the last
  EXPECT_EQ(at(rest, times, states, 1e30), (std::vector<float>{8, 0, 0}));   // held
}

TEST(VertexStates, WithoutStatesTheRestPose) {
  const std::vector<float> rest = {1, 2, 3, 4, 5, 6};
  EXPECT_EQ(at(rest, {}, {}, 5.0), rest);
  // A states array of another size than times x rest is not read.
  EXPECT_EQ(at(rest, {0, 1}, {9, 9, 9}, 0.5), rest);
  EXPECT_TRUE(at({}, {0, 1}, {}, 0.5).empty());
}

}  // namespace
}  // namespace calf
