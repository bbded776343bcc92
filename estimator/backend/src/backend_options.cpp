#include "evio/estimator/backend/backend_options.h"

#include <string>

#include "evio/core/error.h"

namespace evio::estimator {

void BackendOptions::validate() const {
  // Upper bounds on sizes keep a typo from exhausting memory or time: the state
  // grows by 6 per window pose and 3 per SLAM feature, its covariance quadratically.
  requireField(window_size >= 2 && window_size <= 200, "window_size", "must be in [2, 200]");
  requireInRange("keyframe_interval_s", keyframe_interval_s, 0.0, 10.0);
  requireField(max_slam_features >= 0 && max_slam_features <= 1000, "max_slam_features", "must be in [0, 1000]");
  requirePositive("sigma_img_px", sigma_img_px);
  requireNonNegative("sigma_img_normalized", sigma_img_normalized);
  requireNonNegative("accelerometer_noise_density", accelerometer_noise_density);
  requireNonNegative("accelerometer_random_walk", accelerometer_random_walk);
  requireNonNegative("gyroscope_noise_density", gyroscope_noise_density);
  requireNonNegative("gyroscope_random_walk", gyroscope_random_walk);
  requirePositive("imu_max_acc_mps2", imu_max_acc_mps2);
  requirePositive("imu_max_gap_s", imu_max_gap_s);
  requireField(imu_fail_gap_s >= imu_max_gap_s, "imu_fail_gap_s", "must be >= imu_max_gap_s");
  requireNonNegative("initial_sigma_p_m", initial_sigma_p_m);
  requireNonNegative("initial_sigma_v_mps", initial_sigma_v_mps);
  requireNonNegative("initial_sigma_theta_deg", initial_sigma_theta_deg);
  requireNonNegative("initial_sigma_bg_degps", initial_sigma_bg_degps);
  requireNonNegative("initial_sigma_ba_mps2", initial_sigma_ba_mps2);
  requirePositive("slam_min_depth_m", slam_min_depth_m);
  // A fresh depth-prior feature has σ_ρ/ρ = 1/2: at 1/2 or above it would count as converged at once.
  requireField(map_prior_max_relative_sigma > 0.0 && map_prior_max_relative_sigma < 0.5,
               "map_prior_max_relative_sigma", "must be in (0, 0.5)");
  requireField(map_prior_memory >= 1 && map_prior_memory <= 100000, "map_prior_memory", "must be in [1, 100000]");
  requireField(map_prior_min_points >= 1, "map_prior_min_points", "must be >= 1");
  requireField(slam_min_track_length >= 1, "slam_min_track_length", "must be >= 1");
  requireField(slam_min_track_span_s >= 0.0 && slam_min_track_span_s <= 60.0, "slam_min_track_span_s", "must be in [0, 60] s");
  requireField(slam_gate_probability > 0.0 && slam_gate_probability < 1.0, "slam_gate_probability",
               "must be in (0, 1)");
  requireField(slam_max_gate_failures >= 1, "slam_max_gate_failures", "must be >= 1");
  requireInRange("slam_update_interval_s", slam_update_interval_s, 0.0, 60.0);
  requireInRange("slam_update_min_displacement_normalized", slam_update_min_displacement_normalized, 0.0, 1.0);
  requireInRange("slam_fixed_prior_wait_s", slam_fixed_prior_wait_s, 0.0, 1e9);
  requireNonNegative("slam_prior_track_min_parallax_px", slam_prior_track_min_parallax_px);
  requireField(slam_prior_track_iterations >= 1 && slam_prior_track_iterations <= 50, "slam_prior_track_iterations",
               "must be in [1, 50]");
  requireField(!slam_prior_track_update || slam_prior_init_with_track, "slam_prior_track_update",
               "needs slam_prior_init_with_track: true");
  requireField(slam_prior_track_iterations == 1 || slam_prior_track_update, "slam_prior_track_iterations",
               "above 1 needs slam_prior_track_update: true");
  requireField(slam_scene_depth_share >= 0.0 && slam_scene_depth_share < 1.0, "slam_scene_depth_share",
               "must be in [0, 1)");
  requireField(slam_scene_depth_memory_s > 0.0 && slam_scene_depth_memory_s <= 1e9, "slam_scene_depth_memory_s",
               "must be in (0, 1e9]");
  requireInRange("slam_bearing_walk_px2_per_s", slam_bearing_walk_px2_per_s, 0.0, 1e6);
  requireInRange("slam_track_error_sigma_px", slam_track_error_sigma_px, 0.0, 100.0);
  requirePositive("slam_track_error_time_s", slam_track_error_time_s);
  requireInRange("slam_image_shift_sigma_px", slam_image_shift_sigma_px, 0.0, 100.0);
  requireField(slam_image_shift_time_s > 0.0 && slam_image_shift_time_s <= 60.0, "slam_image_shift_time_s",
               "must be in (0, 60]");
  requireField(msckf_min_track_length >= 2, "msckf_min_track_length", "must be >= 2");
  requireNonNegative("min_parallax_px", min_parallax_px);
  requireNonNegative("slam_min_parallax_px", slam_min_parallax_px);
  requireField(msckf_gate_probability > 0.0 && msckf_gate_probability < 1.0, "msckf_gate_probability",
               "must be in (0, 1)");
  requireField(triangulation_max_iterations >= 1 && triangulation_max_iterations <= 1000, "triangulation_max_iterations",
               "must be in [1, 1000]");
  requirePositive("triangulation_tolerance", triangulation_tolerance);
  requirePositive("triangulation_min_depth_m", triangulation_min_depth_m);
  requireField(iekf_iterations >= 1 && iekf_iterations <= 100, "iekf_iterations", "must be in [1, 100]");
  requireField(msckf_iterations >= 1 && msckf_iterations <= 100, "msckf_iterations", "must be in [1, 100]");
  requireInRange("visual_covariance_factor", visual_covariance_factor, 1.0, 100.0);
  requireField(msckf_iterations == 1 || iekf_iterations == 1, "msckf_iterations",
               "iterating the MSCKF rows needs iekf_iterations = 1 (the SLAM rows then stay linearised once)");
  requireInRange("max_delay_s", max_delay_s, 0.0, 60.0);  // measurements wait this long in memory
  requireNonNegative("max_late_s", max_late_s);
  requirePositive("max_velocity_mps", max_velocity_mps);
  requireInRange("covariance_check_interval_s", covariance_check_interval_s, 0.0, 60.0);
  requireNonNegative("range_sigma_m", range_sigma_m);
  requireNonNegative("range_prior_relative_sigma", range_prior_relative_sigma);
  requireNonNegative("range_prior_max_age_s", range_prior_max_age_s);
  requireInRange("range_max_feature_angle_deg", range_max_feature_angle_deg, 0.0, 90.0);
  requirePositive("zero_velocity_sigma_mps", zero_velocity_sigma_mps);
  requirePositive("static_window_s", static_window_s);
  requireInRange("static_window_s", static_window_s, 0.0, 3600.0);  // the IMU window is buffered
  requirePositive("static_max_acc_std_mps2", static_max_acc_std_mps2);
  requirePositive("static_max_gyro_std_radps", static_max_gyro_std_radps);
}

ImuNoiseDensities BackendOptions::imuNoise(const ImuSensor& rig_imu) const {
  if (use_rig_imu_noise)
    return {rig_imu.accelerometer_noise_density, rig_imu.accelerometer_random_walk,
            rig_imu.gyroscope_noise_density, rig_imu.gyroscope_random_walk};
  return {accelerometer_noise_density, accelerometer_random_walk, gyroscope_noise_density, gyroscope_random_walk};
}

BackendSensors BackendSensors::fromRig(const SensorRig& rig, std::string_view camera_name) {
  const CameraSensor* cam = nullptr;
  if (!camera_name.empty()) {
    cam = rig.findCamera(camera_name);
    if (cam == nullptr) throw Error("backend: camera '" + std::string(camera_name) + "' is not in the rig");
  } else {
    cam = rig.firstCamera(CameraRole::kEvent);
    if (cam == nullptr && !rig.cameras.empty()) cam = &rig.cameras.front();
    if (cam == nullptr) throw Error("backend: the rig has no camera");
  }
  BackendSensors s{cam->camera, cam->T_B_C, rig.gravity_m_s2, rig.imu, rig.range_finder, rig.time_offset_cam_imu_ns};
  return s;
}

}  // namespace evio::estimator
