#pragma once
/// @file preset_util.h
/// Small helpers shared by the preset implementations (private to the module).

#include <numbers>
#include <string>

#include "evio/core/eigen_types.h"
#include "evio/core/io/config.h"
#include "evio/core/options.h"

namespace evio::preset {

constexpr double kDegToRad = std::numbers::pi / 180.0;

/// Validates a frequency band [lo, hi] in Hz (0 < lo <= hi).
inline void requireBand(const char* lo_name, double lo, const char* hi_name, double hi) {
  requirePositive(lo_name, lo);
  requirePositive(hi_name, hi);
  requireField(lo <= hi, hi_name, std::string("must be >= ") + lo_name);
}

/// Validates a vector whose components must all be >= 0 and finite.
inline void requireNonNegative3(const char* name, const Vec3& v) {
  for (int i = 0; i < 3; ++i) requireNonNegative(std::string(name) + "[" + std::to_string(i) + "]", v(i));
}

/// Validates that every component is finite.
inline void requireFinite3(const char* name, const Vec3& v) {
  requireField(v.allFinite(), name, "must be finite");
}

/// The resolved options as YAML, for ContinuousTrajectory::configYaml().
template <class Options>
std::string yamlOf(const Options& options) {
  return config::toYaml(options);
}

}  // namespace evio::preset
