#pragma once
/// @file events_h5.h
/// Events in HDF5, DSEC layout (Gehrig et al., "DSEC", RA-L 2021):
///
///   /events/t    relative time in microseconds: uint32 when the span fits,
///                otherwise int64 (the reader accepts any integer type)
///   /events/x    uint16, pixel column (0 = left)
///   /events/y    uint16, pixel row (0 = top)
///   /events/p    uint8, polarity: 1 brighter, 0 darker
///   /ms_to_idx   uint64; ms_to_idx[k] = index of the first event with
///                t >= 1000 k µs (DSEC's definition); evio writes one entry per
///                millisecond up to and including floor(t_last / 1000 µs) + 1,
///                whose value is the number of events
///   /t_offset    int64 scalar, µs; absolute time = t_offset + t
///   /  attributes `width`, `height` (uint32), written when known; optional
///                when reading (real DSEC files do not carry them)
///
/// Time resolution. The library keeps time as int64 ns; this file keeps µs.
/// Writing floors every time to the µs: t_us = floor(t_ns / 1000), also for
/// negative times. Flooring (like rounding) never reorders events, so sorted
/// input stays sorted; it was chosen because the stored time is then never
/// later than the true time (an event is never moved into a later window), it
/// matches what integer µs hardware counters do, and t_offset = floor(first
/// time) keeps every relative time >= 0. Reading returns t_ns = 1000 t_us, so
/// a round trip is exact for times that are whole microseconds. events.txt
/// (text, seconds with 9 decimals) keeps the full ns resolution.
///
/// Errors. Every failure (missing file, not HDF5, truncated or corrupt file,
/// missing dataset, wrong type, mismatched lengths, non-monotonic time, pixel
/// outside the sensor, polarity other than 0/1) throws evio::Error naming the
/// file and, where one is involved, the dataset and event index. HDF5's own
/// error printing is switched off for the duration of each call (and restored
/// afterwards, per thread); its innermost message is appended to the Error.
///
/// Real DSEC files are compressed with the Blosc filter; reading them needs
/// the Blosc HDF5 plugin (HDF5_PLUGIN_PATH), otherwise read() throws an Error
/// naming the missing filter. Files written here use only gzip + shuffle.
///
/// Thread safety: one reader or writer object must not be used by two threads
/// at once; distinct objects may be (the system HDF5 is built thread-safe,
/// which serialises the calls).

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "evio/core/event.h"
#include "evio/core/time.h"

namespace evio::io {

/// Options of EventH5Writer and writeEventsH5.
struct EventH5Options {
  /// gzip (deflate) level 0..9; 0 stores raw chunks. Any level > 0 also applies
  /// the byte-shuffle filter first. Trade-off measured by
  /// experiments/bench/io_bench.cpp (one core, 16.8 M events): raw storage
  /// takes 9.0 B/event and streams at ~200 M events/s; gzip 1 takes 3.3 B/event
  /// (gzip 4: 3.1) but reading inflates at only ~25 M events/s and writing
  /// drops from ~80 to ~8 M events/s. The default 0 keeps reading above the
  /// 50 M events/s target; choose 1 for archiving.
  int compression_level = 0;
  /// Events per HDF5 chunk (and per write call). 2^16..2^18 stream equally
  /// fast; 2^16 halves the cost of short readWindow() calls (whole chunks are
  /// read and checksummed) and the slack of the last, partly filled chunk
  /// (at most chunk_events x 9 B, allocated in full when uncompressed). It
  /// also bounds the writer's buffer (13 B/event).
  std::uint64_t chunk_events = std::uint64_t{1} << 16;
  /// Stored type of /events/t: "auto" (uint32 while the span since t_offset
  /// fits in 2^32 µs = 71.6 min, switching to int64 if a later event does not),
  /// "uint32" (an event beyond that span is an error) or "int64".
  std::string t_type = "auto";
  /// Add HDF5's Fletcher-32 checksum to every chunk so corrupted bytes are
  /// detected on read (an Error) instead of returning wrong events. Costs
  /// about half of the streaming read speed (measured ~380 -> ~200 M events/s)
  /// and doubles the time of short windows; readers without the filter (any
  /// HDF5 build has it) could not read the file.
  bool checksum = true;
  /// Sensor size in pixels, stored as attributes; 0 = unknown. When known, the
  /// writer rejects events outside the sensor.
  int width = 0;
  int height = 0;

  template <class V>
  void fields(V& v) {
    v("compression_level", compression_level, "gzip level 0..9 (0 = none); >0 adds shuffle");
    v("chunk_events", chunk_events, "events per HDF5 chunk");
    v("t_type", t_type, "stored time type: auto, uint32 or int64");
    v("checksum", checksum, "Fletcher-32 checksum per chunk");
    v("width", width, "sensor width in pixels (0 = unknown)");
    v("height", height, "sensor height in pixels (0 = unknown)");
  }
  void validate() const;
};

/// Streams events into `<path>` in the DSEC layout. Events are appended in
/// time order; memory use is flat in the sequence length (one chunk of events
/// and one chunk of /ms_to_idx entries are buffered). The file is written
/// under a temporary name beside `path` and renamed onto it by close();
/// destroying the writer without close() removes the temporary.
class EventH5Writer {
 public:
  /// `t_offset_ns`: the time that relative times count from (floored to µs).
  /// Default: the first appended event's time, floored to µs.
  /// Throws Error (naming `path`) when the file cannot be created or the
  /// options are invalid.
  explicit EventH5Writer(std::string path, const EventH5Options& options = {},
                         std::optional<TimeNs> t_offset_ns = std::nullopt);
  ~EventH5Writer();
  EventH5Writer(const EventH5Writer&) = delete;
  EventH5Writer& operator=(const EventH5Writer&) = delete;

  /// Appends events. Throws Error (and appends none of `events`) when times
  /// decrease within `events` or relative to the last appended event, when an
  /// event is before t_offset or more than one day after it (/ms_to_idx has
  /// an entry per millisecond), when an event is outside the sensor (width and
  /// height known), when t_type is "uint32" and an event is 2^32 µs or more
  /// after t_offset, or when polarity is not 0/1. A failed write (disk full)
  /// also throws; the writer is then unusable (append and close throw) and
  /// its destruction removes the temporary.
  void append(const EventArray& events);

  /// Writes the buffered events, /ms_to_idx, /t_offset and the attributes,
  /// closes the file and renames it onto `path`. Throws on failure (the
  /// temporary is then removed). Appending after close() throws.
  void close();

  /// Events appended so far.
  std::uint64_t size() const;
  const std::string& path() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Reads a DSEC-layout file without loading it whole. Opening validates the
/// layout (datasets present, 1-D, integer types, equal lengths, first and last
/// time consistent); event data is validated as it is read: times must not
/// decrease (Error naming /events/t and the index), p must be 0 or 1, and
/// pixels must lie inside the sensor when its size is known.
class EventH5Reader {
 public:
  /// `width`, `height` (pixels, 0 = unknown) give the sensor size to check
  /// pixels against; when 0 the file's attributes are used if present. If
  /// both are given and differ, throws Error.
  explicit EventH5Reader(std::string path, int width = 0, int height = 0);
  ~EventH5Reader();
  EventH5Reader(const EventH5Reader&) = delete;
  EventH5Reader& operator=(const EventH5Reader&) = delete;
  EventH5Reader(EventH5Reader&&) noexcept;
  EventH5Reader& operator=(EventH5Reader&&) noexcept;

  /// Number of events.
  std::uint64_t size() const;
  /// t_offset in ns (a whole number of µs).
  TimeNs tOffsetNs() const;
  /// Time of the first and of the last event in ns; both tOffsetNs() when the
  /// file holds no events.
  TimeNs tFirstNs() const;
  TimeNs tLastNs() const;
  /// Sensor size in pixels (argument or attribute), 0 when unknown.
  int width() const;
  int height() const;
  const std::string& path() const;

  /// Reads the events with index in [begin, begin + count) into `out`
  /// (replacing its content). Throws Error when the range exceeds size().
  void read(std::uint64_t begin, std::uint64_t count, EventArray& out);

  /// Reads the events with t0_ns <= t < t1_ns into `out` (replacing its
  /// content), t as returned by the reader (µs resolution). /ms_to_idx
  /// narrows the index range to within one millisecond at each end, so only
  /// the window's events (plus at most 2 ms of margin) are read; the
  /// /ms_to_idx entries used are checked against /events/t.
  void readWindow(TimeNs t0_ns, TimeNs t1_ns, EventArray& out);

  /// Sequential streaming: reads the next at most `max_events` (> 0) events
  /// after the previous call into `out` (replacing its content, reusing its
  /// memory). Returns false, with `out` empty, once all events were read.
  /// Monotonicity is checked across calls as well, so streaming the whole file
  /// validates all of it.
  bool next(EventArray& out, std::size_t max_events);
  /// Restarts next() at event `index` (0 = the beginning).
  void seek(std::uint64_t index);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Writes `events` (time-sorted) to `path` atomically.
void writeEventsH5(const std::string& path, const EventArray& events,
                   const EventH5Options& options = {});

/// Reads every event of `path`, validating all of them.
EventArray readEventsH5(const std::string& path, int width = 0, int height = 0);

}  // namespace evio::io
