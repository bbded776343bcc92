#pragma once
/// @file sensors_yaml.h
/// sensors.yaml: the whole sensor rig of a sequence (core/sensor_rig.h).
///
///   cameras:
///     - name: cam0
///       role: event                     # event | frame
///       model: radtan                   # pinhole | radtan | equidistant
///       resolution: [240, 180]          # width, height in pixels
///       intrinsics: [fx, fy, cx, cy]    # pixels
///       distortion_coeffs: [k1, k2, p1, p2, k3]   # radtan; equidistant: [k1, k2, k3, k4];
///                                                 # pinhole: [] or absent
///       T_B_C:                          # 4×4 rigid transform, rows (Kalibr style);
///         - [r00, r01, r02, tx]         # a flat list of 16 (row-major) is also read
///         - [r10, r11, r12, ty]
///         - [r20, r21, r22, tz]
///         - [0, 0, 0, 1]
///       parameters: {contrast_threshold_pos: 0.2}   # optional open set of scalars
///   imu:                                # Kalibr names and units
///     accelerometer_noise_density: 0.0028   # m/s²/√Hz
///     accelerometer_random_walk: 0.00086    # m/s³/√Hz
///     gyroscope_noise_density: 0.00016      # rad/s/√Hz
///     gyroscope_random_walk: 2.2e-05        # rad/s²/√Hz
///     update_rate: 1000                     # Hz
///   gravity_m_s2: 3.721
///   timeshift_cam_imu: 0.0              # s, optional (0): t_imu = t_cam + timeshift
///   range_finder:                       # optional
///     T_B_L: <4×4 as T_B_C>
///     min_range_m: 0.1
///     max_range_m: 100
///     noise_sigma_m: 0.02
///
/// Reading rejects unknown or duplicate keys, missing required keys, wrong
/// types, non-finite numbers, negative noise densities and transforms that
/// are not rigid (rotation block orthonormal within 1e-6 with determinant +1,
/// last row 0 0 0 1 within 1e-12), each as evio::Error "file:line: field: ...".
/// Writing prints every double with the shortest text that reads back to the
/// same double, and replaces the file atomically.

#include <string>

#include "evio/core/sensor_rig.h"

namespace evio::io {

/// Reads and validates a sensors.yaml file.
SensorRig readSensorsYaml(const std::string& path);

/// Parses sensors.yaml text; `name` stands for the file in messages.
SensorRig parseSensorsYaml(const std::string& text, const std::string& name = "<string>");

/// The rig as sensors.yaml text. Validates the rig first (throws evio::Error).
std::string formatSensorsYaml(const SensorRig& rig);

/// Writes formatSensorsYaml(rig) to `path` atomically.
void writeSensorsYaml(const std::string& path, const SensorRig& rig);

}  // namespace evio::io
