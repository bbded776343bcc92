#pragma once
/// @file health_monitor.h
/// The estimator's self-diagnosis without ground truth
/// (docs/evaluation.md#self-diagnosis): a stage between the backend and the
/// writer that watches every estimate's innovations and covariance and
/// reports the run `degraded` or `diverged`, with the time and the cause of
/// the first such verdict. It never changes an estimate and never stops the
/// filter; its verdict goes into status.yaml.
///
/// Signals, over a sliding window of window_s of data time:
///  - innovation ratio ρ = Σ nis / Σ dof of the visual features the gates
///    accepted (Estimate::innovation). For a consistent filter
///    Σ nis ~ χ²(Σ dof), so E[ρ] ≈ 1 (slightly less: the gates cut the
///    tail). `degraded` when Σ nis exceeds its χ² quantile of
///    nis_probability (0.999: the innovations are larger than the filter's
///    own noise model allows, at 99.9 %); `diverged` when ρ exceeds
///    nis_diverged_ratio: the state disagrees with the measurements it
///    uses. Judged once the window holds at least min_window_dof degrees of
///    freedom. No threshold is fitted to a sequence: the χ² test is the
///    filter's own claim;
///  - features gated out: of the n features the gates judged in the window,
///    more rejected than a Binomial(n, expected_rejected_share) count
///    exceeds with probability 1 − nis_probability is `degraded` (the
///    measurements disagree with the filter, which goes on on the IMU and
///    the features it keeps; a rejected innovation alone never says
///    `diverged`: a tracker losing its features at speed looks the same);
///  - feature starvation: no feature accepted by the gates for starvation_s
///    (after the first accepted one) is `degraded`;
///  - covariance growth: the body's largest position standard deviation
///    above max_position_sigma_m is `degraded`.

#include <deque>
#include <optional>
#include <string>
#include <vector>

#include "evio/core/io/health_txt.h"
#include "evio/core/io/status_yaml.h"
#include "evio/core/options.h"
#include "evio/estimator/backend/chi_squared.h"
#include "evio/estimator/measurements.h"
#include "evio/estimator/pipeline/stage.h"

namespace evio::estimator {

struct HealthOptions {
  bool enabled = true;                 ///< off: status.yaml reports numerical health only
  double window_s = 2.0;               ///< sliding window of data time, s
  int min_window_dof = 50;             ///< residual dimensions the window needs before ρ is judged
  double nis_probability = 0.999;      ///< Σ nis above its χ²(Σ dof) quantile of this: degraded
  double nis_diverged_ratio = 10.0;    ///< ρ = Σ nis / Σ dof above this: diverged
  /// Share of features a consistent filter's gates reject: 1 − their
  /// probability (backend slam_gate_probability, msckf_gate_probability: 0.95).
  double expected_rejected_share = 0.05;
  int min_window_features = 20;        ///< gated features the window needs before the share is judged
  double starvation_s = 1.0;           ///< no accepted feature for this long: degraded, s
  double max_position_sigma_m = 1.0;   ///< position standard deviation above this: degraded, m

  template <class V>
  void fields(V& v) {
    v("enabled", enabled, "judge the run's health from its innovations and covariance");
    v("window_s", window_s, "sliding window of data time, s");
    v("min_window_dof", min_window_dof, "residual dimensions the window needs before the ratio is judged");
    v("nis_probability", nis_probability, "sum(nis) above its chi-squared(sum(dof)) quantile of this: degraded");
    v("nis_diverged_ratio", nis_diverged_ratio, "innovation ratio sum(nis)/sum(dof) above which: diverged");
    v("expected_rejected_share", expected_rejected_share, "share of features a consistent filter's gates reject");
    v("min_window_features", min_window_features, "gated features the window needs before the share is judged");
    v("starvation_s", starvation_s, "no accepted feature for this long: degraded, s");
    v("max_position_sigma_m", max_position_sigma_m, "position standard deviation above which: degraded, m");
  }
  void validate() const;
};

/// A verdict of the self-diagnosis.
struct HealthVerdict {
  io::EstimateStatus::Code code = io::EstimateStatus::Code::kOk;  ///< kOk, kDegraded or kDiverged
  TimeNs t_ns = 0;       ///< first time the verdict held (IMU clock, as the estimates)
  std::string cause;     ///< one line
};

/// One visual update as the monitor sees it (a health.txt row): from an
/// Estimate while running, or read back from an estimate folder to judge it
/// again with other options (`evio health`).
io::HealthRow healthRow(const Estimate& e);

/// The smallest k with P(X ≤ k) ≥ probability for X ~ Binomial(n, p)
/// (exact sum of the probabilities, in logarithms).
long binomialQuantile(long n, double p, double probability);

class HealthMonitor : public Stage<Estimate, Estimate> {
 public:
  explicit HealthMonitor(const HealthOptions& options);
  /// Passes the estimate on unchanged after judging it.
  void process(Estimate& in, std::vector<Estimate>& out) override;
  /// Judges one update (rows in increasing time).
  void observe(const io::HealthRow& row);
  /// The worst verdict so far (the first diverged, else the first degraded, else ok).
  const HealthVerdict& verdict() const { return verdict_; }

 private:
  struct Update {
    TimeNs t_ns;
    double nis;  // accepted features only
    int dof;
    int accepted;
    int rejected;
  };

  void raise(io::EstimateStatus::Code code, TimeNs t_ns, const std::string& cause);
  void slideWindow(const io::HealthRow& row);
  void judgeInnovations(TimeNs t_ns);
  void judgeGatedOut(TimeNs t_ns);

  HealthOptions options_;
  Chi2Table chi2_;
  std::deque<Update> window_;
  double window_nis_ = 0.0;
  long window_dof_ = 0;
  long window_accepted_ = 0;
  long window_rejected_ = 0;
  std::optional<TimeNs> last_accepted_ns_;
  HealthVerdict verdict_;
};

}  // namespace evio::estimator
