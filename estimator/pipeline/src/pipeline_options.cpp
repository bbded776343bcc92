#include "evio/estimator/pipeline/pipeline_options.h"

#include <cmath>
#include <string>

#include "evio/core/error.h"
#include "evio/core/options.h"

namespace evio::estimator {

void InitOptions::validate() const {
  requireField(mode == "groundtruth" || mode == "static", "mode",
               "must be groundtruth or static (got '" + mode + "'" +
                   (mode == "auto" ? "; auto is gone: ground truth is used only when asked for" : "") + ")");
  requireNonNegative("start_offset_s", start_offset_s);
  requirePositive("velocity_half_window_s", velocity_half_window_s);
  requireField(!perturb || mode == "groundtruth", "perturb", "needs mode groundtruth (it perturbs the ground-truth start)");
  requireNonNegative("gyro_bias_window_s", gyro_bias_window_s);
  requireField(gyro_bias_window_s == 0.0 || mode == "groundtruth", "gyro_bias_window_s",
               "needs mode groundtruth (static initialisation takes the bias from the still window)");
  requirePositive("gyro_bias_keyframe_s", gyro_bias_keyframe_s);
  requireField(gyro_bias_window_s == 0.0 || gyro_bias_keyframe_s * 3.0 <= gyro_bias_window_s, "gyro_bias_keyframe_s",
               "at most a third of gyro_bias_window_s (the estimate needs two keyframe pairs)");
  requireNonNegative("gyro_bias_window_rest_prefix_s", gyro_bias_window_rest_prefix_s);
  requirePositive("gyro_bias_window_rest_block_s", gyro_bias_window_rest_block_s);
  requireField(gyro_bias_window_rest_prefix_s == 0.0 || gyro_bias_window_rest_prefix_s >= 2.0 * gyro_bias_window_rest_block_s,
               "gyro_bias_window_rest_prefix_s", "0 or at least two blocks (2 x gyro_bias_window_rest_block_s)");
  requireField(gyro_bias_window_sigma == "prior" || gyro_bias_window_sigma == "window", "gyro_bias_window_sigma",
               "must be prior or window (got '" + gyro_bias_window_sigma + "')");
}

void CalibrationOptions::validate() const {
  requireField(T_B_C.allFinite(), "T_B_C", "must be finite");
  const Mat3 R = T_B_C.topLeftCorner<3, 3>();
  requireField((R.transpose() * R - Mat3::Identity()).cwiseAbs().maxCoeff() < 1e-6 && R.determinant() > 0.0, "T_B_C",
               "rotation block must be orthonormal with determinant +1 (within 1e-6)");
  requireField((T_B_C.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).cwiseAbs().maxCoeff() < 1e-12, "T_B_C",
               "last row must be 0 0 0 1");
  requirePositive("gravity_mps2", gravity_mps2);
  requireInRange("time_offset_cam_imu_s", time_offset_cam_imu_s, -1.0, 1.0);
  requirePositive("imu_rate_hz", imu_rate_hz);
  requireInRange("imu_rate_hz", imu_rate_hz, 0.0, 1e5);
  requireField(width >= 0 && height >= 0, "width", "width and height must be >= 0");
  requireField(width <= 65536 && height <= 65536, "width", "width and height must be <= 65536");
  requireField((width == 0) == (height == 0), "width", "width and height must both be 0 or both > 0");
}

void TracksInputOptions::validate() const {
  requireField(!file.empty(), "file", "must not be empty");
  requireNonNegative("noise_px", noise_px);
  requireInRange("rate_hz", rate_hz, 0.0, 1e5);  // measurement sets per second
  requirePositive("max_gap_s", max_gap_s);
}

void PipelineOutputOptions::validate() const {
  requirePositive("timing_interval_s", timing_interval_s);
  requireField(timing_clock == "wall" || timing_clock == "cpu", "timing_clock",
               "must be wall or cpu (got '" + timing_clock + "')");
}

void PipelineOptions::validate() const {
  const std::optional<Method> m = parseMethod(method);
  requireField(m.has_value(), "method", "must be one of " + methodNames() + " (got '" + method + "')");
  validateSection("frontend", frontend);
  validateSection("sync", sync);
  validateSection("backend", backend);
  validateSection("init", init);
  validateSection("calibration", calibration);
  validateSection("tracks", tracks);
  validateSection("health", health);
  validateSection("output", output);
  const MethodInfo& info = methodInfo(*m);
  if (*info.tracker)
    requireField(frontend.tracker == info.tracker, "frontend.tracker",
                 std::string("must be ") + info.tracker + " for method " + method + " (got '" + frontend.tracker +
                     "')");
  if (*info.tracker && !info.reads_events)
    requireField(sync.trigger != "events", "sync.trigger",
                 "must be track_time or fixed_rate for method " + method + " (" + info.tracker +
                     " reads no events)");
}

Method PipelineOptions::methodKind() const {
  const std::optional<Method> m = parseMethod(method);
  if (!m) throw Error("method: must be one of " + methodNames() + " (got '" + method + "')");
  return *m;
}

PipelineOptions PipelineOptions::forMethod(std::string_view method) {
  const std::optional<Method> m = parseMethod(method);
  if (!m) throw Error("method: must be one of " + methodNames() + " (got '" + std::string(method) + "')");
  const MethodInfo& info = methodInfo(*m);
  PipelineOptions o;
  o.method = info.name;
  if (*info.tracker) {
    o.frontend.tracker = info.tracker;
    o.sync.trigger = info.sync_trigger;
  }
  return o;
}

}  // namespace evio::estimator
