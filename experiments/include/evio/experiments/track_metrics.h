#pragma once
/// @file track_metrics.h
/// Scores estimated feature tracks against ground-truth tracks (both in the
/// tracks.txt format, core/io/tracks_txt.h), as in the feature-tracking
/// evaluation of EKLT (Gehrig et al., IJCV 2019):
///  - tracking error (px) against feature age (time since the track began),
///  - feature age until the track is lost or its error first exceeds
///    max_error_px (5 px),
///  - the number of tracks alive over time.
/// Each estimated track is associated with one ground-truth track: by equal
/// id (match "id", for ground truth generated from the estimated tracks'
/// first points) or by the ground-truth track nearest to the estimated
/// track's first point at its first time, within association_radius_px
/// (match "nearest"; the estimated start is then taken as exact and the
/// ground-truth track's displacement since that time as the true motion, so
/// the start offset is not counted as error). Ground truth is interpolated linearly in time between
/// its samples; gaps longer than max_gap_s (occlusion) are not bridged, and
/// an estimated track is scored only while the ground truth covers it.
///
/// The depth mode (the second evaluateTracks) needs no ground-truth tracks:
/// every estimated track gets its own truth from the depth map at its start
/// and the ground-truth poses (depth_track_truth.h), so tracks born anywhere
/// at any frame can be scored; tracks with no truth (not starting at a depth
/// stamp, or on a depth discontinuity or no surface) are counted as
/// unevaluable.

#include <cstdint>
#include <string>
#include <vector>

#include "evio/core/io/tracks_txt.h"
#include "evio/core/options.h"
#include "evio/experiments/depth_track_truth.h"

namespace evio::experiments {

struct TrackMetricsOptions {
  std::string match = "nearest";        ///< nearest | id
  double association_radius_px = 2.0;   ///< nearest: largest start distance
  double max_error_px = 5.0;            ///< a track's scored life ends above this error
  double max_gap_s = 0.1;               ///< ground-truth samples further apart are not interpolated
  double age_bin_s = 0.05;              ///< bin width of error vs age
  double alive_bin_s = 0.05;            ///< sampling interval of the alive count

  template <class V>
  void fields(V& v) {
    v("match", match, "nearest or id");
    v("association_radius_px", association_radius_px, "nearest: largest start distance, px");
    v("max_error_px", max_error_px, "error that ends a track's scored life, px");
    v("max_gap_s", max_gap_s, "longest ground-truth gap that is interpolated, s");
    v("age_bin_s", age_bin_s, "bin width of error vs age, s");
    v("alive_bin_s", alive_bin_s, "sampling interval of the alive count, s");
  }
  void validate() const;
};

struct AgeBin {
  double age_s = 0.0;         ///< start of the bin
  double mean_error_px = 0.0;
  std::uint64_t samples = 0;
};

struct AliveSample {
  double t_s = 0.0;
  std::uint64_t estimated = 0;  ///< estimated tracks alive (first ≤ t ≤ last sample)
  std::uint64_t truth = 0;      ///< ground-truth tracks visible
};

struct TrackMetrics {
  std::string mode;                    ///< "tracks-nearest", "tracks-id" or "depth"
  std::uint64_t estimated_tracks = 0;
  std::uint64_t matched_tracks = 0;    ///< tracks with a truth (evaluable)
  std::uint64_t unevaluable_tracks = 0;          ///< estimated_tracks − matched_tracks
  std::uint64_t unevaluable_no_depth_frame = 0;  ///< depth: first sample not at a depth stamp
  std::uint64_t unevaluable_depth = 0;           ///< depth: no surface or a discontinuity at the start
  std::uint64_t ended_by_error = 0;    ///< scored life ended by the error passing max_error_px
  std::uint64_t ended_by_truth = 0;    ///< ... by the truth ending (out of view, occluded)
  std::uint64_t ended_by_track = 0;    ///< ... by the estimated track ending
  std::uint64_t scored_samples = 0;
  double mean_error_px = 0.0;          ///< over scored samples (before the error passes the limit)
  double median_error_px = 0.0;
  double mean_feature_age_s = 0.0;     ///< over matched tracks
  double median_feature_age_s = 0.0;
  double mean_track_length_s = 0.0;    ///< over all estimated tracks, last − first sample
  std::vector<AgeBin> error_vs_age;
  std::vector<AliveSample> alive;
};

/// Scores `estimated` against `truth`. Throws evio::Error for bad options.
TrackMetrics evaluateTracks(const std::vector<io::TrackSample>& estimated, const std::vector<io::TrackSample>& truth,
                            const TrackMetricsOptions& options);

/// Scores `estimated` against the truth of each track from depth maps and
/// poses (the alive count's "truth" is then the number of evaluable tracks
/// between their first sample and the end of their truth). Throws
/// evio::Error for bad options and unreadable depth maps.
TrackMetrics evaluateTracks(const std::vector<io::TrackSample>& estimated, const DepthTrackTruth& truth,
                            const TrackMetricsOptions& options);

/// The summary and both tables as one JSON object.
std::string trackMetricsJson(const TrackMetrics& metrics);

/// Error vs age as CSV: "age_s,mean_error_px,samples".
std::string errorVsAgeCsv(const TrackMetrics& metrics);

/// Alive count as CSV: "t_s,estimated,truth".
std::string aliveCsv(const TrackMetrics& metrics);

}  // namespace evio::experiments
