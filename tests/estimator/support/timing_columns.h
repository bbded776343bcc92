#pragma once
/// @file timing_columns.h
/// timing.txt without its clock: the columns that must be the same bytes for
/// any frontend.threads / backend_thread setting (t, events, features), the
/// processing time left out (it is the machine's, not the estimator's).

#include <cstdint>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include "evio/core/io/timing_txt.h"

namespace evio::test {

using TimingColumns = std::vector<std::tuple<TimeNs, std::int64_t, std::optional<std::int64_t>>>;

inline TimingColumns timingWithoutClock(const std::string& path) {
  TimingColumns columns;
  for (const io::TimingSample& s : io::readTimingText(path)) columns.emplace_back(s.t_ns, s.events, s.features);
  return columns;
}

/// Whether any row of `columns` has features > 0 (a comparison of columns
/// that are all zero would show nothing).
inline bool anyFeatures(const TimingColumns& columns) {
  for (const auto& [t, events, features] : columns)
    if (features.value_or(0) > 0) return true;
  return false;
}

}  // namespace evio::test
