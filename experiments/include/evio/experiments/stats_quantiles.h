#pragma once
/// @file stats_quantiles.h
/// Nearest-rank quantiles in constant memory, for `evio stats`
/// (sequence_stats.h). The p-quantile (p in percent) of n values is the
/// value of rank r = ceil(p · n / 100) (1-based) in ascending order, computed
/// in integers, so that a one-line Python check reproduces it exactly:
/// `s = sorted(v); s[-(-p * len(s) // 100) - 1]`. The maximum is rank n.

#include <cstdint>
#include <vector>

#include "evio/core/time.h"

namespace evio::experiments {

/// The quantiles `evio stats` reports, in the unit of the values.
struct Quantiles {
  double p1 = 0.0, p5 = 0.0, p50 = 0.0, p90 = 0.0, p99 = 0.0;
  double min = 0.0, max = 0.0;
};

/// 1-based nearest rank of the `percent` quantile of `n` values (≥ 1 when n ≥ 1).
std::uint64_t nearestRank(int percent, std::uint64_t n);

/// Quantiles of `values` (sorts a copy; all zero when empty).
Quantiles quantilesOf(std::vector<double> values);

/// Counts of non-negative integers (bin i = value i), grown as needed:
/// memory is the largest value, not the number of values.
class IntegerHistogram {
 public:
  void add(std::uint64_t value);
  std::uint64_t count() const { return count_; }
  /// Exact nearest-rank quantiles; all zero when empty.
  Quantiles quantiles() const;

 private:
  std::uint64_t valueOfRank(std::uint64_t rank) const;
  std::vector<std::uint64_t> bins_;
  std::uint64_t count_ = 0;
};

/// Counts of non-negative durations in ns: 1 µs bins below 0.1 s, bins 0.1 %
/// wide (geometric) above. A quantile is the lower edge of its bin, so it is
/// the true nearest-rank value floored to the µs below 0.1 s, and within
/// 0.1 % above (up to 10^6 s; longer ones fall in the last bin). The
/// minimum is kept exactly. Under 1 MB whatever the count.
class DurationHistogram {
 public:
  DurationHistogram();
  void add(TimeNs duration_ns);
  std::uint64_t count() const { return count_; }
  /// Values below `limit_ns` (exact: counted directly, not from bins).
  void countBelow(TimeNs limit_ns) { limit_ns_ = limit_ns; }
  std::uint64_t below() const { return below_; }
  TimeNs minNs() const { return min_ns_; }
  /// Nearest-rank quantiles in seconds (min exact); all zero when empty.
  Quantiles quantilesS() const;

 private:
  std::size_t binOf(TimeNs d) const;
  double lowerEdgeS(std::size_t bin) const;
  std::vector<std::uint64_t> bins_;
  std::uint64_t count_ = 0;
  std::uint64_t below_ = 0;
  TimeNs limit_ns_ = 0;
  TimeNs min_ns_ = 0;
};

}  // namespace evio::experiments
