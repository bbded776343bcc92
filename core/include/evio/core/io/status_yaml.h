#pragma once
/// @file status_yaml.h
/// `status.yaml`: how an estimator run ended, written by the estimator beside
/// its trajectory and read by `evio evaluate` (divergence, completion) and by
/// campaigns (success rates). Divergence is a status, not an abort.
///
///   status: diverged          # ok | degraded | diverged | failed (required)
///   time_s: 12.345            # data time (sequence clock, s) of the divergence
///                             # or failure; required unless status is ok
///   cause: "velocity above 100 m/s"   # one line; optional ("" when ok)
///   initialization_time_s: 0.5        # optional: data time the estimator
///                                     # initialised at
///
/// Unknown and duplicate keys, a missing status, an unknown status name and
/// non-finite times are evio::Error "file:line: field: ...". Written atomically.

#include <optional>
#include <string>
#include <string_view>

#include "evio/core/time.h"

namespace evio::io {

struct EstimateStatus {
  /// kDegraded: the run went on to the end, but the estimator's
  /// self-diagnosis judged its estimate unreliable from t_ns on.
  enum class Code { kOk, kDegraded, kDiverged, kFailed };
  Code code = Code::kOk;
  std::optional<TimeNs> t_ns;                 ///< time of divergence/failure (sequence clock)
  std::string cause;                          ///< one line
  std::optional<TimeNs> initialization_t_ns;  ///< time the estimator initialised

  bool ok() const { return code == Code::kOk; }
  friend bool operator==(const EstimateStatus&, const EstimateStatus&) = default;
};

/// "ok", "degraded", "diverged" or "failed".
std::string_view estimateStatusName(EstimateStatus::Code code);

/// Inverse of estimateStatusName; throws evio::Error "status: ..." otherwise.
EstimateStatus::Code parseEstimateStatusName(std::string_view name);

EstimateStatus readStatusYaml(const std::string& path);
EstimateStatus parseStatusYaml(const std::string& text, const std::string& name = "<string>");
std::string formatStatusYaml(const EstimateStatus& status);
/// Validates (time given unless ok, cause one line) and writes atomically.
void writeStatusYaml(const std::string& path, const EstimateStatus& status);

}  // namespace evio::io
