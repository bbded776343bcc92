#include "evio/core/io/range_txt.h"

#include <array>

namespace evio::io {

RangeReader::RangeReader(std::string path) : table_(std::move(path), {"range_m", "valid"}, "range.txt") {}

bool RangeReader::next(RangeSample& s) {
  std::array<double, 2> v{};
  if (!table_.next(&s.t_ns, v.data())) return false;
  if (v[1] != 0.0 && v[1] != 1.0) table_.fail("valid", "must be 0 or 1");
  if (v[0] < 0.0) table_.fail("range_m", "must be >= 0");
  s.valid = v[1] == 1.0;
  s.range_m = s.valid ? v[0] : 0.0;
  return true;
}

std::vector<RangeSample> readRangeText(const std::string& path) {
  RangeReader reader(path);
  std::vector<RangeSample> samples;
  RangeSample s;
  while (reader.next(s)) samples.push_back(s);
  return samples;
}

RangeWriter::RangeWriter(std::string path, const std::vector<std::string>& header)
    : table_(std::move(path), header) {}

void RangeWriter::append(const RangeSample& s) {
  const std::array<double, 2> v = {s.valid ? s.range_m : 0.0, s.valid ? 1.0 : 0.0};
  table_.append(s.t_ns, v.data(), v.size());
}

void RangeWriter::close() { table_.close(); }

void writeRangeText(const std::string& path, const std::vector<RangeSample>& samples,
                    const std::vector<std::string>& header) {
  RangeWriter writer(path, header);
  for (const auto& s : samples) writer.append(s);
  writer.close();
}

}  // namespace evio::io
