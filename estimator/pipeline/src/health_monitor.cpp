#include "evio/estimator/pipeline/health_monitor.h"

#include <cmath>
#include <algorithm>
#include <cstdio>
#include <limits>

namespace evio::estimator {

void HealthOptions::validate() const {
  requirePositive("window_s", window_s);
  requireInRange("window_s", window_s, 0.0, 3600.0);  // the window's updates are kept in memory
  requireField(min_window_dof >= 1 && min_window_dof <= 1000000, "min_window_dof", "must be in [1, 1000000]");
  requireField(nis_probability > 0.0 && nis_probability < 1.0, "nis_probability", "must be in (0, 1)");
  requireField(nis_diverged_ratio > 1.0, "nis_diverged_ratio", "must be > 1 (E[ratio] = 1)");
  requireField(expected_rejected_share > 0.0 && expected_rejected_share < 1.0, "expected_rejected_share",
               "must be in (0, 1)");
  requireField(min_window_features >= 1 && min_window_features <= 1000000, "min_window_features",
               "must be in [1, 1000000]");
  requirePositive("starvation_s", starvation_s);
  requirePositive("max_position_sigma_m", max_position_sigma_m);
}

HealthMonitor::HealthMonitor(const HealthOptions& options)
    : options_(options), chi2_((options.validate(), options.nis_probability)) {}

io::HealthRow healthRow(const Estimate& e) {
  const InnovationStats& n = e.innovation;
  const double var_p = e.cov_pose_B.diagonal().head<3>().maxCoeff();
  // A covariance that is no longer finite (the update that makes the filter
  // diverge) is reported as the largest σ a file can hold, so that the
  // monitor flags it and health.txt stays readable.
  const double sigma_p =
      std::isfinite(var_p) ? std::sqrt(std::max(var_p, 0.0)) : std::numeric_limits<double>::max();
  io::HealthRow row;
  row.t_ns = e.t_ns;
  row.nis = n.nis;
  row.dof = n.dof;
  row.accepted = n.accepted;
  row.rejected = n.rejected;
  row.slam = e.num_slam_features;
  row.msckf = e.num_msckf_features;
  row.sigma_p_m = sigma_p;
  row.nis_accepted = n.nis_accepted;
  row.dof_accepted = n.dof_accepted;
  return row;
}

void HealthMonitor::process(Estimate& in, std::vector<Estimate>& out) {
  observe(healthRow(in));
  out.push_back(std::move(in));
}

void HealthMonitor::raise(io::EstimateStatus::Code code, TimeNs t_ns, const std::string& cause) {
  const auto rank = [](io::EstimateStatus::Code c) {
    return c == io::EstimateStatus::Code::kDiverged ? 2 : c == io::EstimateStatus::Code::kDegraded ? 1 : 0;
  };
  if (rank(code) <= rank(verdict_.code)) return;
  verdict_ = HealthVerdict{code, t_ns, cause};
}

long binomialQuantile(long n, double p, double probability) {
  if (n <= 0 || !(p > 0.0)) return 0;
  if (!(p < 1.0)) return n;
  const double log_odds = std::log(p / (1.0 - p));
  double log_pmf = static_cast<double>(n) * std::log1p(-p);  // P(X = 0)
  double cdf = 0.0;
  for (long k = 0; k < n; ++k) {
    cdf += std::exp(log_pmf);
    if (cdf >= probability) return k;
    log_pmf += std::log(static_cast<double>(n - k) / static_cast<double>(k + 1)) + log_odds;
  }
  return n;
}

void HealthMonitor::slideWindow(const io::HealthRow& e) {
  window_.push_back({e.t_ns, e.nis_accepted, e.dof_accepted, e.accepted, e.rejected});
  window_nis_ += e.nis_accepted;
  window_dof_ += e.dof_accepted;
  window_accepted_ += e.accepted;
  window_rejected_ += e.rejected;
  const TimeNs span = secondsToNs(options_.window_s);
  while (!window_.empty() && window_.front().t_ns <= e.t_ns - span) {
    window_nis_ -= window_.front().nis;
    window_dof_ -= window_.front().dof;
    window_accepted_ -= window_.front().accepted;
    window_rejected_ -= window_.front().rejected;
    window_.pop_front();
  }
}

void HealthMonitor::judgeInnovations(TimeNs t_ns) {
  if (window_dof_ < options_.min_window_dof) return;
  if (!(window_nis_ > chi2_(static_cast<int>(window_dof_)))) return;
  const double rho = window_nis_ / static_cast<double>(window_dof_);
  char buf[200];
  std::snprintf(buf, sizeof(buf), "innovations %.3g times their expectation over %.3g s (%ld dof)", rho,
                options_.window_s, window_dof_);
  raise(rho > options_.nis_diverged_ratio ? io::EstimateStatus::Code::kDiverged : io::EstimateStatus::Code::kDegraded,
        t_ns, std::string("self-diagnosis: ") + buf);
}

void HealthMonitor::judgeGatedOut(TimeNs t_ns) {
  const long judged = window_accepted_ + window_rejected_;
  if (judged < options_.min_window_features) return;
  const long bound = binomialQuantile(judged, options_.expected_rejected_share, options_.nis_probability);
  if (window_rejected_ <= bound) return;
  char buf[200];
  std::snprintf(buf, sizeof(buf), "%ld of %ld features gated out over %.3g s (a consistent filter: at most %ld)",
                window_rejected_, judged, options_.window_s, bound);
  raise(io::EstimateStatus::Code::kDegraded, t_ns, std::string("self-diagnosis: ") + buf);
}

void HealthMonitor::observe(const io::HealthRow& e) {
  if (!options_.enabled) return;
  char buf[200];
  slideWindow(e);
  judgeInnovations(e.t_ns);
  judgeGatedOut(e.t_ns);
  // Feature starvation.
  if (e.accepted > 0) last_accepted_ns_ = e.t_ns;
  if (last_accepted_ns_ && nsToSeconds(e.t_ns - *last_accepted_ns_) > options_.starvation_s) {
    std::snprintf(buf, sizeof(buf), "no feature accepted for %.3g s", nsToSeconds(e.t_ns - *last_accepted_ns_));
    raise(io::EstimateStatus::Code::kDegraded, e.t_ns, std::string("self-diagnosis: ") + buf);
  }
  // Covariance growth.
  if (e.sigma_p_m > options_.max_position_sigma_m) {
    std::snprintf(buf, sizeof(buf), "position standard deviation %.3g m", e.sigma_p_m);
    raise(io::EstimateStatus::Code::kDegraded, e.t_ns, std::string("self-diagnosis: ") + buf);
  }
}

}  // namespace evio::estimator
