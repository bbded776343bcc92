#include "evio/experiments/trajectory_errors.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace evio::experiments {

namespace {
constexpr double kDegPerRad = 180.0 / std::numbers::pi;
}

ErrorStats errorStats(std::vector<double> values) {
  ErrorStats s;
  s.count = values.size();
  if (values.empty()) return s;
  double sum = 0.0, sum2 = 0.0;
  for (double v : values) {
    sum += v;
    sum2 += v * v;
    s.max = std::max(s.max, v);
  }
  const double n = static_cast<double>(values.size());
  s.mean = sum / n;
  s.rmse = std::sqrt(sum2 / n);
  const std::size_t mid = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(mid), values.end());
  s.median = values[mid];
  if (values.size() % 2 == 0) {
    const double below = *std::max_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(mid));
    s.median = 0.5 * (s.median + below);
  }
  return s;
}

std::vector<PoseError> poseErrors(const Association& association, const Alignment& alignment) {
  std::vector<PoseError> out;
  out.reserve(association.poses.size());
  double distance = 0.0;
  for (std::size_t k = 0; k < association.poses.size(); ++k) {
    const AssociatedPose& a = association.poses[k];
    if (k > 0) distance += (a.T_W_gt.translation() - association.poses[k - 1].T_W_gt.translation()).norm();
    const Pose es = alignment.transform.apply(a.T_W_es);
    PoseError e;
    e.t_ns = a.t_ns;
    e.distance_m = distance;
    e.p_gt = a.T_W_gt.translation();
    e.p_es = es.translation();
    e.position_m = (e.p_gt - e.p_es).norm();
    const Mat3 dR = es.rotation() * a.T_W_gt.rotation().transpose();  // R̂ R_gtᵀ, in W
    e.rotation_deg = angleBetween(es.quaternion(), a.T_W_gt.quaternion()) * kDegPerRad;
    e.yaw_deg = yawOf(dR) * kDegPerRad;
    const Vec3 z = dR.col(2);  // dR · e_z
    e.gravity_deg = std::atan2(z.head<2>().norm(), z.z()) * kDegPerRad;
    out.push_back(e);
  }
  return out;
}

PaperMetrics paperMetrics(const std::vector<PoseError>& errors, double groundtruth_length_m) {
  PaperMetrics m;
  m.groundtruth_length_m = groundtruth_length_m;
  if (errors.empty()) return m;
  for (const auto& e : errors) {
    m.mean_position_m += e.position_m;
    m.mean_rotation_deg += e.rotation_deg;
    m.mean_yaw_deg += std::fabs(e.yaw_deg);
  }
  const double n = static_cast<double>(errors.size());
  m.mean_position_m /= n;
  m.mean_rotation_deg /= n;
  m.mean_yaw_deg /= n;
  const double L = groundtruth_length_m > 0.0 ? groundtruth_length_m : std::numeric_limits<double>::quiet_NaN();
  m.mpe_percent = 100.0 * m.mean_position_m / L;
  m.mre_deg_per_m = m.mean_rotation_deg / L;
  m.mye_deg_per_m = m.mean_yaw_deg / L;
  return m;
}

AteMetrics absoluteTrajectoryError(const std::vector<PoseError>& errors) {
  std::vector<double> p, r;
  p.reserve(errors.size());
  r.reserve(errors.size());
  for (const auto& e : errors) {
    p.push_back(e.position_m);
    r.push_back(e.rotation_deg);
  }
  return {errorStats(std::move(p)), errorStats(std::move(r))};
}

DriftMetrics driftMetrics(const std::vector<PoseError>& errors, double window_s) {
  DriftMetrics d;
  if (errors.empty()) return d;
  const TimeNs t_last = errors.back().t_ns;
  const TimeNs t_from = t_last - secondsToNs(window_s);
  std::size_t n = 0;
  for (auto it = errors.rbegin(); it != errors.rend() && it->t_ns >= t_from; ++it, ++n) {
    d.final_position_m += it->position_m;
    d.final_rotation_deg += it->rotation_deg;
  }
  d.final_position_m /= static_cast<double>(n);
  d.final_rotation_deg /= static_cast<double>(n);
  const double minutes = nsToSeconds(t_last - errors.front().t_ns) / 60.0;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  d.position_m_per_min = minutes > 0.0 ? d.final_position_m / minutes : nan;
  d.rotation_deg_per_min = minutes > 0.0 ? d.final_rotation_deg / minutes : nan;
  return d;
}

}  // namespace evio::experiments
