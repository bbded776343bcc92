#pragma once
/// @file tracks_input.h
/// The `tracks` method's input: feature tracks from a file (core/io/
/// tracks_txt.h: `id t x y`, pixels of the event camera, e.g. the
/// simulator's truth/tracks.txt) turned into measurement sets for the backend,
/// so that the backend can be tested without a frontend.
///
/// The samples are sorted by time (then id) and Gaussian noise of σ = noise_px
/// is added to each coordinate in that order (RandomStream(seed,
/// "track_noise")). They are then fed to a Synchronizer (synchronizer.h) as
/// track points, with trigger fixed_rate at rate_hz, or track_time (one set
/// per distinct file time) when rate_hz is 0. A track with a gap longer than
/// max_gap_s between two samples is split, the rest continuing under a new id
/// (a re-detected feature); a track ends (kLost) before the first file time
/// after its last sample. At a fixed-rate update time equal
/// to a file time the set holds exactly the file's samples at that time;
/// between file times the synchroniser's linear extrapolation applies.
///
/// The file is read whole (a tracks file is small next to the event stream).

#include <cstdint>
#include <string>
#include <vector>

#include "evio/core/io/tracks_txt.h"
#include "evio/estimator/frontend/synchronizer.h"
#include "evio/estimator/pipeline/pipeline_options.h"

namespace evio::estimator {

class TracksInput {
 public:
  /// Reads `path` (throws evio::Error naming file:line for bad input).
  TracksInput(const std::string& path, const TracksInputOptions& options, std::uint64_t seed);
  /// From samples already in memory (tests); sorted and noised as above.
  TracksInput(std::vector<io::TrackSample> samples, const TracksInputOptions& options, std::uint64_t seed);

  /// Appends to `out` every measurement set with time <= t_ns not returned yet.
  void advanceTo(TimeNs t_ns, std::vector<MeasurementSet>& out);

  std::size_t numSamples() const { return samples_.size(); }
  /// Tracks after splitting at gaps.
  std::size_t numTracks() const { return last_t_.size(); }
  /// Gaps longer than max_gap_s that split a track.
  std::size_t numSplits() const { return splits_; }

 private:
  void prepare(std::uint64_t seed);

  TracksInputOptions options_;
  std::vector<io::TrackSample> samples_;
  std::vector<std::pair<std::int64_t, TimeNs>> last_t_;  // id → time of its last sample, sorted by id
  Synchronizer sync_;
  std::size_t next_ = 0;
  std::size_t splits_ = 0;
  std::vector<FeatureId> ending_;  // tracks whose last sample was fed
};

}  // namespace evio::estimator
