#pragma once
/// @file time.h
/// Time in the library is int64 nanoseconds (`t_ns`). Files use their own
/// unit; conversions happen in core/io only through these helpers.

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>

namespace evio {

using TimeNs = std::int64_t;

constexpr TimeNs kNsPerSecond = 1'000'000'000;
constexpr TimeNs kNsPerMs = 1'000'000;
constexpr TimeNs kNsPerUs = 1'000;

/// Seconds (double) to nanoseconds, rounded to nearest.
inline TimeNs secondsToNs(double t_s) { return static_cast<TimeNs>(std::llround(t_s * 1e9)); }

/// Nanoseconds to seconds (double).
constexpr double nsToSeconds(TimeNs t_ns) { return static_cast<double>(t_ns) * 1e-9; }

/// A time for messages: "12.345 s" (`decimals` digits after the point).
inline std::string secondsText(TimeNs t_ns, int decimals = 3) {
  char buf[48];
  std::snprintf(buf, sizeof(buf), "%.*f s", decimals, nsToSeconds(t_ns));
  return buf;
}

}  // namespace evio
