#include "evio/experiments/stats_quantiles.h"

#include <algorithm>
#include <cmath>

namespace evio::experiments {

namespace {
constexpr int kPercents[] = {1, 5, 50, 90, 99};
constexpr TimeNs kFineLimitNs = 100 * kNsPerMs;  ///< 1 µs bins below this
constexpr std::size_t kFineBins = kFineLimitNs / 1000;
constexpr std::size_t kCoarseBins = 16200;       ///< 1.001^16200 · 0.1 s > 10^6 s
const double kLogRatio = std::log(1.001);
}  // namespace

std::uint64_t nearestRank(int percent, std::uint64_t n) {
  const std::uint64_t r = (static_cast<std::uint64_t>(percent) * n + 99) / 100;
  return std::max<std::uint64_t>(r, 1);
}

Quantiles quantilesOf(std::vector<double> values) {
  Quantiles q;
  if (values.empty()) return q;
  std::sort(values.begin(), values.end());
  const std::uint64_t n = values.size();
  double* out[] = {&q.p1, &q.p5, &q.p50, &q.p90, &q.p99};
  for (int i = 0; i < 5; ++i) *out[i] = values[nearestRank(kPercents[i], n) - 1];
  q.min = values.front();
  q.max = values.back();
  return q;
}

void IntegerHistogram::add(std::uint64_t value) {
  if (value >= bins_.size()) bins_.resize(value + 1, 0);
  ++bins_[value];
  ++count_;
}

std::uint64_t IntegerHistogram::valueOfRank(std::uint64_t rank) const {
  std::uint64_t cumulative = 0;
  for (std::size_t v = 0; v < bins_.size(); ++v) {
    cumulative += bins_[v];
    if (cumulative >= rank) return v;
  }
  return bins_.empty() ? 0 : bins_.size() - 1;
}

Quantiles IntegerHistogram::quantiles() const {
  Quantiles q;
  if (count_ == 0) return q;
  double* out[] = {&q.p1, &q.p5, &q.p50, &q.p90, &q.p99};
  for (int i = 0; i < 5; ++i) *out[i] = static_cast<double>(valueOfRank(nearestRank(kPercents[i], count_)));
  q.min = static_cast<double>(valueOfRank(1));
  q.max = static_cast<double>(valueOfRank(count_));
  return q;
}

DurationHistogram::DurationHistogram() : bins_(kFineBins + kCoarseBins, 0) {}

std::size_t DurationHistogram::binOf(TimeNs d) const {
  if (d < kFineLimitNs) return static_cast<std::size_t>(std::max<TimeNs>(d, 0) / 1000);
  const double k = std::floor(std::log(static_cast<double>(d) / static_cast<double>(kFineLimitNs)) / kLogRatio);
  return kFineBins + std::min<std::size_t>(static_cast<std::size_t>(k), kCoarseBins - 1);
}

double DurationHistogram::lowerEdgeS(std::size_t bin) const {
  if (bin < kFineBins) return static_cast<double>(bin) * 1e-6;
  return nsToSeconds(kFineLimitNs) * std::exp(kLogRatio * static_cast<double>(bin - kFineBins));
}

void DurationHistogram::add(TimeNs duration_ns) {
  ++bins_[binOf(duration_ns)];
  min_ns_ = count_ == 0 ? duration_ns : std::min(min_ns_, duration_ns);
  ++count_;
  if (duration_ns < limit_ns_) ++below_;
}

Quantiles DurationHistogram::quantilesS() const {
  Quantiles q;
  if (count_ == 0) return q;
  auto ofRank = [&](std::uint64_t rank) {
    std::uint64_t cumulative = 0;
    for (std::size_t b = 0; b < bins_.size(); ++b) {
      cumulative += bins_[b];
      if (cumulative >= rank) return lowerEdgeS(b);
    }
    return lowerEdgeS(bins_.size() - 1);
  };
  double* out[] = {&q.p1, &q.p5, &q.p50, &q.p90, &q.p99};
  for (int i = 0; i < 5; ++i) *out[i] = ofRank(nearestRank(kPercents[i], count_));
  q.min = nsToSeconds(min_ns_);
  q.max = ofRank(count_);
  return q;
}

}  // namespace evio::experiments
