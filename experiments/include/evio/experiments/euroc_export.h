#pragma once
/// @file euroc_export.h
/// `evio export <sequence> --format euroc`: a sequence folder in the
/// EuRoC/ASL layout with Kalibr calibration files, so that frame-based VIO
/// peers (OpenVINS, VINS, OKVIS, …) run on our synthetic sequences.
///
///   <out>/mav0/cam0/data.csv      "#timestamp [ns],filename", one row per frame
///   <out>/mav0/cam0/data/<t_ns>.png
///   <out>/mav0/cam0/sensor.yaml   EuRoC camera description (T_BS = T_B_C)
///   <out>/mav0/imu0/data.csv      "#timestamp [ns],w_RS_S_x..z [rad s^-1],a_RS_S_x..z [m s^-2]"
///                                 (gyroscope before accelerometer, unlike imu.txt)
///   <out>/mav0/imu0/sensor.yaml
///   <out>/mav0/state_groundtruth_estimate0/data.csv
///       "#timestamp, p_RS_R_x..z [m], q_RS_w,x,y,z [], v_RS_R_x..z [m s^-1],
///        b_w_RS_S_x..z [rad s^-1], b_a_RS_S_x..z [m s^-2]": the body (IMU) pose
///       T_W_B with the quaternion w first. From truth/imu_state.txt when present
///       (velocity and biases exact); otherwise T_W_B = T_W_E · T_B_E⁻¹ from
///       groundtruth.txt (E the event camera whose pose it holds), velocity by
///       central differences and zero biases (a warning says so).
///   <out>/camchain.yaml           Kalibr camera–IMU chain (OpenVINS' kalibr_imucam_chain.yaml):
///       cam0: T_cam_imu (= T_B_C⁻¹: maps IMU points into the camera), camera_model,
///       intrinsics, distortion_model/coeffs, resolution, rostopic, timeshift_cam_imu
///   <out>/imu.yaml                Kalibr IMU (OpenVINS' kalibr_imu_chain.yaml): imu0 noise
///       densities and random walks, update_rate, and the intrinsics OpenVINS
///       requires (Tw, R_IMUtoGYRO, Ta, R_IMUtoACC identity; Tg zero)
///   <out>/estimator_config.yaml   OpenVINS: gravity_mag (the sequence's gravity) and the
///       paths of imu.yaml and camchain.yaml
///   <out>/mav0/body.yaml, mav0/state_groundtruth_estimate0/sensor.yaml   as in EuRoC
///   <out>/evio_export.yaml        what was exported from where, gravity, warnings
/// Every YAML file starts with "%YAML:1.0" as EuRoC's do, so OpenCV's
/// cv::FileStorage (OpenVINS, VINS) reads it. A gravity other than 9.81 m/s²
/// is a warning: EuRoC has no field for it and peers assume Earth's.
/// cam0 is the first frame camera of sensors.yaml (or the one named by
/// options.camera). Kalibr's radtan has four coefficients: a non-zero k3 is
/// dropped with a warning. Memory stays flat: IMU and ground truth stream.

#include <string>
#include <vector>

namespace evio::experiments {

struct EurocExportOptions {
  std::string camera;  ///< camera of sensors.yaml for cam0; empty: the first frame camera
};

struct EurocExportSummary {
  std::size_t frames = 0;
  std::size_t imu_samples = 0;
  std::size_t groundtruth_poses = 0;
  bool groundtruth_from_imu_state = false;
  std::vector<std::string> warnings;
};

/// Exports `sequence` into `folder` (created). Throws evio::Error for a
/// missing or malformed input file, or a sequence without frames.
EurocExportSummary exportEuroc(const std::string& sequence, const std::string& folder,
                               const EurocExportOptions& options = {});

}  // namespace evio::experiments
