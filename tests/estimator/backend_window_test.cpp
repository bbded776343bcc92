// The keyframe window of the backend (backend_options.h keyframe_interval_s):
// which cloned poses stay in the window for a given measurement rate, checked
// against the exact clone times.
#include <gtest/gtest.h>

#include <vector>

#include "evio/estimator/backend/backend.h"

namespace evio::estimator {
namespace {

const Camera kCamera = Camera(PinholeCamera(240, 180, Vec4(200, 200, 120, 90)));

/// Clone times (s) after each of `sets` feature-less measurement sets at
/// `rate_hz`, the body at rest under gravity with a 1 kHz IMU.
std::vector<std::vector<double>> cloneTimesAtRest(double rate_hz, int sets, const BackendOptions& options) {
  ImuSensor imu;
  imu.update_rate = 1000.0;
  Backend backend(options, BackendSensors{kCamera, Pose(), 9.81, imu, std::nullopt, 0});
  ImuState x0;
  backend.initialize(x0);
  const TimeNs imu_period = secondsToNs(0.001);
  const TimeNs set_period = secondsToNs(1.0 / rate_hz);
  TimeNs t_imu = 0;
  std::vector<std::vector<double>> out;
  for (int k = 1; k <= sets; ++k) {
    const TimeNs t_set = k * set_period;
    while (t_imu <= t_set + imu_period) {
      backend.addImu(ImuSample{t_imu, Vec3(0, 0, 9.81), Vec3::Zero()});
      t_imu += imu_period;
    }
    backend.addMeasurementSet(MeasurementSet{t_set, {}});
    std::vector<double> times;
    for (const CameraClone& c : backend.state().clones) times.push_back(nsToSeconds(c.t_ns));
    out.push_back(times);
  }
  return out;
}

// At 200 Hz with keyframes 40 ms apart: every kept pose but the newest is at
// least 40 ms after the one before it, the newest is the set just processed,
// and once the window is full its keyframes are exactly 40 ms apart (eight
// 5 ms sets each), M − 2 intervals from the oldest to the newest keyframe.
TEST(BackendWindow, KeyframesAreAtLeastTheIntervalApartAtAHighUpdateRate) {
  BackendOptions o;
  o.window_size = 10;
  o.keyframe_interval_s = 0.04;
  const auto history = cloneTimesAtRest(200.0, 400, o);
  for (std::size_t k = 0; k < history.size(); ++k) {
    const std::vector<double>& t = history[k];
    ASSERT_LE(static_cast<int>(t.size()), o.window_size) << "set " << k;
    EXPECT_NEAR(t.back(), 0.005 * static_cast<double>(k + 1), 1e-9);
    for (std::size_t i = 1; i + 1 < t.size(); ++i) EXPECT_GE(t[i] - t[i - 1], 0.04 - 1e-9) << "set " << k;
  }
  const std::vector<double>& last = history.back();
  ASSERT_EQ(static_cast<int>(last.size()), o.window_size);
  EXPECT_NEAR(last[last.size() - 2] - last.front(), 8 * 0.04, 1e-9);
}

// Without keyframes (0) the window is the last M sets: 45 ms at 200 Hz.
TEST(BackendWindow, ZeroIntervalKeepsTheLastMSets) {
  BackendOptions o;
  o.window_size = 10;
  o.keyframe_interval_s = 0.0;
  const auto history = cloneTimesAtRest(200.0, 100, o);
  const std::vector<double>& last = history.back();
  ASSERT_EQ(last.size(), 10u);
  for (std::size_t i = 0; i < last.size(); ++i) EXPECT_NEAR(last[i], 0.005 * static_cast<double>(91 + i), 1e-9);
}

// Sets slower than the interval (frames at 20 Hz) keep every pose: the same
// window as without keyframes.
TEST(BackendWindow, SetsSlowerThanTheIntervalAreAllKept) {
  BackendOptions with, without;
  with.keyframe_interval_s = 0.04;
  without.keyframe_interval_s = 0.0;
  EXPECT_EQ(cloneTimesAtRest(20.0, 60, with), cloneTimesAtRest(20.0, 60, without));
}

}  // namespace
}  // namespace evio::estimator
