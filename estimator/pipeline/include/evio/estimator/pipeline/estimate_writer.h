#pragma once
/// @file estimate_writer.h
/// Writes an estimate folder (the layout `evio evaluate` reads,
/// experiments/estimate_files.h) through core/io, every file atomically:
///
///   trajectory.txt             TUM, T_W_E: the event camera in W, the frame of
///                              groundtruth.txt: T_W_E = T_W_B · T_B_E, on the
///                              camera clock t_cam = t_imu − time_offset_cam_imu
///   trajectory_covariance.txt  the same poses with covariances (ov_eval layout,
///                              core/io/tum.h): orientation block of δθ_E with
///                              R_W_E = R̂_W_E · Exp(δθ_E), position block of
///                              δp_W_E in W; from the IMU block Σ of the filter:
///                                δp_E = δp_B − R_W_B [p_B_E]× δθ_B,  δθ_E = R_B_Eᵀ δθ_B
///   imu_state.txt              the body state (core/io/imu_state_txt.h layout):
///                              p_W_B, q_W_B, v_W, biases; ω and a are not
///                              estimated and written as 0
///   timing.txt                 core/io/timing_txt.h (real-time factor)
///   health.txt                 core/io/health_txt.h: the innovations and
///                              feature counts of every visual update
///                              (self-diagnosis; output.health)
///   status.yaml                core/io/status_yaml.h
///   config.yaml                the resolved configuration
///   summary.yaml               per-stage wall-clock times and counters
///
/// Streams are kept open until finish(); nothing appears under its final
/// name before that (a killed run leaves no partial result).

#include <memory>
#include <string>
#include <vector>

#include "evio/core/io/health_txt.h"
#include "evio/core/io/imu_state_txt.h"
#include "evio/core/io/status_yaml.h"
#include "evio/core/io/timing_txt.h"
#include "evio/core/io/tum.h"
#include "evio/core/pose.h"
#include "evio/estimator/backend/backend_status.h"
#include "evio/estimator/pipeline/pipeline_options.h"

namespace evio::estimator {

/// The 6×6 covariance of [δp_W_E; δθ_E] of the camera E rigidly attached to B
/// at T_B_E, from the IMU covariance block (filter_state.h order) and R_W_B.
Mat6 cameraPoseCovariance(const Eigen::Matrix<double, 15, 15>& cov_imu, const Quat& q_W_B, const Pose& T_B_E);

class EstimateWriter {
 public:
  /// Creates `folder` when missing. `T_B_E`: the event camera of the rig;
  /// `header`: comment lines for the text files.
  EstimateWriter(std::string folder, const PipelineOutputOptions& options, const Pose& T_B_E,
                 TimeNs time_offset_cam_imu_ns, const std::vector<std::string>& header);
  ~EstimateWriter();
  EstimateWriter(const EstimateWriter&) = delete;
  EstimateWriter& operator=(const EstimateWriter&) = delete;

  /// One filter estimate (IMU clock). Estimates must come in increasing time;
  /// one not after the previous written one is skipped.
  void addEstimate(const Estimate& estimate);
  /// One timing.txt row (camera clock); see core/io/timing_txt.h.
  void addTiming(const io::TimingSample& sample);
  /// Writes status.yaml, config.yaml and summary.yaml and closes every stream.
  void finish(const io::EstimateStatus& status, const std::string& config_yaml, const std::string& summary_yaml);

  std::size_t numPoses() const { return num_poses_; }
  const std::string& folder() const { return folder_; }

 private:
  std::string folder_;
  PipelineOutputOptions options_;
  Pose T_B_E_;
  TimeNs offset_ns_;
  std::vector<std::string> header_;
  std::unique_ptr<io::TumWriter> trajectory_;
  std::unique_ptr<io::ImuStateWriter> imu_state_;
  std::unique_ptr<io::TimingWriter> timing_;
  std::unique_ptr<io::HealthWriter> health_;
  std::vector<io::StampedPoseCovariance> covariance_;  // no streaming writer in core/io: 20 doubles per pose
  std::size_t num_poses_ = 0;
  TimeNs last_t_ns_ = 0;
  bool finished_ = false;
};

}  // namespace evio::estimator
