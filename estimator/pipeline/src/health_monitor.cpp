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
  return io::HealthRow{e.t_ns, n.nis, n.dof, n.accepted, n.rejected, e.num_slam_features, e.num_msckf_features,
                       sigma_p};
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

void HealthMonitor::observe(const io::HealthRow& e) {
  if (!options_.enabled) return;
  char buf[200];
  // Innovation ratio over the window.
  window_.push_back({e.t_ns, e.nis, e.dof});
  window_nis_ += e.nis;
  window_dof_ += e.dof;
  const TimeNs span = secondsToNs(options_.window_s);
  while (!window_.empty() && window_.front().t_ns <= e.t_ns - span) {
    window_nis_ -= window_.front().nis;
    window_dof_ -= window_.front().dof;
    window_.pop_front();
  }
  if (window_dof_ >= options_.min_window_dof) {
    const double rho = window_nis_ / static_cast<double>(window_dof_);
    if (window_nis_ > chi2_(static_cast<int>(window_dof_))) {
      std::snprintf(buf, sizeof(buf), "innovations %.3g times their expectation over %.3g s (%ld dof)", rho,
                    options_.window_s, window_dof_);
      raise(rho > options_.nis_diverged_ratio ? io::EstimateStatus::Code::kDiverged
                                              : io::EstimateStatus::Code::kDegraded,
            e.t_ns, std::string("self-diagnosis: ") + buf);
    }
  }
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
