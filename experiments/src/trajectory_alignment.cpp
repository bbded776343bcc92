#include "evio/experiments/trajectory_alignment.h"

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <cmath>
#include <cstdio>

#include "evio/core/error.h"

namespace evio::experiments {

namespace {

/// The rotation maximising trace(R·C) for `type` (posyaw: R = Rz(θ)).
Mat3 bestRotation(const Mat3& C, AlignmentType type, Mat3* svd_D_S = nullptr) {
  if (type == AlignmentType::kPosYaw) return rotationZ(std::atan2(C(0, 1) - C(1, 0), C(0, 0) + C(1, 1)));
  const Eigen::JacobiSVD<Mat3> svd(C.transpose(), Eigen::ComputeFullU | Eigen::ComputeFullV);
  Mat3 S = Mat3::Identity();
  if (svd.matrixU().determinant() * svd.matrixV().determinant() < 0.0) S(2, 2) = -1.0;
  if (svd_D_S) *svd_D_S = svd.singularValues().asDiagonal() * S;
  return svd.matrixU() * S * svd.matrixV().transpose();
}

}  // namespace

std::string alignmentTypeName(AlignmentType type) {
  switch (type) {
    case AlignmentType::kPosYaw: return "posyaw";
    case AlignmentType::kSe3: return "se3";
    case AlignmentType::kSim3: return "sim3";
    case AlignmentType::kNone: return "none";
  }
  return "none";
}

AlignmentType parseAlignmentType(const std::string& name) {
  if (name == "posyaw") return AlignmentType::kPosYaw;
  if (name == "se3") return AlignmentType::kSe3;
  if (name == "sim3") return AlignmentType::kSim3;
  if (name == "none") return AlignmentType::kNone;
  throw Error("alignment: must be posyaw, se3, sim3 or none (got '" + name + "')");
}

void AlignmentOptions::validate() const {
  requireField(type == "posyaw" || type == "se3" || type == "sim3" || type == "none", "type",
               "must be posyaw, se3, sim3 or none (got '" + type + "')");
  requireField(window == "all" || window == "first" || window == "time", "window",
               "must be all, first or time (got '" + window + "')");
  if (window == "first") requireField(first_n >= 1, "first_n", "must be >= 1 for window first");
  if (window == "time") {
    requireField(std::isfinite(start_s) && std::isfinite(end_s), "start_s", "must be finite");
    requireField(end_s > start_s, "end_s", "must be > start_s for window time");
  }
  requireNonNegative("min_spread_m", min_spread_m);
}

AlignmentOptions AlignmentOptions::paper() {
  AlignmentOptions o;
  o.type = "posyaw";
  o.window = "time";
  o.start_s = 3.0;
  o.end_s = 8.0;
  return o;
}

Pose Similarity::apply(const Pose& T) const { return Pose(Mat3(R * T.rotation()), apply(T.translation())); }

Pose Similarity::applyInverse(const Pose& T) const {
  return Pose(Mat3(R.transpose() * T.rotation()), Vec3(R.transpose() * (T.translation() - t) / scale));
}

std::string Alignment::describe() const {
  if (type == AlignmentType::kNone) return "none";
  char buf[160];
  const std::string name = alignmentTypeName(type);
  if (options.window == "all")
    std::snprintf(buf, sizeof(buf), "%s on all poses (%zu)", name.c_str(), poses_used);
  else if (options.window == "first")
    std::snprintf(buf, sizeof(buf), "%s on the first %d poses (%zu)", name.c_str(), options.first_n, poses_used);
  else
    std::snprintf(buf, sizeof(buf), "%s on t0+%g..%g s (%zu poses)", name.c_str(), options.start_s, options.end_s,
                  poses_used);
  return std::string(buf) + (rotation_from_orientation ? ", rotation from orientations" : "");
}

Similarity umeyama(const std::vector<Vec3>& x, const std::vector<Vec3>& y, AlignmentType type) {
  require(!x.empty() && x.size() == y.size(), "umeyama: point sets empty or of unequal size");
  Similarity out;
  if (type == AlignmentType::kNone) return out;
  const double n = static_cast<double>(x.size());
  Vec3 mx = Vec3::Zero(), my = Vec3::Zero();
  for (std::size_t k = 0; k < x.size(); ++k) {
    mx += x[k];
    my += y[k];
  }
  mx /= n;
  my /= n;
  Mat3 C = Mat3::Zero();
  double var_x = 0.0;
  for (std::size_t k = 0; k < x.size(); ++k) {
    C += (x[k] - mx) * (y[k] - my).transpose();
    var_x += (x[k] - mx).squaredNorm();
  }
  Mat3 DS = Mat3::Zero();
  out.R = bestRotation(C, type, &DS);
  if (type == AlignmentType::kSim3) {
    require(var_x > 0.0, "umeyama: sim3 needs positions with spread");
    out.scale = DS.trace() / var_x;
  }
  out.t = my - out.scale * out.R * mx;
  return out;
}

Alignment align(const Association& association, TimeNs groundtruth_start_ns, const AlignmentOptions& options) {
  options.validate();
  Alignment a;
  a.options = options;
  a.type = parseAlignmentType(options.type);
  const auto& poses = association.poses;
  std::vector<std::size_t> window;
  const TimeNs t_start = groundtruth_start_ns + secondsToNs(options.start_s);
  const TimeNs t_end = groundtruth_start_ns + secondsToNs(options.end_s);
  for (std::size_t k = 0; k < poses.size(); ++k) {
    if (options.window == "first" && k >= static_cast<std::size_t>(options.first_n)) break;
    if (options.window == "time" && (poses[k].t_ns < t_start || poses[k].t_ns > t_end)) continue;
    window.push_back(k);
  }
  if (a.type == AlignmentType::kNone) {
    a.poses_used = 0;
    return a;
  }
  if (window.empty()) {
    char buf[200];
    if (options.window == "time")
      std::snprintf(buf, sizeof(buf),
                    "alignment: no associated pose in the window t0+%g..%g s (t0 = first ground-truth time %.3f s)",
                    options.start_s, options.end_s, nsToSeconds(groundtruth_start_ns));
    else
      std::snprintf(buf, sizeof(buf), "alignment: no associated pose in the window '%s'", options.window.c_str());
    throw Error(buf);
  }
  a.poses_used = window.size();
  a.window_start_s = nsToSeconds(poses[window.front()].t_ns);
  a.window_end_s = nsToSeconds(poses[window.back()].t_ns);

  std::vector<Vec3> x, y;
  x.reserve(window.size());
  y.reserve(window.size());
  for (std::size_t k : window) {
    x.push_back(poses[k].T_W_es.translation());
    y.push_back(poses[k].T_W_gt.translation());
  }
  // Is the rotation determined by the positions? Only if both trajectories
  // spread: an estimate drifting while the truth stands still (a hover, a
  // rotation in place) would otherwise choose the rotation from its drift.
  const auto mean = [](const std::vector<Vec3>& points) {
    Vec3 m = Vec3::Zero();
    for (const auto& p : points) m += p;
    return Vec3(m / static_cast<double>(points.size()));
  };
  const auto spreads = [&](const std::vector<Vec3>& points) {
    const Vec3 m = mean(points);
    Mat3 scatter = Mat3::Zero();
    for (const auto& p : points) scatter += (p - m) * (p - m).transpose();
    scatter /= static_cast<double>(points.size());
    if (a.type == AlignmentType::kPosYaw)  // the horizontal RMS spread
      return std::sqrt(std::max(0.0, scatter(0, 0) + scatter(1, 1))) >= options.min_spread_m;
    const Eigen::SelfAdjointEigenSolver<Mat3> es(scatter, Eigen::EigenvaluesOnly);
    return std::sqrt(std::max(0.0, es.eigenvalues()(1))) >= options.min_spread_m;  // a plane: 2nd of ascending
  };
  const Vec3 mx = mean(x);
  const bool determined = spreads(x) && spreads(y);
  if (determined) {
    a.transform = umeyama(x, y, a.type);
    return a;
  }
  if (a.type == AlignmentType::kSim3)
    throw Error("alignment: sim3 needs positions that span a plane in the window (RMS spread below " +
                std::to_string(options.min_spread_m) + " m)");
  Mat3 M = Mat3::Zero();
  for (std::size_t k : window) M += poses[k].T_W_es.rotation() * poses[k].T_W_gt.rotation().transpose();
  a.rotation_from_orientation = true;
  a.transform.R = bestRotation(M, a.type);
  a.transform.t = mean(y) - a.transform.R * mx;
  return a;
}

double yawOf(const Mat3& R) { return std::atan2(R(1, 0), R(0, 0)); }

Mat3 rotationZ(double theta_rad) {
  const double c = std::cos(theta_rad), s = std::sin(theta_rad);
  Mat3 R;
  R << c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0;
  return R;
}

}  // namespace evio::experiments
