#include "evio/estimator/pipeline/groundtruth_init.h"

#include <algorithm>

#include "evio/core/error.h"
#include "evio/core/io/tum.h"

namespace evio::estimator {

namespace {

std::string secondsText(TimeNs t_ns) { return std::to_string(nsToSeconds(t_ns)) + " s"; }

}  // namespace

Pose interpolatePose(const Trajectory& T_W_C, TimeNs t_ns) {
  require(!T_W_C.empty(), "ground truth: no poses");
  if (t_ns < T_W_C.front().t_ns || t_ns > T_W_C.back().t_ns)
    throw Error("ground truth: time " + secondsText(t_ns) + " outside its span [" + secondsText(T_W_C.front().t_ns) +
                ", " + secondsText(T_W_C.back().t_ns) + "]");
  const auto it = std::lower_bound(T_W_C.begin(), T_W_C.end(), t_ns,
                                   [](const StampedPose& p, TimeNs t) { return p.t_ns < t; });
  if (it->t_ns == t_ns) return it->pose;
  const StampedPose& b = *it;
  const StampedPose& a = *(it - 1);
  const double s = static_cast<double>(t_ns - a.t_ns) / static_cast<double>(b.t_ns - a.t_ns);
  const Vec3 p = (1.0 - s) * a.pose.translation() + s * b.pose.translation();
  const Quat q = a.pose.quaternion().slerp(s, b.pose.quaternion());
  return Pose(q.normalized(), p);
}

ImuState initialStateFromTrajectory(const Trajectory& T_W_C, TimeNs t_cam_ns, const Pose& T_B_C,
                                    double half_window_s, TimeNs time_offset_cam_imu_ns) {
  require(half_window_s > 0.0, "initialStateFromTrajectory: half_window_s must be > 0");
  const Pose T_C_B = T_B_C.inverse();
  const Pose T_W_B = interpolatePose(T_W_C, t_cam_ns) * T_C_B;
  const TimeNs h = secondsToNs(half_window_s);
  const TimeNs ta = std::max(T_W_C.front().t_ns, t_cam_ns - h);
  const TimeNs tb = std::min(T_W_C.back().t_ns, t_cam_ns + h);
  if (tb <= ta)
    throw Error("ground truth: no span around " + secondsText(t_cam_ns) + " to take the initial velocity from");
  const Vec3 pa = (interpolatePose(T_W_C, ta) * T_C_B).translation();
  const Vec3 pb = (interpolatePose(T_W_C, tb) * T_C_B).translation();
  ImuState x;
  x.t_ns = t_cam_ns + time_offset_cam_imu_ns;
  x.p_W_B = T_W_B.translation();
  x.q_W_B = T_W_B.quaternion();
  x.v_W = (pb - pa) / nsToSeconds(tb - ta);
  return x;
}

Trajectory readTrajectoryPrefix(const std::string& path, TimeNs t_until_ns) {
  io::TumReader reader(path);
  Trajectory out;
  StampedPose p;
  while (reader.next(p)) {
    if (!out.empty() && p.t_ns <= out.back().t_ns)
      throw Error(path + ": time does not increase at " + secondsText(p.t_ns));
    out.push_back(p);
    if (p.t_ns > t_until_ns) break;
  }
  return out;
}

}  // namespace evio::estimator
