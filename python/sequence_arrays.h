#pragma once
/// @file sequence_arrays.h
/// A sequence folder's streams as NumPy arrays for the Python module.
///
/// dtypes (little-endian, packed; times in integer nanoseconds like the files):
///   events       t:i8 x:u2 y:u2 p:u1                  (p: 1 brighter, 0 darker)
///   imu          t:i8 gyro:f8[3] acc:f8[3]            (rad/s and m/s² in the IMU frame B)
///   groundtruth  t:i8 p:f8[3] q:f8[4]                 (T_W_X: position m, quaternion x y z w)
/// Event columns (read_event_columns) are separate arrays that take over the
/// reader's buffers without a copy; a structured array needs one copy, as the
/// readers fill columns.

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "evio/core/event.h"

namespace evio::python {

/// A window [t_start, t_end) in ns; an absent end is open.
struct TimeWindow {
  std::optional<std::int64_t> t_start_ns;
  std::optional<std::int64_t> t_end_ns;
};

/// Streams a sequence's events (events.h5 or events.txt) in chunks of at
/// most `chunk` events inside `window`. Memory: one chunk.
class EventChunks {
 public:
  EventChunks(const std::string& folder, std::size_t chunk, TimeWindow window);
  ~EventChunks();
  /// The next chunk as a structured array; false at the end.
  bool next(EventArray& out);

 private:
  struct Reader;
  std::unique_ptr<Reader> reader_;
  std::size_t chunk_;
  TimeWindow window_;
  bool done_ = false;
};

pybind11::dtype eventDtype();
pybind11::array eventsToStructured(const EventArray& events);
/// The columns t, x, y, p as arrays owning the moved-out buffers (no copy).
pybind11::dict eventsToColumns(EventArray&& events);

pybind11::array readImu(const std::string& folder);
pybind11::array readGroundtruth(const std::string& folder);

/// Registers read_events, iter_events, read_event_columns, read_imu,
/// read_groundtruth, iter_frames on the module.
void addSequenceReaders(pybind11::module_& m);

}  // namespace evio::python
