// Tests of the log-16 depth mapping (format/include/calf/format/log_depth.h).
#include "calf/format/log_depth.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace calf {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

LogDepthRange must_make(float near, float far) {
  auto r = LogDepthRange::make(near, far);
  EXPECT_TRUE(r.ok()) << r.status().to_string();
  return *r;
}

TEST(LogDepthTest, ExactAtNearAndFar) {
  for (auto [near, far] : {std::pair{0.1f, 100.0f}, {1e-4f, 1e6f}, {2.0f, 2.001f}}) {
    const LogDepthRange r = must_make(near, far);
    EXPECT_EQ(*r.encode(near), 0);
    EXPECT_EQ(*r.encode(far), kLog16MaxFinite);
    EXPECT_EQ(r.decode(0), near);
    EXPECT_EQ(r.decode(kLog16MaxFinite), far);
  }
}

TEST(LogDepthTest, MatchesEquation13) {
  // Eq. 13 with the top code reserved: code = 65534 * ln(z / near) / ln(far / near), rounded.
  const LogDepthRange r = must_make(0.5f, 80.0f);
  for (float z : {0.5f, 0.7f, 1.0f, 3.3f, 10.0f, 47.5f, 79.9f}) {
    const double expected = std::round(65534.0 * std::log(z / 0.5) / std::log(80.0 / 0.5));
    EXPECT_EQ(*r.encode(z), static_cast<uint16_t>(expected)) << z;
  }
}

TEST(LogDepthTest, RelativeStepPerCodeIsDocumentedValue) {
  const LogDepthRange r = must_make(0.1f, 100.0f);
  const double step = std::log(100.0 / static_cast<double>(0.1f)) / 65534.0;
  EXPECT_NEAR(r.relative_step(), step, 1e-15);
  // Consecutive codes differ by exactly that ratio (up to float rounding of the decoded depth).
  for (uint16_t c : {1, 100, 30000, 65000}) {
    const double ratio = std::log(static_cast<double>(r.decode(c + 1)) / r.decode(c));
    EXPECT_NEAR(ratio, step, 1.2e-7) << c;
  }
}

TEST(LogDepthTest, MonotonicOverEveryCode) {
  const LogDepthRange r = must_make(1e-4f, 1e6f);
  float previous = 0;
  for (uint32_t c = 0; c <= kLog16MaxFinite; ++c) {
    const float z = r.decode(static_cast<uint16_t>(c));
    ASSERT_TRUE(std::isfinite(z)) << c;
    ASSERT_GE(z, previous) << c;  // float rounding may merge neighbours, never reorder them
    previous = z;
  }
  // and encode is monotonic over depths
  uint16_t previous_code = 0;
  for (double x = 0; x <= 1.0; x += 1.0 / 200000) {
    const uint16_t code = r.encode_unchecked(static_cast<float>(r.depth_from_normalized(x)));
    ASSERT_GE(code, previous_code) << x;
    previous_code = code;
  }
}

TEST(LogDepthTest, RoundTripErrorWithinHalfAStepAtTheExtremes) {
  // near 1e-4 with far 1e6: the widest range in the spec's tests.
  for (auto [near, far] : {std::pair{1e-4f, 1e6f}, {0.1f, 100.0f}, {1.0f, 1.0001f}}) {
    const LogDepthRange r = must_make(near, far);
    const double bound = std::exp(r.relative_step() / 2) - 1 + 2e-7;  // + float rounding
    for (int i = 0; i <= 10000; ++i) {
      const float z = static_cast<float>(r.depth_from_normalized(i / 10000.0));
      if (z < near || z > far) continue;
      const float back = r.decode(*r.encode(z));
      ASSERT_LE(std::fabs(back / static_cast<double>(z) - 1.0), bound) << near << " " << z;
    }
  }
}

TEST(LogDepthTest, SkyHasItsOwnCode) {
  const LogDepthRange r = must_make(0.1f, 100.0f);
  EXPECT_EQ(*r.encode(kInf), kLog16Sky);
  EXPECT_EQ(r.decode(kLog16Sky), kInf);
  EXPECT_EQ(classify_depth(kInf), DepthClass::kSky);
  // No finite depth, however far inside the range, codes as sky.
  EXPECT_EQ(*r.encode(100.0f), kLog16MaxFinite);
  EXPECT_NE(*r.encode(std::nextafter(100.0f, 0.0f)), kLog16Sky);
}

TEST(LogDepthTest, InvalidDepthsAreErrorsNeverFinite) {
  const LogDepthRange r = must_make(0.1f, 100.0f);
  for (float z : {kNaN, -kInf, -1.0f, 0.0f, -0.0f, -1e-30f}) {
    EXPECT_EQ(classify_depth(z), DepthClass::kInvalid) << z;
    auto code = r.encode(z);
    ASSERT_FALSE(code.ok()) << z;
    EXPECT_EQ(code.status().id(), ErrorId::kDepthValue);
    EXPECT_NE(code.status().to_string().find("CALF-E021"), std::string::npos);
  }
  EXPECT_EQ(r.encode_unchecked(kNaN), kLog16Sky);  // unchecked: NaN is never a finite code
}

TEST(LogDepthTest, OutOfRangeDepthsAreErrorsButRoundingIsClamped) {
  const LogDepthRange r = must_make(1.0f, 10.0f);
  auto below = r.encode(0.5f);
  ASSERT_FALSE(below.ok());
  EXPECT_EQ(below.status().id(), ErrorId::kDepthOutOfRange);
  EXPECT_NE(below.status().message().find("0.5"), std::string::npos);
  EXPECT_FALSE(r.encode(20.0f).ok());
  // One float ulp outside (a measured min/max after float rounding) clamps to the end codes.
  EXPECT_EQ(*r.encode(std::nextafter(1.0f, 0.0f)), 0);
  EXPECT_EQ(*r.encode(std::nextafter(10.0f, 100.0f)), kLog16MaxFinite);
}

TEST(LogDepthTest, InvalidRangesAreRejected) {
  struct Case {
    float near, far;
  } cases[] = {{1.0f, 1.0f}, {0.0f, 1.0f}, {-1.0f, 1.0f}, {2.0f, 1.0f}, {kNaN, 1.0f},
               {1.0f, kNaN}, {1.0f, kInf}, {kInf, kInf},  {-kInf, 1.0f}};
  for (const auto& c : cases) {
    auto r = LogDepthRange::make(c.near, c.far);
    ASSERT_FALSE(r.ok()) << c.near << " " << c.far;
    EXPECT_EQ(r.status().id(), ErrorId::kDepthRange);
  }
  // The whole positive float range is a valid (if coarse) range: ln(far / near) stays finite.
  auto widest = LogDepthRange::make(1e-45f, std::numeric_limits<float>::max());
  ASSERT_TRUE(widest.ok());
  EXPECT_EQ(*widest->encode(1e-45f), 0);
  EXPECT_EQ(*widest->encode(std::numeric_limits<float>::max()), kLog16MaxFinite);
}

TEST(LogDepthTest, CoveringWidensAFlatScene) {
  auto r = LogDepthRange::covering(5.0f, 5.0f);
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r->z_near(), 5.0f);
  EXPECT_GT(r->z_far(), 5.0f);
  EXPECT_EQ(*r->encode(5.0f), 0);
  EXPECT_EQ(r->decode(0), 5.0f);
  auto huge =
      LogDepthRange::covering(std::numeric_limits<float>::max(), std::numeric_limits<float>::max());
  ASSERT_TRUE(huge.ok());
  EXPECT_EQ(*huge->encode(std::numeric_limits<float>::max()), kLog16MaxFinite);
  EXPECT_FALSE(LogDepthRange::covering(5.0f, 4.0f).ok());
  EXPECT_FALSE(LogDepthRange::covering(0.0f, 4.0f).ok());
  EXPECT_FALSE(LogDepthRange::covering(1.0f, kInf).ok());
}

TEST(LogDepthTest, NormalizedFormIsTheContinuousMapping) {
  const LogDepthRange r = must_make(0.25f, 64.0f);
  EXPECT_NEAR(r.normalized_from_depth(0.25), 0.0, 1e-15);
  EXPECT_NEAR(r.normalized_from_depth(64.0), 1.0, 1e-15);
  EXPECT_NEAR(r.normalized_from_depth(4.0), 0.5, 1e-15);  // geometric midpoint
  for (double x : {0.0, 0.1, 0.5, 0.9, 1.0}) {
    EXPECT_NEAR(r.normalized_from_depth(r.depth_from_normalized(x)), x, 1e-12);
    // The 16-bit code is the normalised value scaled by 65534.
    EXPECT_NEAR(r.encode_unchecked(static_cast<float>(r.depth_from_normalized(x))), x * 65534,
                0.51);
  }
}

}  // namespace
}  // namespace calf
