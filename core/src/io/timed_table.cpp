#include "evio/core/io/timed_table.h"

#include "evio/core/error.h"

namespace evio::io {

TimedTableReader::TimedTableReader(std::string path, std::vector<std::string> value_columns,
                                   std::string format, std::size_t optional_columns)
    : lines_(std::move(path)), columns_(std::move(value_columns)), format_(std::move(format)) {
  require(optional_columns <= columns_.size(), "TimedTableReader: more optional columns than columns");
  fields_.resize(columns_.size() + 1);
  min_fields_ = fields_.size() - optional_columns;
  row_fields_ = min_fields_;
}

std::string TimedTableReader::expectedColumns() const {
  // Before the first row: the range the format allows; after it, the first row's count.
  const std::size_t lo = any_ ? row_fields_ : min_fields_;
  const std::size_t hi = any_ ? row_fields_ : fields_.size();
  std::string names = "t";
  for (std::size_t i = 0; i + 1 < hi; ++i) names += " " + columns_[i];
  std::string text = (lo == hi ? std::to_string(hi) : std::to_string(lo) + " to " + std::to_string(hi)) +
                     " columns '" + names + "'";
  if (lo < hi) text += " (the last " + std::to_string(hi - lo) + " optional)";
  if (any_ && min_fields_ < fields_.size()) text += " (as on the first row)";
  return text;
}

void TimedTableReader::fail(const std::string& column, const std::string& what) const {
  throw Error::inField(lines_.path(), lines_.lineNumber(), column, what);
}

bool TimedTableReader::next(TimeNs* t_ns, double* values) {
  std::string_view line;
  while (lines_.next(line)) {
    if (isBlankOrComment(line)) continue;
    bool more = false;
    const std::size_t n = splitFields(line, fields_.data(), fields_.size(), &more);
    const bool count_ok = any_ ? n == row_fields_ : (n >= min_fields_ && n <= fields_.size());
    if (!count_ok || more)
      throw Error::inFile(lines_.path(), lines_.lineNumber(),
                          format_ + ": expected " + expectedColumns() + ", got " + std::to_string(n) +
                              (more ? "+" : ""));
    if (!any_) row_fields_ = n;
    if (!parseSecondsToNs(fields_[0], t_ns))
      fail("t", "not a finite time in seconds: '" + std::string(fields_[0]) + "'");
    if (any_ && *t_ns <= last_t_ns_)
      fail("t", "timestamps must increase strictly ('" + std::string(fields_[0]) +
                    "' does not follow " + std::to_string(nsToSeconds(last_t_ns_)) + " s)");
    for (std::size_t i = 0; i + 1 < row_fields_; ++i)
      if (!parseFiniteDouble(fields_[i + 1], &values[i]))
        fail(columns_[i], "not a finite number: '" + std::string(fields_[i + 1]) + "'");
    any_ = true;
    last_t_ns_ = *t_ns;
    return true;
  }
  return false;
}

TimedTableWriter::TimedTableWriter(std::string path, const std::vector<std::string>& header)
    : file_(std::move(path)) {
  for (const auto& h : header) buffer_ += "# " + h + "\n";
}

void TimedTableWriter::append(TimeNs t_ns, const double* values, std::size_t count) {
  appendSeconds(buffer_, t_ns);
  for (std::size_t i = 0; i < count; ++i) {
    buffer_.push_back(' ');
    appendDouble(buffer_, values[i]);
  }
  buffer_.push_back('\n');
  if (buffer_.size() > (1u << 20)) {
    file_.write(buffer_);
    buffer_.clear();
  }
}

void TimedTableWriter::close() {
  file_.write(buffer_);
  buffer_.clear();
  file_.commit();
}

}  // namespace evio::io
