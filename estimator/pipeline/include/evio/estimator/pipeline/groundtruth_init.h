#pragma once
/// @file groundtruth_init.h
/// The paper's initialisation protocol (Mahlknecht et al. 2022, Experiments;
/// docs/algorithms.md#ground-truth-initialisation): the filter starts from the ground-truth pose and velocity
/// with zero IMU biases.
///
/// groundtruth.txt holds T_W_C(t), the camera (event camera) in W on the
/// camera clock. The body (IMU) state at camera time t is
///   T_W_B(t) = T_W_C(t) · T_B_C⁻¹,
/// with T_W_C(t) interpolated between the neighbouring poses (position
/// linearly, rotation by slerp), and the velocity of B by a central difference
///   v_W(t) = (p_W_B(t + h) − p_W_B(t − h)) / 2h,
/// the window [t − h, t + h] clipped to the span of the ground truth.

#include <cstdint>
#include <optional>
#include <string>

#include "evio/core/pose.h"
#include "evio/core/random_stream.h"
#include "evio/core/time.h"
#include "evio/estimator/measurements.h"

namespace evio::estimator {

/// T_W_C at t_ns, interpolated; throws evio::Error when t_ns is outside the
/// trajectory's span or the trajectory is empty.
Pose interpolatePose(const Trajectory& T_W_C, TimeNs t_ns);

/// The body state at camera time t_cam_ns from the camera trajectory T_W_C
/// (see the file comment). state.t_ns = t_cam_ns + time_offset_cam_imu_ns (the
/// IMU clock, as Backend::initialize wants it); biases zero.
ImuState initialStateFromTrajectory(const Trajectory& T_W_C, TimeNs t_cam_ns, const Pose& T_B_C,
                                    double half_window_s, TimeNs time_offset_cam_imu_ns = 0);

/// Standard deviations of the initial state's error: the backend's initial
/// covariance (BackendOptions::initial_sigma_*), in SI units.
struct InitialErrorSigmas {
  double p_m = 0.0;
  double v_mps = 0.0;
  double theta_rad = 0.0;   ///< per axis, body frame
  double bg_radps = 0.0;
  double ba_mps2 = 0.0;
};

/// x with an error drawn from N(0, diag(σ²)) in the backend's error-state
/// convention (filter_state.h): p + δp, v + δv, q · Exp(δθ) (δθ in B),
/// b_g + δb_g, b_a + δb_a; drawn in that order, three normals each.
/// A filter started from the perturbed truth has an initial error that is a
/// sample of its initial covariance, as a NEES test needs.
ImuState perturbInitialState(const ImuState& x, const InitialErrorSigmas& sigmas, RandomStream& rng);

/// Ground-truth initialisation as a run uses it: the initialisation time is
/// the first IMU reading's camera time (or the first ground-truth pose if
/// later) plus start_offset_s; the state comes from the ground truth read up
/// to that time plus the velocity half-window (memory flat in its length).
class GroundTruthInitializer {
 public:
  GroundTruthInitializer(std::string groundtruth_path, double start_offset_s, double velocity_half_window_s,
                         const Pose& T_B_C, TimeNs time_offset_cam_imu_ns);
  /// Offered each IMU reading's time (IMU clock) until it returns a state:
  /// the initial state once the readings reach the initialisation time, else
  /// nullopt. Throws evio::Error when the ground truth has no poses or ends
  /// before the initialisation time.
  std::optional<ImuState> offer(TimeNs t_imu_ns);
  /// From now on offer() returns the state perturbed by perturbInitialState
  /// with a stream of `seed` ("initial_state").
  void perturbWith(const InitialErrorSigmas& sigmas, std::uint64_t seed);

 private:
  std::string path_;
  double start_offset_s_;
  double half_window_s_;
  Pose T_B_C_;
  TimeNs offset_ns_;
  std::optional<TimeNs> t_init_cam_ns_;
  std::optional<InitialErrorSigmas> perturbation_;
  std::uint64_t perturbation_seed_ = 0;
};

/// Reads the beginning of a TUM file (groundtruth.txt), up to the first pose
/// after `t_until_ns` (all of it when the file ends earlier): memory stays
/// flat for long sequences.
Trajectory readTrajectoryPrefix(const std::string& path, TimeNs t_until_ns);

}  // namespace evio::estimator
