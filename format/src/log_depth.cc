#include "calf/format/log_depth.h"

#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

namespace calf {
namespace {

std::string float_text(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

}  // namespace

DepthClass classify_depth(float z) {
  if (z == std::numeric_limits<float>::infinity()) return DepthClass::kSky;
  if (!(z > 0.0f) || !std::isfinite(z)) return DepthClass::kInvalid;  // NaN fails z > 0
  return DepthClass::kFinite;
}

LogDepthRange::LogDepthRange(float z_near, float z_far)
    : near_(z_near),
      far_(z_far),
      log_near_(std::log(static_cast<double>(z_near))),
      log_ratio_(std::log(static_cast<double>(z_far)) - std::log(static_cast<double>(z_near))),
      step_(log_ratio_ / kLog16MaxFinite),
      inv_step_(kLog16MaxFinite / log_ratio_) {}

Expected<LogDepthRange> LogDepthRange::make(float z_near, float z_far) {
  if (!std::isfinite(z_near) || !(z_near > 0.0f)) {
    return Status(ErrorId::kDepthRange,
                  "z_near " + float_text(z_near) + " must be finite and greater than 0");
  }
  if (!std::isfinite(z_far)) {
    return Status(ErrorId::kDepthRange,
                  "z_far " + float_text(z_far) + " must be finite (sky is coded separately)");
  }
  if (!(z_far > z_near)) {
    return Status(ErrorId::kDepthRange, "z_far " + float_text(z_far) +
                                            " must be greater than z_near " + float_text(z_near));
  }
  LogDepthRange range(z_near, z_far);
  if (!std::isfinite(range.log_ratio_) || !(range.log_ratio_ > 0)) {
    return Status(ErrorId::kDepthRange, "ln(z_far / z_near) is not finite for z_near " +
                                            float_text(z_near) + ", z_far " + float_text(z_far));
  }
  return range;
}

Expected<LogDepthRange> LogDepthRange::covering(float min_depth, float max_depth) {
  if (classify_depth(min_depth) != DepthClass::kFinite ||
      classify_depth(max_depth) != DepthClass::kFinite || max_depth < min_depth) {
    return Status(ErrorId::kDepthRange, "measured depths [" + float_text(min_depth) + ", " +
                                            float_text(max_depth) +
                                            "] are not finite, positive and ordered");
  }
  if (max_depth == min_depth) {
    const float widened = min_depth + min_depth / 1024.0f;
    // At FLT_MAX the widened value overflows; widen downward instead.
    if (!std::isfinite(widened)) return make(min_depth - min_depth / 1024.0f, min_depth);
    return make(min_depth, widened);
  }
  return make(min_depth, max_depth);
}

Expected<uint16_t> LogDepthRange::encode(float z) const {
  switch (classify_depth(z)) {
    case DepthClass::kSky:
      return kLog16Sky;
    case DepthClass::kInvalid:
      return Status(ErrorId::kDepthValue,
                    "depth " + float_text(z) + " is not a distance (NaN, -inf or <= 0)");
    case DepthClass::kFinite:
      break;
  }
  const double x = (std::log(static_cast<double>(z)) - log_near_) * inv_step_;
  if (x < -1.0 || x > kLog16MaxFinite + 1.0) {
    return Status(ErrorId::kDepthOutOfRange, "depth " + float_text(z) + " is outside [z_near " +
                                                 float_text(near_) + ", z_far " + float_text(far_) +
                                                 "]");
  }
  return encode_unchecked(z);
}

uint16_t LogDepthRange::encode_unchecked(float z) const {
  if (!(z < std::numeric_limits<float>::infinity())) return kLog16Sky;  // +inf and NaN
  if (!(z > near_)) return 0;
  if (z >= far_) return kLog16MaxFinite;
  const double x = (std::log(static_cast<double>(z)) - log_near_) * inv_step_;
  const double code = std::floor(x + 0.5);
  return code >= kLog16MaxFinite ? kLog16MaxFinite : static_cast<uint16_t>(code);
}

float LogDepthRange::decode(uint16_t code) const {
  if (code == kLog16Sky) return std::numeric_limits<float>::infinity();
  if (code == 0) return near_;
  if (code == kLog16MaxFinite) return far_;
  return static_cast<float>(std::exp(log_near_ + code * step_));
}

double LogDepthRange::normalized_from_depth(double z) const {
  return (std::log(z) - log_near_) / log_ratio_;
}

double LogDepthRange::depth_from_normalized(double x) const {
  return std::exp(log_near_ + x * log_ratio_);
}

}  // namespace calf
