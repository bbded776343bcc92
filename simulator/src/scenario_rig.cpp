// Scenario options: validation and the sensor rig they describe.
#include <algorithm>
#include <cmath>

#include "evio/core/error.h"
#include "evio/simulator/scenario.h"

namespace evio::simulator {

namespace {

VecX toVecX(const std::vector<double>& v) {
  VecX out(static_cast<Eigen::Index>(v.size()));
  for (std::size_t i = 0; i < v.size(); ++i) out[static_cast<Eigen::Index>(i)] = v[i];
  return out;
}

/// Re-throws a camera error with the option path in front.
Camera createCamera(const std::string& field, std::string_view model, int width, int height, const Vec4& intrinsics,
                    const std::vector<double>& distortion) {
  try {
    return Camera::create(model, width, height, intrinsics, toVecX(distortion));
  } catch (const Error& e) {
    throw Error(field + "." + e.what());
  }
}

}  // namespace

Pose rigidFromMatrix(const Mat4& T, const std::string& field) {
  requireField(T.allFinite(), field, "must be finite");
  const Mat3 R = T.topLeftCorner<3, 3>();
  requireField((R.transpose() * R - Mat3::Identity()).cwiseAbs().maxCoeff() < 1e-6 && R.determinant() > 0.0, field,
               "the rotation block must be orthonormal with determinant +1");
  requireField((T.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).cwiseAbs().maxCoeff() < 1e-12, field,
               "the last row must be 0 0 0 1");
  // Re-orthonormalise to round-off so the pose is exactly rigid.
  return Pose(Quat(R).normalized(), T.topRightCorner<3, 1>());
}

void EventCameraRigOptions::validate() const {
  requireField(model == "pinhole" || model == "radtan", "model",
               "must be pinhole or radtan (calib.txt cannot hold '" + model + "')");
  // An empty preset (width 0) is allowed while the keys are being filled; the
  // scenario checks the camera as a whole (Scenario::eventCamera).
  if (sensor.width > 0 || sensor.height > 0) sensor.validate();
  rigidFromMatrix(T_B_E, "T_B_E");
}

void FrameCameraRigOptions::validate() const {
  requireInRange("rate_hz", rate_hz, 0.1, 1000.0);
  requireInRange("exposure_samples", exposure_samples, 1, 64);
  requireField(!name.empty(), "name", "must not be empty");
  sensor.validate();
  const double period_s = 1.0 / rate_hz;
  requireField(sensor.readout_s < period_s, "sensor.readout_s", "must be shorter than the frame period 1 / rate_hz");
  requireField(sensor.auto_exposure || sensor.exposure_s + sensor.readout_s <= period_s * (1.0 + 1e-9),
               "sensor.exposure_s", "plus sensor.readout_s must not exceed the frame period 1 / rate_hz");
  requireField(!sensor.auto_exposure || sensor.auto_exposure_min_s + sensor.readout_s < period_s,
               "sensor.auto_exposure_min_s", "plus sensor.readout_s must be shorter than the frame period 1 / rate_hz");
  if (!co_located) {
    createCamera("frame_camera", model, width, height, intrinsics, distortion);
    rigidFromMatrix(T_B_F, "T_B_F");
  }
}

void RangeFinderRigOptions::validate() const {
  requireInRange("rate_hz", rate_hz, 0.01, 100000.0);
  rigidFromMatrix(T_B_L, "T_B_L");
  requireNonNegative("min_range_m", min_range_m);
  requireField(max_range_m > min_range_m, "max_range_m", "must be > min_range_m");
  requireNonNegative("noise_sigma_m", noise_sigma_m);
}

namespace {
template <class O>
void validateIn(const char* section, const O& options) {
  try {
    options.validate();
  } catch (const Error& e) {
    throw Error(std::string(section) + "." + e.what());
  }
}
}  // namespace

void RigOptions::validate() const {
  validateIn("event_camera", event_camera);
  validateIn("frame_camera", frame_camera);
  validateIn("imu", imu);
  validateIn("range_finder", range_finder);
}

void RenderScheduleOptions::validate() const {
  requireInRange("lambda", lambda, 1e-3, 10.0);
  requireInRange("min_rate_hz", min_rate_hz, 1e-3, 1e5);  // a bound on the render count, not physics
  requireInRange("max_rate_hz", max_rate_hz, 1e-3, 1e5);
  requireField(max_rate_hz >= min_rate_hz, "max_rate_hz", "must be >= min_rate_hz");
  requireField(fastest_pixel_quantile > 0.0 && fastest_pixel_quantile <= 1.0, "fastest_pixel_quantile",
               "must be in (0, 1]");
  requireInRange("supersampling", supersampling, 1, 8);
  requireField(schedule == "whole_frame" || schedule == "tiles", "schedule", "must be whole_frame or tiles");
  requireField(tile_px == 0 || (tile_px >= 1 && tile_px <= 256), "tile_px", "must be 0 (by schedule) or in [1, 256]");
  requireField(tile_quantum_s == 0.0 || (tile_quantum_s >= 1e-6 && tile_quantum_s <= 1.0 / min_rate_hz),
               "tile_quantum_s", "must be 0 or in [1e-6, 1 / min_rate_hz] s");
}

TimeNs RenderScheduleOptions::tileQuantumNs() const {
  return std::max<TimeNs>(1, secondsToNs(tile_quantum_s > 0.0 ? tile_quantum_s : 1.0 / max_rate_hz));
}

void SequenceOutputOptions::validate() const {
  requireInRange("events_h5_compression", events_h5_compression, 0, 9);
  requireInRange("groundtruth_rate_hz", groundtruth_rate_hz, 1.0, 100000.0);
  requireInRange("truth_tracks", truth_tracks, 0, 1000000);
  requireNonNegative("truth_track_border_px", truth_track_border_px);
}

void ScenarioOptions::validate() const {
  requireInRange("start_s", start_s, 0.0, 1e6);  // times become int64 ns: far below 9.2e9 s
  requirePositive("duration_s", duration_s);
  requireInRange("duration_s", duration_s, 0.0, 1e6);
  requireInRange("threads", threads, 0, 1024);
  validateIn("rig", rig);
  validateIn("sampling", sampling);
  validateIn("output", output);
}

Camera Scenario::eventCamera() const {
  const auto& e = options.rig.event_camera;
  requireField(e.sensor.width > 0 && e.sensor.height > 0, "rig.event_camera.width",
               "the event camera needs a resolution (set `preset:` or width/height)");
  return createCamera("rig.event_camera", e.model, e.sensor.width, e.sensor.height, e.sensor.intrinsics, e.distortion);
}

Pose Scenario::T_B_E() const { return rigidFromMatrix(options.rig.event_camera.T_B_E, "rig.event_camera.T_B_E"); }

Camera Scenario::frameCamera() const {
  const auto& f = options.rig.frame_camera;
  if (f.co_located) return eventCamera();
  return createCamera("rig.frame_camera", f.model, f.width, f.height, f.intrinsics, f.distortion);
}

Pose Scenario::T_B_F() const {
  const auto& f = options.rig.frame_camera;
  return f.co_located ? T_B_E() : rigidFromMatrix(f.T_B_F, "rig.frame_camera.T_B_F");
}

SensorRig Scenario::sensorRig() const {
  const auto& r = options.rig;
  SensorRig rig;
  CameraSensor ev{"cam0", CameraRole::kEvent, eventCamera(), T_B_E(), {}};
  const auto& ec = r.event_camera.sensor.event_camera;
  ev.parameters = {{"contrast_threshold_pos", ec.threshold_pos},
                   {"contrast_threshold_neg", ec.threshold_neg},
                   {"threshold_mismatch_sigma", ec.threshold_mismatch_sigma},
                   {"refractory_period_s", ec.refractory_period_s},
                   {"pixel_pitch_um", r.event_camera.sensor.pixel_pitch_um}};
  rig.cameras.push_back(ev);
  if (r.frame_camera.enabled) {
    CameraSensor fr{r.frame_camera.name, CameraRole::kFrame, frameCamera(), T_B_F(), {}};
    fr.parameters = {{"co_located_with_cam0", r.frame_camera.co_located ? 1.0 : 0.0},
                     {"rate_hz", r.frame_camera.rate_hz},
                     {"exposure_samples", static_cast<double>(r.frame_camera.exposure_samples)},
                     {"auto_exposure", r.frame_camera.sensor.auto_exposure ? 1.0 : 0.0},
                     {"auto_exposure_davis", r.frame_camera.sensor.auto_exposure_method == "davis" ? 1.0 : 0.0},
                     {"exposure_s", r.frame_camera.sensor.exposure_s},
                     {"rolling_shutter", r.frame_camera.sensor.shutter == "rolling" ? 1.0 : 0.0},
                     {"readout_s", r.frame_camera.sensor.readout_s},
                     {"full_well_e", r.frame_camera.sensor.full_well_e},
                     {"dark_offset_dn", r.frame_camera.sensor.dark_offset_dn},
                     {"saturation_dn", r.frame_camera.sensor.saturation_dn}};
    rig.cameras.push_back(fr);
  }
  rig.imu.accelerometer_noise_density = r.imu.accelerometer_noise_density;
  rig.imu.accelerometer_random_walk = r.imu.accelerometer_random_walk;
  rig.imu.gyroscope_noise_density = r.imu.gyroscope_noise_density;
  rig.imu.gyroscope_random_walk = r.imu.gyroscope_random_walk;
  rig.imu.update_rate = r.imu.update_rate_hz;
  rig.gravity_m_s2 = r.imu.gravity_mps2;
  rig.time_offset_cam_imu_ns = secondsToNs(r.imu.timeshift_cam_imu_s);
  if (r.range_finder.enabled) {
    RangeFinderSensor rf;
    rf.T_B_L = rigidFromMatrix(r.range_finder.T_B_L, "rig.range_finder.T_B_L");
    rf.min_range_m = r.range_finder.min_range_m;
    rf.max_range_m = r.range_finder.max_range_m;
    rf.noise_sigma_m = r.range_finder.noise_sigma_m;
    rig.range_finder = rf;
  }
  rig.validate();
  return rig;
}

}  // namespace evio::simulator
