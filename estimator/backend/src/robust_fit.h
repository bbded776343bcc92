#pragma once
// Robust statistics shared by the gyroscope-bias estimators
// (gyro_bias_from_tracks.cpp, gyro_bias_bundle.cpp): the residuals' σ from
// their median absolute value, and Huber's weights at 1.345 σ (95 %
// efficiency on Gaussian residuals, bounded influence of the others).

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

namespace evio::estimator::robust {

/// σ of Gaussian values from their median absolute value: σ = 1.4826 · median |x|.
inline constexpr double kMadToSigma = 1.4826;
/// Huber's threshold in units of σ.
inline constexpr double kHuberSigmas = 1.345;

/// The median of v (0 for no values).
inline double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

/// The robust σ of values given as their absolute values.
inline double sigmaOfAbsolute(std::vector<double> abs_values) { return kMadToSigma * median(std::move(abs_values)); }

/// Huber's weight of a residual r for the threshold c (1 when c is not positive).
inline double huberWeight(double r, double c) { return c > 0.0 && std::abs(r) > c ? c / std::abs(r) : 1.0; }

}  // namespace evio::estimator::robust
