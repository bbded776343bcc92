#pragma once
/// @file backend_scenarios.h
/// The three backend scenarios of the consistency tests: a DAVIS346-like
/// radtan camera (scenes/presets/preview_rig.yaml intrinsics), 1 px track
/// noise (σ_img = 1 px in the filter), the DAVIS240 reference IMU noise in
/// both simulator and filter, 20–30 Hz updates.
///  - six_dof: camera along B's x axis facing a landmark volume 2.5–8 m ahead;
///  - rotation_only: landmarks on a shell 3–12 m around the fixed camera;
///  - hover: camera looking down from 10 m on landmarks on Mars-like ground.

#include <yaml-cpp/yaml.h>

#include "backend_scenario.h"
#include "evio/trajectories/trajectory_factory.h"
#include "trajectory_presets.h"

namespace evio::test {

inline Camera scenarioCamera() {
  Eigen::VectorXd dist(5);
  dist << -0.08, 0.02, 0.0005, -0.0003, 0.0;
  return Camera::create("radtan", 346, 260, Vec4(300.0, 300.0, 172.5, 129.5), dist);
}

/// Camera z along B's x (forward), x along −y of B, y along −z of B, with a lever arm.
inline Pose forwardCamera() {
  Mat3 R_B_C;
  R_B_C.col(0) = Vec3(0, -1, 0);
  R_B_C.col(1) = Vec3(0, 0, -1);
  R_B_C.col(2) = Vec3(1, 0, 0);
  return Pose(R_B_C, Vec3(0.03, -0.01, 0.02));
}

/// Camera z along −z of B (down), x along B's x.
inline Pose downCamera() { return Pose(Mat3(Vec3(1.0, -1.0, -1.0).asDiagonal()), Vec3(0.02, 0.0, -0.05)); }

inline BackendScenario baseScenario(const ContinuousTrajectory& traj) {
  BackendScenario sc(scenarioCamera());
  sc.update_rate_hz = 20.0;
  sc.skip_s = 1.0;
  sc.imu.gravity_mps2 = YAML::Load(traj.configYaml())["gravity_mps2"].as<double>();
  sc.tracks.pixel_noise_px = 1.0;
  sc.backend.sigma_img_px = 1.0;
  sc.backend.use_rig_imu_noise = true;
  return sc;
}

/// The preset as shipped (60 s); scenarios run its first max_duration_s.
inline std::unique_ptr<ContinuousTrajectory> scenarioTrajectory(const std::string& preset) {
  return makeTrajectory(trajectoryPresetPath(preset + ".yaml"));
}

inline BackendScenario sixDofScenario(const ContinuousTrajectory& traj) {
  BackendScenario sc = baseScenario(traj);
  sc.T_B_C = forwardCamera();
  RandomStream rng(1, "landmarks");
  // Depths follow the depth prior of d_min = 2 m (ρ0 = 0.25, σ = 0.125 1/m),
  // truncated to 2–10 m, so that the prior is a true prior of this scene.
  sc.backend.slam_min_depth_m = 2.0;
  sc.landmarks_W = landmarksWithInverseDepth(0.25, 0.125, 0.1, 0.5, 1.0, 0.85, 8000, rng);
  sc.tracks.retrack_landmarks = false;
  return sc;
}

inline BackendScenario rotationOnlyScenario(const ContinuousTrajectory& traj) {
  BackendScenario sc = baseScenario(traj);
  sc.T_B_C = forwardCamera();
  sc.update_rate_hz = 30.0;
  RandomStream rng(2, "landmarks");
  // Depths follow the depth prior of d_min = 2 m, truncated to 2–10 m.
  sc.backend.slam_min_depth_m = 2.0;
  sc.landmarks_W = landmarksAroundWithInverseDepth(0.25, 0.125, 0.1, 0.5, 20000, rng);
  sc.tracks.retrack_landmarks = false;
  return sc;
}

inline BackendScenario hoverScenario(const ContinuousTrajectory& traj) {
  BackendScenario sc = baseScenario(traj);
  sc.T_B_C = downCamera();
  RandomStream rng(3, "landmarks");
  sc.landmarks_W = landmarksInBox(Vec3(-20, -20, -0.5), Vec3(20, 20, 0.5), 3000, rng);
  sc.backend.slam_min_depth_m = 5.0;
  return sc;
}

}  // namespace evio::test
