#pragma once
/// @file events_txt.h
/// `events.txt` of the Event-Camera Dataset: one event per line, `t x y p`,
/// t in seconds (written with 9 decimals, i.e. exact nanoseconds), x y
/// integer pixel coordinates, p in {0, 1} (a polarity of -1 is read as 0).
/// Reading streams through a fixed buffer: memory stays flat.

#include <cstddef>
#include <optional>
#include <string>

#include "evio/core/event.h"
#include "evio/core/io/atomic_file.h"
#include "evio/core/io/text_scanner.h"

namespace evio::io {

/// Sensor size used to validate pixel coordinates (x < width, y < height).
struct SensorSize {
  int width = 0;
  int height = 0;
};

/// Streams events out of an events.txt file, validating every line:
/// column count, numbers, finite non-negative-pixel values, polarity, time
/// non-decreasing, pixels inside `sensor` when given. Errors name file:line
/// and the column.
class EventTextReader {
 public:
  explicit EventTextReader(std::string path, std::optional<SensorSize> sensor = std::nullopt);

  /// Appends up to `max_events` events to `out`; false when none were left.
  bool next(EventArray& out, std::size_t max_events);

  /// Number of events returned so far.
  std::size_t count() const { return count_; }

 private:
  LineReader lines_;
  std::optional<SensorSize> sensor_;
  TimeNs last_t_ns_ = 0;
  std::size_t count_ = 0;
};

/// Reads a whole events.txt (for files that fit in memory).
EventArray readEventsText(const std::string& path, std::optional<SensorSize> sensor = std::nullopt);

/// Streams events into an events.txt, atomically: the file appears under its
/// name only after close(). Throws if time decreases.
class EventTextWriter {
 public:
  explicit EventTextWriter(std::string path);
  void append(const EventArray& events);
  void close();

 private:
  AtomicFile file_;
  std::string buffer_;
  TimeNs last_t_ns_ = 0;
  bool any_ = false;
};

/// Writes a whole EventArray to events.txt atomically.
void writeEventsText(const std::string& path, const EventArray& events);

}  // namespace evio::io
