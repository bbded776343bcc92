#include "evio/core/io/events_txt.h"

#include "evio/core/error.h"

namespace evio::io {

namespace {
constexpr const char* kColumns[4] = {"t", "x", "y", "p"};
}

EventTextReader::EventTextReader(std::string path, std::optional<SensorSize> sensor)
    : lines_(std::move(path)), sensor_(sensor) {}

bool EventTextReader::next(EventArray& out, std::size_t max_events) {
  std::size_t added = 0;
  std::string_view line;
  std::string_view f[4];
  while (added < max_events && lines_.next(line)) {
    if (isBlankOrComment(line)) continue;
    bool more = false;
    const std::size_t n = splitFields(line, f, 4, &more);
    const auto fail = [&](const char* column, const std::string& what) {
      throw Error::inField(lines_.path(), lines_.lineNumber(), column, what);
    };
    if (n != 4 || more)
      throw Error::inFile(lines_.path(), lines_.lineNumber(),
                          "expected 4 columns 't x y p', got " + std::to_string(n) + (more ? "+" : ""));
    TimeNs t_ns = 0;
    if (!parseSecondsToNs(f[0], &t_ns)) fail(kColumns[0], "not a finite time in seconds: '" + std::string(f[0]) + "'");
    if (t_ns < last_t_ns_ && count_ > 0)
      fail(kColumns[0], "timestamp decreases (" + std::string(f[0]) + " after an event at " +
                            std::to_string(nsToSeconds(last_t_ns_)) + " s)");
    std::int64_t x = 0, y = 0, p = 0;
    if (!parseInt64(f[1], &x) || x < 0 || x > 65535) fail(kColumns[1], "not a pixel column: '" + std::string(f[1]) + "'");
    if (!parseInt64(f[2], &y) || y < 0 || y > 65535) fail(kColumns[2], "not a pixel row: '" + std::string(f[2]) + "'");
    if (!parseInt64(f[3], &p) || (p != 0 && p != 1 && p != -1))
      fail(kColumns[3], "polarity must be 0, 1 (or -1), got '" + std::string(f[3]) + "'");
    if (sensor_ && (x >= sensor_->width || y >= sensor_->height))
      throw Error::inFile(lines_.path(), lines_.lineNumber(),
                          "pixel (" + std::to_string(x) + ", " + std::to_string(y) + ") outside the " +
                              std::to_string(sensor_->width) + "x" + std::to_string(sensor_->height) +
                              " sensor");
    out.push_back(t_ns, static_cast<std::uint16_t>(x), static_cast<std::uint16_t>(y), p == 1);
    last_t_ns_ = t_ns;
    ++count_;
    ++added;
  }
  return added > 0;
}

EventArray readEventsText(const std::string& path, std::optional<SensorSize> sensor) {
  EventTextReader reader(path, sensor);
  EventArray events;
  while (reader.next(events, 1u << 20)) {
  }
  return events;
}

EventTextWriter::EventTextWriter(std::string path) : file_(std::move(path)) { buffer_.reserve(1u << 20); }

void EventTextWriter::append(const EventArray& events) {
  const auto& t = events.t();
  const auto& x = events.x();
  const auto& y = events.y();
  const auto& p = events.p();
  for (std::size_t i = 0; i < events.size(); ++i) {
    if (any_ && t[i] < last_t_ns_)
      throw Error::inFile(file_.path(), 0, "events must be appended in time order (event " +
                                               std::to_string(i) + " of a chunk goes back in time)");
    any_ = true;
    last_t_ns_ = t[i];
    appendSeconds(buffer_, t[i]);
    buffer_.push_back(' ');
    appendInt(buffer_, x[i]);
    buffer_.push_back(' ');
    appendInt(buffer_, y[i]);
    buffer_.push_back(' ');
    buffer_.push_back(p[i] ? '1' : '0');
    buffer_.push_back('\n');
    if (buffer_.size() > (1u << 20) - 64) {
      file_.write(buffer_);
      buffer_.clear();
    }
  }
}

void EventTextWriter::close() {
  file_.write(buffer_);
  buffer_.clear();
  file_.commit();
}

void writeEventsText(const std::string& path, const EventArray& events) {
  EventTextWriter writer(path);
  writer.append(events);
  writer.close();
}

}  // namespace evio::io
