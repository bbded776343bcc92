#include "evio/estimator/pipeline/health_monitor.h"

#include <cmath>
#include <cstdio>

namespace evio::estimator {

void HealthOptions::validate() const {
  requirePositive("window_s", window_s);
  requireField(min_window_dof >= 1, "min_window_dof", "must be >= 1");
  requirePositive("nis_degraded_ratio", nis_degraded_ratio);
  requireField(nis_diverged_ratio >= nis_degraded_ratio, "nis_diverged_ratio", "must be >= nis_degraded_ratio");
  requirePositive("starvation_s", starvation_s);
  requirePositive("max_position_sigma_m", max_position_sigma_m);
}

HealthMonitor::HealthMonitor(const HealthOptions& options) : options_(options) { options_.validate(); }

void HealthMonitor::process(Estimate& in, std::vector<Estimate>& out) {
  if (options_.enabled) judge(in);
  out.push_back(std::move(in));
}

void HealthMonitor::raise(io::EstimateStatus::Code code, TimeNs t_ns, const std::string& cause) {
  const auto rank = [](io::EstimateStatus::Code c) {
    return c == io::EstimateStatus::Code::kDiverged ? 2 : c == io::EstimateStatus::Code::kDegraded ? 1 : 0;
  };
  if (rank(code) <= rank(verdict_.code)) return;
  verdict_ = HealthVerdict{code, t_ns, cause};
}

void HealthMonitor::judge(const Estimate& e) {
  char buf[200];
  // Innovation ratio over the window.
  window_.push_back({e.t_ns, e.innovation.nis, e.innovation.dof});
  window_nis_ += e.innovation.nis;
  window_dof_ += e.innovation.dof;
  const TimeNs span = secondsToNs(options_.window_s);
  while (!window_.empty() && window_.front().t_ns <= e.t_ns - span) {
    window_nis_ -= window_.front().nis;
    window_dof_ -= window_.front().dof;
    window_.pop_front();
  }
  if (window_dof_ >= options_.min_window_dof) {
    const double rho = window_nis_ / static_cast<double>(window_dof_);
    if (rho > options_.nis_degraded_ratio) {
      std::snprintf(buf, sizeof(buf), "innovations %.3g times their expectation over %.3g s (%ld dof)", rho,
                    options_.window_s, window_dof_);
      raise(rho > options_.nis_diverged_ratio ? io::EstimateStatus::Code::kDiverged
                                              : io::EstimateStatus::Code::kDegraded,
            e.t_ns, std::string("self-diagnosis: ") + buf);
    }
  }
  // Feature starvation.
  if (e.innovation.accepted > 0) last_accepted_ns_ = e.t_ns;
  if (last_accepted_ns_ && nsToSeconds(e.t_ns - *last_accepted_ns_) > options_.starvation_s) {
    std::snprintf(buf, sizeof(buf), "no feature accepted for %.3g s", nsToSeconds(e.t_ns - *last_accepted_ns_));
    raise(io::EstimateStatus::Code::kDegraded, e.t_ns, std::string("self-diagnosis: ") + buf);
  }
  // Covariance growth.
  const double sigma_p = std::sqrt(std::max(e.cov_pose_B.diagonal().head<3>().maxCoeff(), 0.0));
  if (sigma_p > options_.max_position_sigma_m) {
    std::snprintf(buf, sizeof(buf), "position standard deviation %.3g m", sigma_p);
    raise(io::EstimateStatus::Code::kDegraded, e.t_ns, std::string("self-diagnosis: ") + buf);
  }
}

}  // namespace evio::estimator
