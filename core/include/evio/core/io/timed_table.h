#pragma once
/// @file timed_table.h
/// Text tables whose first column is a time in seconds followed by a fixed
/// number of finite doubles (imu.txt, groundtruth.txt, TUM trajectories).
/// The shared reader validates the column count, numbers and strictly
/// increasing time; the shared writer is atomic.

#include <array>
#include <string>
#include <vector>

#include "evio/core/io/atomic_file.h"
#include "evio/core/io/text_scanner.h"

namespace evio::io {

/// Streams rows `t v1 … vN` out of a text file.
class TimedTableReader {
 public:
  /// `value_columns` names the N value columns (for messages), e.g.
  /// {"ax","ay","az","gx","gy","gz"}; `format` names the format ("imu.txt").
  /// The last `optional_columns` of them may be absent (a newer format's
  /// added columns): the first row fixes the file's column count, and every
  /// later row must have the same.
  TimedTableReader(std::string path, std::vector<std::string> value_columns, std::string format,
                   std::size_t optional_columns = 0);

  /// Reads the next row; false at the end. `values` receives valueCount()
  /// doubles (N when no column is optional).
  bool next(TimeNs* t_ns, double* values);

  /// Value columns of this file's rows (fixed by the first row; before it,
  /// the number of required columns).
  std::size_t valueCount() const { return row_fields_ - 1; }

  const std::string& path() const { return lines_.path(); }
  std::int64_t lineNumber() const { return lines_.lineNumber(); }

  /// Throws Error at the current line about `column`.
  [[noreturn]] void fail(const std::string& column, const std::string& what) const;

 private:
  std::string expectedColumns() const;

  LineReader lines_;
  std::vector<std::string> columns_;
  std::string format_;
  std::size_t min_fields_;  // t and the required value columns
  std::size_t row_fields_;  // t and the value columns of every row (set by the first row)
  std::vector<std::string_view> fields_;
  TimeNs last_t_ns_ = 0;
  bool any_ = false;
};

/// Writes rows `t v1 … vN` (t with 9 decimals, values in shortest round-trip
/// form) to a file that appears only on close().
class TimedTableWriter {
 public:
  /// `header` lines are written first, each prefixed with "# ".
  explicit TimedTableWriter(std::string path, const std::vector<std::string>& header = {});
  void append(TimeNs t_ns, const double* values, std::size_t count);
  void close();

 private:
  AtomicFile file_;
  std::string buffer_;
};

}  // namespace evio::io
