#pragma once
/// @file backend_scenario.h
/// Runs the backend on a simulated trajectory with exact-model IMU
/// (simulator/imu_simulator.h, Kalibr noise model) and noisy ground-truth
/// tracks (gt_tracks.h), and scores every estimate against the truth:
///   pose error e = [p − p̂; Log(R̂ᵀ R)] (the backend's right-perturbation
///   convention, filter_state.h), NEES = eᵀ Σ⁻¹ e with Σ = cov_pose_B.
/// The initial state is the truth perturbed by a draw from the initial
/// covariance (velocity, attitude), the true IMU biases start at a draw from
/// the initial bias covariance while the filter starts at zero bias (the
/// paper's protocol), so the initial error is distributed as the filter
/// assumes. Streams: RandomStream(seed, "initial_state"), the simulator's IMU
/// streams and the tracks' "gt_tracks".

#include <cmath>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Cholesky>

#include "evio/core/random_stream.h"
#include "evio/core/so3.h"
#include "evio/estimator/backend/backend.h"
#include "evio/simulator/imu_simulator.h"
#include "evio/trajectories/continuous_trajectory.h"
#include "gt_tracks.h"

namespace evio::test {

struct BackendScenario {
  explicit BackendScenario(Camera c) : camera(std::move(c)) {}
  Camera camera;
  Pose T_B_C = Pose();
  std::vector<Vec3> landmarks_W;
  GtTrackOptions tracks;
  ImuSimulator::Options imu;
  estimator::BackendOptions backend;
  double update_rate_hz = 20.0;
  double skip_s = 0.0;  ///< estimates before start + skip_s are not scored
  double max_duration_s = 1e9;  ///< the run stops this long after the start
  /// A laser range finder measuring to the plane z = 0 of W at every update
  /// (noise σ 0.02 m, RandomStream(seed, "range")), when set.
  std::optional<Pose> T_B_L;
};

struct ScenarioResult {
  estimator::BackendStatus status;
  estimator::BackendStats stats;
  std::vector<double> t_s;        ///< time of each scored estimate since the start
  std::vector<double> nees;       ///< pose NEES (6 dof) per scored estimate
  std::vector<Vec6> error;        ///< [δp; δθ]
  std::vector<Vec6> sigma;        ///< sqrt of the diagonal of cov_pose_B
  std::vector<double> yaw_sigma;  ///< σ of the world-frame yaw e_zᵀ R_W_B δθ, rad
  std::vector<Vec3> velocity_error;  ///< v − v̂, m/s
  std::vector<Vec3> velocity_sigma;  ///< m/s
  /// Per measurement set: mean over the SLAM features of |d̂ − d|/d, d the depth
  /// of the true landmark in the feature's (estimated) anchor camera.
  std::vector<double> slam_depth_rel_error;
  bool always_pd = true;          ///< every scored pose covariance positive definite
  double max_error_over_3sigma = 0.0;  ///< max over estimates and components of |e_i| / (3 σ_i)
  int slam_features_max = 0;
};

inline ScenarioResult runBackendScenario(const ContinuousTrajectory& traj, const BackendScenario& sc,
                                         std::uint64_t seed) {
  using namespace estimator;
  RandomStream init_rng(seed, "initial_state");
  const BackendOptions& bo = sc.backend;
  constexpr double kDeg = M_PI / 180.0;
  auto draw3 = [&init_rng](double sigma) -> Vec3 { return Vec3(init_rng.normal(), init_rng.normal(), init_rng.normal()) * sigma; };

  ImuSimulator::Options imu = sc.imu;
  imu.gyroscope_initial_bias_radps = draw3(bo.initial_sigma_bg_degps * kDeg);
  imu.accelerometer_initial_bias_mps2 = draw3(bo.initial_sigma_ba_mps2);
  ImuSimulator sim(traj, imu, seed);

  BackendSensors sensors{sc.camera, sc.T_B_C, imu.gravity_mps2, ImuSensor{}, std::nullopt, 0};
  constexpr double kRangeSigma = 0.02;
  if (sc.T_B_L) sensors.range_finder = RangeFinderSensor{*sc.T_B_L, 0.1, 100.0, kRangeSigma};
  RandomStream range_rng(seed, "range");
  sensors.imu.accelerometer_noise_density = imu.accelerometer_noise_density;
  sensors.imu.accelerometer_random_walk = imu.accelerometer_random_walk;
  sensors.imu.gyroscope_noise_density = imu.gyroscope_noise_density;
  sensors.imu.gyroscope_random_walk = imu.gyroscope_random_walk;
  sensors.imu.update_rate = imu.update_rate_hz;
  Backend backend(bo, sensors);

  const TrajectoryState x0 = traj.evaluate(traj.startTime());
  ImuState init;
  init.t_ns = x0.t_ns;
  init.p_W_B = x0.T_W_B.translation() + draw3(bo.initial_sigma_p_m);
  init.v_W = x0.v_W + draw3(bo.initial_sigma_v_mps);
  init.q_W_B = x0.T_W_B.quaternion() * so3::expQuat(draw3(bo.initial_sigma_theta_deg * kDeg));
  backend.initialize(init);

  GroundTruthTracks tracks(sc.landmarks_W, sc.camera, sc.T_B_C, sc.tracks, seed);
  const TimeNs period = static_cast<TimeNs>(std::llround(1e9 / sc.update_rate_hz));
  TimeNs next_update = traj.startTime() + period;
  const TimeNs skip_ns = traj.startTime() + secondsToNs(sc.skip_s);

  ScenarioResult out;
  auto score = [&](const Estimate& e) {
    out.slam_features_max = std::max(out.slam_features_max, e.num_slam_features);
    if (e.t_ns < skip_ns) return;
    const TrajectoryState truth = traj.evaluate(e.t_ns);
    Vec6 err;
    err.head<3>() = truth.T_W_B.translation() - e.T_W_B.translation();
    err.tail<3>() = so3::log(Quat(e.T_W_B.quaternion().conjugate() * truth.T_W_B.quaternion()));
    const Eigen::LLT<Mat6> llt(e.cov_pose_B);
    if (llt.info() != Eigen::Success) {
      out.always_pd = false;
      return;
    }
    const Vec6 sig = e.cov_pose_B.diagonal().cwiseSqrt();
    out.t_s.push_back(nsToSeconds(e.t_ns - traj.startTime()));
    out.nees.push_back(err.dot(llt.solve(err)));
    out.error.push_back(err);
    out.sigma.push_back(sig);
    out.velocity_error.push_back(truth.v_W - e.imu.v_W);
    out.velocity_sigma.push_back(e.cov_imu.diagonal().segment<3>(3).cwiseSqrt());
    const Vec3 u = e.T_W_B.rotation().transpose() * Vec3::UnitZ();  // δψ = e_zᵀ R δθ = uᵀ δθ
    out.yaw_sigma.push_back(std::sqrt(u.dot(e.cov_pose_B.bottomRightCorner<3, 3>() * u)));
    out.max_error_over_3sigma =
        std::max(out.max_error_over_3sigma, (err.cwiseAbs().array() / (3.0 * sig.array())).maxCoeff());
  };

  ImuMeasurement m;
  const TimeNs stop_ns = traj.startTime() + secondsToNs(std::min(sc.max_duration_s, 1e6));
  while (sim.next(m) && m.sample.t_ns <= stop_ns) {
    backend.addImu(m.sample);
    while (next_update <= m.sample.t_ns && next_update <= traj.endTime()) {
      const Pose T_W_B = traj.evaluate(next_update).T_W_B;
      backend.addMeasurementSet(tracks.measure(next_update, T_W_B));
      const FilterState& st = backend.state();
      double sum = 0.0;
      int count = 0;
      for (const SlamFeature& f : st.features) {
        const Vec3* landmark = tracks.landmarkOf(f.id);
        const int a = st.findClone(f.anchor_clone_id);
        if (landmark == nullptr || a < 0 || !(f.abr.z() > 0.0)) continue;
        const CameraClone& anchor = st.clones[static_cast<std::size_t>(a)];
        const double depth = (anchor.R_W_C().transpose() * (*landmark - anchor.p_W_C)).z();
        sum += std::abs(1.0 / f.abr.z() - depth) / depth;
        ++count;
      }
      if (count > 0) out.slam_depth_rel_error.push_back(sum / count);
      if (sc.T_B_L) {
        const Pose T_W_L = T_W_B * *sc.T_B_L;
        const Vec3 d = T_W_L.rotation().col(2);
        const double range = -T_W_L.translation().z() / d.z();  // to the plane z = 0
        backend.addRange(next_update, range + range_rng.normal() * kRangeSigma);
      }
      next_update += period;
    }
    for (const Estimate& e : backend.takeEstimates()) score(e);
    if (!backend.status().ok()) break;
  }
  out.status = backend.status();
  out.stats = backend.stats();
  return out;
}

}  // namespace evio::test
