#include "evio/simulator/davis_auto_exposure.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>

namespace evio::simulator {

namespace {

constexpr int kLowBin = 25;              // ⌊0.10 · 256⌋
constexpr int kHighBin = 230;            // ⌊0.90 · 256⌋
constexpr double kUnderOverFraction = 0.33;
constexpr double kUnderOverStepUs = 14000.0;
constexpr double kUnderOverExponent = 1.65;
constexpr double kMsvStepUs = 100.0;
constexpr double kMsvDeadBand = 0.1;
constexpr int kMsvRanges = 5;
constexpr std::int64_t kRangeWidth = 65536 / kMsvRanges;  // 13107, as the driver's integer division
constexpr std::int64_t kMinExposureUs = 1;
constexpr std::int64_t kMaxExposureUs = 1000000;

/// A move of `step` µs toward `sign`, at least 1 µs, within the driver's limits.
std::int64_t move(std::int64_t exposure_us, std::int64_t step, int sign) {
  std::int64_t next = exposure_us + sign * step;
  if (next == exposure_us) next += sign;
  return std::clamp(next, kMinExposureUs, kMaxExposureUs);
}

}  // namespace

DavisExposureStatistics davisExposureStatistics(const cv::Mat& image) {
  std::array<std::int64_t, 256> histogram{};
  std::array<double, kMsvRanges> range_sum{};
  for (int y = 0; y < image.rows; ++y) {
    const std::uint8_t* row = image.ptr<std::uint8_t>(y);
    for (int x = 0; x < image.cols; ++x) {
      const std::int64_t v = static_cast<std::int64_t>(row[x]) * 256;  // the 16-bit sample
      ++histogram[row[x]];
      range_sum[static_cast<std::size_t>(std::min<std::int64_t>(v / kRangeWidth, kMsvRanges - 1))] +=
          static_cast<double>(v);
    }
  }
  const double pixels = static_cast<double>(image.total());
  std::int64_t low = 0, high = 0;
  for (int b = 0; b < kLowBin; ++b) low += histogram[static_cast<std::size_t>(b)];
  for (int b = kHighBin; b < 256; ++b) high += histogram[static_cast<std::size_t>(b)];
  double num = 0.0, den = 0.0;
  for (int i = 0; i < kMsvRanges; ++i) {
    num += (i + 1.0) * range_sum[static_cast<std::size_t>(i)];
    den += range_sum[static_cast<std::size_t>(i)];
  }
  DavisExposureStatistics s;
  s.fraction_low = pixels > 0 ? static_cast<double>(low) / pixels : 0.0;
  s.fraction_high = pixels > 0 ? static_cast<double>(high) / pixels : 0.0;
  s.mean_sample_value = num / (den > 0.0 ? den : 1.0);  // an all-black frame: 0, under-exposed
  return s;
}

std::int64_t davisNextExposureUs(const DavisExposureStatistics& s, std::int64_t exposure_us) {
  const double low_error = s.fraction_low - kUnderOverFraction;
  const double high_error = s.fraction_high - kUnderOverFraction;
  if (low_error >= 0.0 && high_error < 0.0)
    return move(exposure_us, static_cast<std::int64_t>(kUnderOverStepUs * std::pow(low_error, kUnderOverExponent)), +1);
  if (high_error >= 0.0 && low_error < 0.0)
    return move(exposure_us, static_cast<std::int64_t>(kUnderOverStepUs * std::pow(high_error, kUnderOverExponent)), -1);
  std::int64_t divisor = 1;
  if (std::abs(low_error) < 0.1 || std::abs(high_error) < 0.1) divisor = 5;
  if (std::abs(low_error) < 0.05 || std::abs(high_error) < 0.05) divisor = 10;
  const double msv_error = 0.5 * kMsvRanges - s.mean_sample_value;
  const std::int64_t step = static_cast<std::int64_t>(kMsvStepUs * msv_error * msv_error) / divisor;
  if (msv_error > kMsvDeadBand) return move(exposure_us, step, +1);
  if (msv_error < -kMsvDeadBand) return move(exposure_us, step, -1);
  return exposure_us;
}

}  // namespace evio::simulator
