#pragma once
/// @file trajectory_export.h
/// What `evio trajectory <preset.yaml> -o <folder>` does: writes a trajectory
/// and the IMU it implies as a (partial) sequence folder:
///   groundtruth.txt       TUM `t px py pz qx qy qz qw`: pose of B (the IMU) in W,
///                         or of the camera C when T_B_C is given, at groundtruth_rate_hz
///   imu.txt               `t ax ay az gx gy gz`, the synthesised IMU (imu_simulator.h)
///   truth/imu_state.txt   the true state and biases at every IMU sample (core/io/imu_state_txt.h)
///   trajectory.yaml       the resolved configuration: `trajectory:` (the preset,
///                         every field), `export:` (these options, IMU included), seed
/// The plot (trajectory.png) is drawn afterwards by
/// experiments/plots/plot_trajectory.py <folder>.
/// Same preset, options and seed ⇒ byte-identical files.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "evio/core/pose.h"
#include "evio/simulator/imu_simulator.h"
#include "evio/trajectories/continuous_trajectory.h"

namespace evio {

struct TrajectoryExportOptions {
  /// The IMU. When exporting a preset file, gravity_mps2 is taken from the
  /// preset's gravity_mps2 unless set explicitly (`--set imu.gravity_mps2=…`).
  ImuSimulator::Options imu;
  /// Rate of groundtruth.txt, Hz (the Event-Camera Dataset's motion capture: 200 Hz).
  double groundtruth_rate_hz = 200.0;

  template <class V>
  void fields(V& v) {
    v("imu", imu, "the IMU (Kalibr names)");
    v("groundtruth_rate_hz", groundtruth_rate_hz, "rate of groundtruth.txt, Hz");
  }
  void validate() const;
};

/// Counts of what was written.
struct TrajectoryExportSummary {
  std::int64_t groundtruth_poses = 0;
  std::int64_t imu_samples = 0;
  std::vector<std::string> files;  ///< paths written, in order
};

/// Writes the files listed above into `folder` (created if missing; existing
/// files are replaced atomically). `seed` seeds the IMU noise streams. With
/// `T_B_C`, groundtruth.txt holds T_W_C = T_W_B · T_B_C.
TrajectoryExportSummary exportTrajectory(const ContinuousTrajectory& trajectory,
                                         const TrajectoryExportOptions& options, std::uint64_t seed,
                                         const std::string& folder,
                                         const std::optional<Pose>& T_B_C = std::nullopt);

/// The `evio trajectory` command: builds the trajectory of `preset_yaml`
/// (trajectory_factory.h) and exports it with its own seed. Overrides
/// "key=value" go to the preset, except those starting with "imu." or
/// "export." which set TrajectoryExportOptions ("imu.update_rate_hz=200",
/// "export.groundtruth_rate_hz=100"). Throws evio::Error with file:line or
/// --set context on bad input.
TrajectoryExportSummary exportTrajectoryPreset(const std::string& preset_yaml, const std::string& folder,
                                               const std::vector<std::string>& overrides = {});

}  // namespace evio
