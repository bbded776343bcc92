#include "evio/estimator/pipeline/groundtruth_init.h"

#include <algorithm>
#include <utility>

#include "evio/core/error.h"
#include "evio/core/io/tum.h"
#include "evio/core/so3.h"

namespace evio::estimator {

Pose interpolatePose(const Trajectory& T_W_C, TimeNs t_ns) {
  require(!T_W_C.empty(), "ground truth: no poses");
  if (t_ns < T_W_C.front().t_ns || t_ns > T_W_C.back().t_ns)
    throw Error("ground truth: time " + secondsText(t_ns, 6) + " outside its span [" +
                secondsText(T_W_C.front().t_ns, 6) + ", " + secondsText(T_W_C.back().t_ns, 6) + "]");
  const auto it = firstPoseAtOrAfter(T_W_C, t_ns);
  if (it->t_ns == t_ns) return it->pose;
  // Position linear, rotation by slerp (core/pose.h); the initial attitude is
  // normalised once more, as the estimator always did.
  const Pose T = evio::interpolatePose(*(it - 1), *it, t_ns);
  return Pose(T.quaternion().normalized(), T.translation());
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
    throw Error("ground truth: no span around " + secondsText(t_cam_ns, 6) + " to take the initial velocity from");
  const Vec3 pa = (interpolatePose(T_W_C, ta) * T_C_B).translation();
  const Vec3 pb = (interpolatePose(T_W_C, tb) * T_C_B).translation();
  ImuState x;
  x.t_ns = t_cam_ns + time_offset_cam_imu_ns;
  x.p_W_B = T_W_B.translation();
  x.q_W_B = T_W_B.quaternion();
  x.v_W = (pb - pa) / nsToSeconds(tb - ta);
  return x;
}

GroundTruthInitializer::GroundTruthInitializer(std::string groundtruth_path, double start_offset_s,
                                               double velocity_half_window_s, const Pose& T_B_C,
                                               TimeNs time_offset_cam_imu_ns)
    : path_(std::move(groundtruth_path)),
      start_offset_s_(start_offset_s),
      half_window_s_(velocity_half_window_s),
      T_B_C_(T_B_C),
      offset_ns_(time_offset_cam_imu_ns) {}

std::optional<ImuState> GroundTruthInitializer::offer(TimeNs t_imu_ns) {
  const TimeNs t_cam_ns = t_imu_ns - offset_ns_;
  if (!t_init_cam_ns_) {
    const Trajectory head = readTrajectoryPrefix(path_, t_cam_ns);
    if (head.empty()) throw Error(path_ + ": no poses");
    t_init_cam_ns_ = std::max(t_cam_ns, head.front().t_ns) + secondsToNs(start_offset_s_);
  }
  if (t_cam_ns < *t_init_cam_ns_) return std::nullopt;
  const Trajectory gt = readTrajectoryPrefix(path_, *t_init_cam_ns_ + secondsToNs(half_window_s_));
  if (gt.back().t_ns < *t_init_cam_ns_)
    throw Error(path_ + ": ends at " + secondsText(gt.back().t_ns) + ", before the initialisation time " +
                secondsText(*t_init_cam_ns_));
  const ImuState x = initialStateFromTrajectory(gt, *t_init_cam_ns_, T_B_C_, half_window_s_, offset_ns_);
  if (!perturbation_) return x;
  RandomStream rng(perturbation_seed_, "initial_state");
  return perturbInitialState(x, *perturbation_, rng);
}

void GroundTruthInitializer::perturbWith(const InitialErrorSigmas& sigmas, std::uint64_t seed) {
  perturbation_ = sigmas;
  perturbation_seed_ = seed;
}

ImuState perturbInitialState(const ImuState& x, const InitialErrorSigmas& sigmas, RandomStream& rng) {
  const auto draw = [&rng](double sigma) -> Vec3 {
    const double a = rng.normal(), b = rng.normal(), c = rng.normal();  // sequenced: a, b, c
    return Vec3(a, b, c) * sigma;
  };
  ImuState out = x;
  out.p_W_B += draw(sigmas.p_m);
  out.v_W += draw(sigmas.v_mps);
  out.q_W_B = (x.q_W_B * so3::expQuat(draw(sigmas.theta_rad))).normalized();
  out.b_g += draw(sigmas.bg_radps);
  out.b_a += draw(sigmas.ba_mps2);
  return out;
}

Trajectory readTrajectoryPrefix(const std::string& path, TimeNs t_until_ns) {
  io::TumReader reader(path);
  Trajectory out;
  StampedPose p;
  while (reader.next(p)) {
    if (!out.empty() && p.t_ns <= out.back().t_ns)
      throw Error(path + ": time does not increase at " + secondsText(p.t_ns, 6));
    out.push_back(p);
    if (p.t_ns > t_until_ns) break;
  }
  return out;
}

}  // namespace evio::estimator
