#pragma once
/// @file track_points_txt.h
/// `truth/track_points.txt`: the world points behind the ground-truth
/// feature tracks (truth/tracks.txt), one per line, `id px py pz`: id the
/// track id (a non-negative integer, unique), p_W in metres. '#' starts a
/// comment line. Track id k of tracks.txt is the projection of point k.

#include <cstdint>
#include <string>
#include <vector>

#include "evio/core/eigen_types.h"

namespace evio::io {

struct TrackPoint {
  std::int64_t id = 0;
  Vec3 p_W = Vec3::Zero();  ///< m
  friend bool operator==(const TrackPoint&, const TrackPoint&) = default;
};

/// Reads and validates the file: 4 columns, a non-negative integer id not
/// seen before, finite coordinates (errors name file:line and the column).
std::vector<TrackPoint> readTrackPoints(const std::string& path);

/// Writes the points atomically, coordinates in shortest round-trip form
/// (reading back gives the same bits); `header` lines are prefixed "# ".
/// Throws for a negative or repeated id or a non-finite coordinate.
void writeTrackPoints(const std::string& path, const std::vector<TrackPoint>& points,
                      const std::vector<std::string>& header = {});

}  // namespace evio::io
