#pragma once
/// @file backend_input.h
/// What the backend consumes (stages.h): IMU samples (IMU clock), measurement
/// sets and range readings (camera clock), each stream in time order, and
/// the still probe's frame corners (camera clock), which only the first
/// window reads (gyro_bias_window.h); the filter never sees them.

#include <variant>

#include "evio/core/imu_sample.h"
#include "evio/estimator/measurements.h"

namespace evio::estimator {

using BackendInput = std::variant<ImuSample, MeasurementSet, RangeMeasurement, FrameCorners>;

}  // namespace evio::estimator
