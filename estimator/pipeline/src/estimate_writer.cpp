#include "evio/estimator/pipeline/estimate_writer.h"

#include <filesystem>

#include "evio/core/error.h"
#include "evio/core/io/atomic_file.h"
#include "evio/core/so3.h"
#include "evio/estimator/pipeline/health_monitor.h"

namespace evio::estimator {

namespace fs = std::filesystem;

Mat6 cameraPoseCovariance(const Eigen::Matrix<double, 15, 15>& cov_imu, const Quat& q_W_B, const Pose& T_B_E) {
  // [δp_E; δθ_E] = J [δp; δv; δθ; δb_g; δb_a] with
  //   δp_E = δp − R_W_B [p_B_E]× δθ   (p_W_E = p_W_B + R_W_B p_B_E, R_W_B ← R_W_B Exp(δθ))
  //   δθ_E = R_B_Eᵀ δθ                 (R_W_E = R_W_B Exp(δθ) R_B_E = R_W_E Exp(R_B_Eᵀ δθ))
  Eigen::Matrix<double, 6, 15> J = Eigen::Matrix<double, 6, 15>::Zero();
  J.block<3, 3>(0, kIdxP).setIdentity();
  J.block<3, 3>(0, kIdxTheta) = -q_W_B.toRotationMatrix() * so3::hat(T_B_E.translation());
  J.block<3, 3>(3, kIdxTheta) = T_B_E.rotation().transpose();
  Mat6 S = J * cov_imu * J.transpose();
  return 0.5 * (S + S.transpose());
}

EstimateWriter::EstimateWriter(std::string folder, const PipelineOutputOptions& options, const Pose& T_B_E,
                               TimeNs time_offset_cam_imu_ns, const std::vector<std::string>& header)
    : folder_(std::move(folder)), options_(options), T_B_E_(T_B_E), offset_ns_(time_offset_cam_imu_ns),
      header_(header) {
  options_.validate();
  std::error_code ec;
  fs::create_directories(folder_, ec);
  if (!fs::is_directory(folder_)) throw Error(folder_ + ": cannot create the output folder");
  const auto path = [&](const char* name) { return (fs::path(folder_) / name).string(); };
  std::vector<std::string> tum_header = header_;
  tum_header.push_back("pose of the event camera E in the world W (T_W_E); t px py pz qx qy qz qw");
  trajectory_ = std::make_unique<io::TumWriter>(path("trajectory.txt"), tum_header);
  if (options_.imu_state) {
    std::vector<std::string> h = header_;
    h.push_back("estimated body (IMU) state; omega and a are not estimated (0)");
    h.push_back("t px py pz qx qy qz qw vx vy vz wx wy wz ax ay az bax bay baz bgx bgy bgz");
    imu_state_ = std::make_unique<io::ImuStateWriter>(path("imu_state.txt"), h);
  }
  timing_ = std::make_unique<io::TimingWriter>(path("timing.txt"));
  if (options_.health) {
    std::vector<std::string> h = header_;
    h.push_back("innovations of each visual update; t nis dof accepted rejected slam msckf sigma_p_m nis_accepted dof_accepted");
    health_ = std::make_unique<io::HealthWriter>(path("health.txt"), h);
  }
}

EstimateWriter::~EstimateWriter() = default;

void EstimateWriter::addEstimate(const Estimate& e) {
  require(!finished_, "EstimateWriter: estimate after finish()");
  const TimeNs t = e.t_ns - offset_ns_;
  if (num_poses_ > 0 && t <= last_t_ns_) return;
  last_t_ns_ = t;
  ++num_poses_;
  const Pose T_W_E = e.T_W_B * T_B_E_;
  trajectory_->append(StampedPose{t, T_W_E});
  if (options_.covariance) {
    const Mat6 S = cameraPoseCovariance(e.cov_imu, e.T_W_B.quaternion(), T_B_E_);
    io::StampedPoseCovariance c;
    c.t_ns = t;
    c.pose = T_W_E;
    c.cov_position = S.topLeftCorner<3, 3>();
    c.cov_orientation = S.bottomRightCorner<3, 3>();
    covariance_.push_back(c);
  }
  if (health_) {
    io::HealthRow row = healthRow(e);
    row.t_ns = t;  // camera clock, as trajectory.txt
    health_->append(row);
  }
  if (imu_state_) {
    io::ImuTruthState s;
    s.t_ns = t;
    s.T_W_B = e.T_W_B;
    s.v_W = e.imu.v_W;
    s.accel_bias = e.imu.b_a;
    s.gyro_bias = e.imu.b_g;
    imu_state_->append(s);
  }
}

void EstimateWriter::addTiming(const io::TimingSample& sample) {
  require(!finished_, "EstimateWriter: timing after finish()");
  timing_->append(sample);
}

void EstimateWriter::finish(const io::EstimateStatus& status, const std::string& config_yaml,
                            const std::string& summary_yaml) {
  require(!finished_, "EstimateWriter: finish() twice");
  finished_ = true;
  const auto path = [&](const char* name) { return (fs::path(folder_) / name).string(); };
  trajectory_->close();
  if (options_.covariance) io::writeTumCovariance(path("trajectory_covariance.txt"), covariance_, header_);
  if (imu_state_) imu_state_->close();
  if (health_) health_->close();
  timing_->close();
  io::writeFileAtomic(path("config.yaml"), config_yaml);
  io::writeFileAtomic(path("summary.yaml"), summary_yaml);
  io::writeStatusYaml(path("status.yaml"), status);  // last: its presence marks a complete run
}

}  // namespace evio::estimator
