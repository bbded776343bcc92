#pragma once
/// @file health_txt.h
/// `health.txt` of an estimate folder: one row per visual update, what the
/// estimator's self-diagnosis sees (docs/evaluation.md#self-diagnosis):
///
///   t nis dof accepted rejected slam msckf sigma_p_m nis_accepted dof_accepted
///
/// t in s (camera clock, as trajectory.txt); nis the sum of the gated
/// features' normalised innovations squared rᵀ S⁻¹ r and dof their residual
/// dimensions (E[nis] = dof for a consistent filter); accepted / rejected the
/// features the χ² gates let in or turned away; slam / msckf the SLAM
/// features in the state and the MSCKF features used; sigma_p_m the largest
/// position standard deviation of the body, m; nis_accepted / dof_accepted
/// the part of nis and dof from the accepted features. Written atomically.
/// Files written before the last two columns existed read with
/// nis_accepted = nis and dof_accepted = dof.

#include <string>
#include <vector>

#include "evio/core/io/timed_table.h"
#include "evio/core/time.h"

namespace evio::io {

struct HealthRow {
  TimeNs t_ns = 0;
  double nis = 0.0;
  int dof = 0;
  int accepted = 0;
  int rejected = 0;
  int slam = 0;
  int msckf = 0;
  double sigma_p_m = 0.0;
  double nis_accepted = 0.0;
  int dof_accepted = 0;
};

/// Streams rows to `path` (atomically published by close()).
class HealthWriter {
 public:
  explicit HealthWriter(std::string path, const std::vector<std::string>& header = {});
  void append(const HealthRow& row);
  void close();

 private:
  TimedTableWriter table_;
};

/// Reads a whole health.txt (errors name file, line and column).
std::vector<HealthRow> readHealthText(const std::string& path);

}  // namespace evio::io
