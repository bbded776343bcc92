#include "evio/experiments/relative_pose_error.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

#include "evio/core/error.h"

namespace evio::experiments {

namespace {

constexpr double kDegPerRad = 180.0 / std::numbers::pi;

std::string label(double value, const char* unit) {
  char buf[48];
  std::snprintf(buf, sizeof(buf), "%g%s", value, unit);
  std::string s = buf;
  std::replace(s.begin(), s.end(), '.', '_');
  return s;
}

RpeLength rpeForLength(const std::vector<Pose>& gt, const std::vector<Pose>& es, const std::vector<double>& d,
                       double L, double tolerance) {
  RpeLength r;
  r.length_m = L;
  std::vector<double> trans, yaw, grav;
  for (std::size_t i = 0; i < d.size(); ++i) {
    const double target = d[i] + L;
    const auto it = std::lower_bound(d.begin() + static_cast<std::ptrdiff_t>(i), d.end(), target);
    std::size_t j = static_cast<std::size_t>(it - d.begin());
    if (j == d.size() || (j > i && std::fabs(d[j - 1] - target) < std::fabs(d[j] - target))) --j;
    if (j <= i || std::fabs(d[j] - target) > tolerance * L) continue;
    const Pose E = (gt[i].inverse() * gt[j]).inverse() * (es[i].inverse() * es[j]);
    const Mat3 R_w = gt[i].rotation() * E.rotation() * gt[i].rotation().transpose();
    trans.push_back(100.0 * E.translation().norm() / L);
    yaw.push_back(std::fabs(yawOf(R_w)) * kDegPerRad);
    const Vec3 z = R_w.col(2);
    grav.push_back(std::atan2(z.head<2>().norm(), z.z()) * kDegPerRad);
  }
  r.translation_percent = errorStats(std::move(trans));
  r.yaw_deg = errorStats(std::move(yaw));
  r.yaw_deg_per_m = r.yaw_deg.mean / L;
  r.gravity_deg = errorStats(std::move(grav));
  return r;
}

}  // namespace

void RpeOptions::validate() const {
  for (double p : lengths_percent) requireField(p > 0.0 && p <= 100.0, "lengths_percent", "each in (0, 100]");
  for (double m : lengths_m) requirePositive("lengths_m", m);
  requireInRange("tolerance", tolerance, 0.0, 1.0);
}

std::vector<RpeLength> relativePoseError(const Association& association, const Alignment& alignment,
                                         double groundtruth_length_m, const RpeOptions& options) {
  options.validate();
  const auto& poses = association.poses;
  std::vector<Pose> gt, es;
  std::vector<double> d;
  gt.reserve(poses.size());
  es.reserve(poses.size());
  d.reserve(poses.size());
  double distance = 0.0;
  for (std::size_t k = 0; k < poses.size(); ++k) {
    if (k > 0) distance += (poses[k].T_W_gt.translation() - poses[k - 1].T_W_gt.translation()).norm();
    gt.push_back(poses[k].T_W_gt);
    es.push_back(alignment.transform.apply(poses[k].T_W_es));
    d.push_back(distance);
  }
  std::vector<RpeLength> out;
  for (double p : options.lengths_percent) {
    const double L = p / 100.0 * groundtruth_length_m;
    RpeLength r;
    if (L > 0.0) r = rpeForLength(gt, es, d, L, options.tolerance);
    r.label = label(p, "pct");
    r.length_m = L;
    out.push_back(r);
  }
  for (double L : options.lengths_m) {
    RpeLength r = rpeForLength(gt, es, d, L, options.tolerance);
    r.label = label(L, "m");
    out.push_back(r);
  }
  return out;
}

}  // namespace evio::experiments
