#pragma once
/// @file continuous_trajectory.h
/// Continuous-time motion of the body (IMU) frame B in the world frame W
/// (z up, gravity along −z), with exact derivatives at any time.

#include <string>

#include "evio/core/eigen_types.h"
#include "evio/core/pose.h"
#include "evio/core/time.h"
#include "evio/trajectories/taylor.h"

namespace evio {

/// The exact kinematic state of B at one time.
struct TrajectoryState {
  TimeNs t_ns = 0;
  Pose T_W_B;                       ///< pose of B in W (maps points from B into W)
  Vec3 v_W = Vec3::Zero();          ///< velocity of B's origin in W, m/s: d/dt p_W_B
  Vec3 a_W = Vec3::Zero();          ///< acceleration of B's origin in W, m/s²: d²/dt² p_W_B
  Vec3 omega_B = Vec3::Zero();      ///< angular velocity of B w.r.t. W in B, rad/s: [ω]x = R_W_Bᵀ Ṙ_W_B
  Vec3 alpha_B = Vec3::Zero();      ///< angular acceleration in B, rad/s²: α_B = d/dt ω_B
};

/// A motion B(t) defined on [startTime(), endTime()], at least twice
/// continuously differentiable in position and attitude (so the IMU it
/// implies is continuous). Every derivative is exact (closed form).
class ContinuousTrajectory {
 public:
  virtual ~ContinuousTrajectory() = default;

  /// State at time t_ns; throws evio::Error outside [startTime(), endTime()].
  TrajectoryState evaluate(TimeNs t_ns) const;

  TimeNs startTime() const { return start_ns_; }
  TimeNs endTime() const { return end_ns_; }

  /// The resolved configuration that built this trajectory (YAML, every
  /// field including defaults, `type` first), to be written next to outputs.
  virtual std::string configYaml() const = 0;

 protected:
  ContinuousTrajectory(TimeNs start_ns, TimeNs end_ns);

  /// Position p_W_B and attitude R_W_B as order-2 Taylor series about
  /// t_s = seconds since startTime().
  struct Motion {
    taylor::Vector3<2> p_W;
    taylor::Matrix3<2> R_W_B;
  };
  virtual Motion motion(double t_s) const = 0;

 private:
  TimeNs start_ns_;
  TimeNs end_ns_;
};

}  // namespace evio
