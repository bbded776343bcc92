#pragma once
/// @file davis_thresholds.h
/// The DAVIS240C's contrast thresholds (log units) as fitted to the
/// Event-Camera Dataset's recordings (simulator/presets/davis240c.yaml,
/// README "Events calibrated"): what the frontend assumes of an event camera
/// whose calibration states no thresholds (frontend.h resolveSensorParameters).

namespace evio::estimator {

inline constexpr double kDavis240cThresholdOn = 0.5;    ///< C⁺
inline constexpr double kDavis240cThresholdOff = 0.38;  ///< C⁻
/// One C for both polarities (EKLT's batch size): their mean.
inline constexpr double kDavis240cContrastThreshold = 0.5 * (kDavis240cThresholdOn + kDavis240cThresholdOff);

}  // namespace evio::estimator
