#include "evio/core/io/timing_txt.h"

#include <array>
#include <cmath>

#include "evio/core/error.h"

namespace evio::io {

namespace {
constexpr double kMaxCount = 9.0e15;  // whole numbers are exact in a double below 2^53

bool isCount(double v) { return v >= 0.0 && v <= kMaxCount && v == std::floor(v); }
}  // namespace

TimingReader::TimingReader(std::string path)
    : table_(std::move(path), {"processing_s", "events", "features"}, "timing.txt", 1) {}

bool TimingReader::next(TimingSample& s) {
  std::array<double, 3> v{};
  if (!table_.next(&s.t_ns, v.data())) return false;
  if (v[0] < 0.0) table_.fail("processing_s", "must be >= 0");
  if (!isCount(v[1])) table_.fail("events", "must be a whole number >= 0");
  s.processing_s = v[0];
  s.events = static_cast<std::int64_t>(v[1]);
  s.features.reset();
  if (table_.valueCount() == 3) {
    if (!isCount(v[2])) table_.fail("features", "must be a whole number >= 0");
    s.features = static_cast<std::int64_t>(v[2]);
  }
  if (any_ && s.processing_s < last_.processing_s) table_.fail("processing_s", "decreases");
  if (any_ && s.events < last_.events) table_.fail("events", "decreases");
  last_ = s;
  any_ = true;
  return true;
}

std::vector<TimingSample> readTimingText(const std::string& path) {
  TimingReader reader(path);
  std::vector<TimingSample> samples;
  TimingSample s;
  while (reader.next(s)) samples.push_back(s);
  return samples;
}

TimingWriter::TimingWriter(std::string path) : table_(std::move(path), {"t processing_s events features"}) {}

void TimingWriter::append(const TimingSample& s) {
  require(std::isfinite(s.processing_s) && s.processing_s >= 0.0,
          "timing.txt: processing_s must be finite and >= 0");
  require(s.events >= 0, "timing.txt: events must be >= 0");
  require(s.features.has_value() && *s.features >= 0, "timing.txt: features must be given and >= 0");
  if (any_) {
    require(s.t_ns > last_.t_ns, "timing.txt: t must increase strictly");
    require(s.processing_s >= last_.processing_s, "timing.txt: processing_s decreases");
    require(s.events >= last_.events, "timing.txt: events decreases");
  }
  const std::array<double, 3> v = {s.processing_s, static_cast<double>(s.events), static_cast<double>(*s.features)};
  table_.append(s.t_ns, v.data(), v.size());
  last_ = s;
  any_ = true;
}

void TimingWriter::close() { table_.close(); }

void writeTimingText(const std::string& path, const std::vector<TimingSample>& samples) {
  TimingWriter writer(path);
  for (const auto& s : samples) writer.append(s);
  writer.close();
}

}  // namespace evio::io
