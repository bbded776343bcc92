#pragma once
/// @file track_noise_txt.h
/// What a tracker stated with each point of a tracks file, as text
/// (`evio track --noise` writes it beside the tracks, `<tracks>.noise.txt`):
/// one point per line, `id t quality cov_xx cov_xy cov_yy`, in the tracks
/// file's order and with its stamps (t in seconds, 9 decimals), so the two
/// join on (id, t). quality in [0, 1] (EKLT: 1 − cost/2; KLT, HASTE: 1);
/// cov the covariance of the position, px² (distorted image axes), symmetric
/// and positive semi-definite, `0 0 0` when the tracker states none. '#'
/// starts a comment line.

#include <cstdint>
#include <string>
#include <vector>

#include "evio/core/eigen_types.h"
#include "evio/core/time.h"

namespace evio::io {

struct TrackNoiseSample {
  std::int64_t id = 0;
  TimeNs t_ns = 0;
  double quality = 1.0;
  Mat2 cov_px = Mat2::Zero();
  friend bool operator==(const TrackNoiseSample&, const TrackNoiseSample&) = default;
};

/// Writes the samples atomically, numbers in shortest round-trip form
/// (reading back gives the same bits); `header` lines are prefixed "# ".
/// Throws for a negative id, a quality outside [0, 1] or a covariance that
/// is not finite, symmetric and positive semi-definite; off-diagonal entries
/// that differ by rounding (1e-9 of the diagonal) are written as their mean.
void writeTrackNoiseText(const std::string& path, const std::vector<TrackNoiseSample>& samples,
                         const std::vector<std::string>& header = {});

/// Reads and validates the file as the writer states it; errors name
/// file:line and the column.
std::vector<TrackNoiseSample> readTrackNoiseText(const std::string& path);

}  // namespace evio::io
