#pragma once
/// @file tracks_txt.h
/// Feature tracks as text, `tracks.txt`: one sample per line, `id t x y`:
/// id a non-negative integer track id, t in seconds (written with 9
/// decimals, i.e. exact nanoseconds), x y the position in pixels (distorted
/// image coordinates, (0, 0) the centre of the top-left pixel). Lines of
/// different tracks may interleave; within one track time strictly
/// increases. '#' starts a comment line. Estimated tracks (`evio track`) and
/// ground-truth tracks (the simulator's truth/tracks.txt, visible samples
/// only) use the same format.

#include <cstdint>
#include <string>
#include <unordered_map>
#include <vector>

#include "evio/core/eigen_types.h"
#include "evio/core/io/atomic_file.h"
#include "evio/core/io/text_scanner.h"
#include "evio/core/time.h"

namespace evio::io {

struct TrackSample {
  std::int64_t id = 0;
  TimeNs t_ns = 0;
  Vec2 uv = Vec2::Zero();
  friend bool operator==(const TrackSample&, const TrackSample&) = default;
};

/// Streams samples, validating the 4 columns, a non-negative integer id,
/// finite numbers and strictly increasing time within each track; errors
/// name file:line and the column.
class TracksReader {
 public:
  explicit TracksReader(std::string path);
  bool next(TrackSample& sample);

 private:
  LineReader lines_;
  std::unordered_map<std::int64_t, TimeNs> last_t_ns_;
};

std::vector<TrackSample> readTracksText(const std::string& path);

/// Writes samples; the file appears under its name on close(). Throws when
/// a track's time does not increase.
class TracksWriter {
 public:
  /// `header` lines are written first, each prefixed with "# ".
  explicit TracksWriter(std::string path, const std::vector<std::string>& header = {});
  void append(const TrackSample& sample);
  void close();

 private:
  AtomicFile file_;
  std::string buffer_;
  std::unordered_map<std::int64_t, TimeNs> last_t_ns_;
};

void writeTracksText(const std::string& path, const std::vector<TrackSample>& samples,
                     const std::vector<std::string>& header = {});

}  // namespace evio::io
