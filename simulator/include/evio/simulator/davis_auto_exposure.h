#pragma once
/// @file davis_auto_exposure.h
/// The auto-exposure of iniVation's DAVIS driver (libcaer, src/autoexposure.c,
/// the rule used by DV and by the ROS driver since libcaer 3): after each APS
/// frame whose exposure is the one last set, it looks at the frame's
/// histogram and moves the exposure, in whole microseconds, by a step that
/// grows with the error. Restated in our words from the driver's source:
///
///  1. Pixels are 16-bit values v (our 8-bit DN · 256). A 256-bin histogram
///     of v gives f_low, the fraction of pixels in the bins below
///     ⌊0.10 · 256⌋ = 25, and f_high, the fraction in the bins from
///     ⌊0.90 · 256⌋ = 230 up.
///  2. Under-exposed (f_low ≥ 0.33 and f_high < 0.33):
///       t += ⌊14000 · (f_low − 0.33)^1.65⌋ µs.
///     Over-exposed (f_high ≥ 0.33 and f_low < 0.33):
///       t −= ⌊14000 · (f_high − 0.33)^1.65⌋ µs.
///  3. Otherwise the mean sample value over 5 equal ranges of v,
///       MSV = Σ_i (i + 1) · S_i / Σ_i S_i,   S_i = Σ v over the pixels in range i,
///     against the middle 2.5: e = 2.5 − MSV. If |e| > 0.1 the exposure moves
///     by ⌊100 · e²⌋ µs, divided (integer division) by 5 when f_low or f_high
///     is within 0.1 of 0.33 and by 10 when within 0.05, toward e's sign.
///  4. A step that rounds to nothing still moves by 1 µs; the result stays
///     within [1 µs, 1 s].
///
/// Note what this means on a DAVIS whose frames clip white at half the
/// 8-bit range (the Event-Camera Dataset's DAVIS240C: ≈ 115 DN): v never
/// reaches bin 230, so the rule never sees over-exposure through f_high and
/// backs off only through the MSV branch, by ≤ 25 µs per frame.

#include <cstdint>
#include <opencv2/core/mat.hpp>

namespace evio::simulator {

/// What the rule saw in a frame (for tests and diagnostics).
struct DavisExposureStatistics {
  double fraction_low = 0.0;   ///< f_low
  double fraction_high = 0.0;  ///< f_high
  double mean_sample_value = 0.0;  ///< MSV ∈ [1, 5]
};

/// f_low, f_high and MSV of an 8-bit frame (CV_8UC1).
DavisExposureStatistics davisExposureStatistics(const cv::Mat& image);

/// The next exposure in µs after a frame exposed for `exposure_us`.
std::int64_t davisNextExposureUs(const DavisExposureStatistics& s, std::int64_t exposure_us);

}  // namespace evio::simulator
