#include "evio/core/io/imu_txt.h"

namespace evio::io {

ImuTextReader::ImuTextReader(std::string path)
    : table_(std::move(path), {"ax", "ay", "az", "gx", "gy", "gz"}, "imu.txt") {}

bool ImuTextReader::next(ImuSample& sample) {
  double v[6];
  if (!table_.next(&sample.t_ns, v)) return false;
  sample.acc_B = Vec3(v[0], v[1], v[2]);
  sample.gyro_B = Vec3(v[3], v[4], v[5]);
  return true;
}

ImuSamples readImuText(const std::string& path) {
  ImuTextReader reader(path);
  ImuSamples out;
  ImuSample s;
  while (reader.next(s)) out.push_back(s);
  return out;
}

ImuTextWriter::ImuTextWriter(std::string path) : table_(std::move(path)) {}

void ImuTextWriter::append(const ImuSample& s) {
  const double v[6] = {s.acc_B.x(), s.acc_B.y(), s.acc_B.z(), s.gyro_B.x(), s.gyro_B.y(), s.gyro_B.z()};
  table_.append(s.t_ns, v, 6);
}

void ImuTextWriter::close() { table_.close(); }

void writeImuText(const std::string& path, const ImuSamples& samples) {
  ImuTextWriter w(path);
  for (const auto& s : samples) w.append(s);
  w.close();
}

}  // namespace evio::io
