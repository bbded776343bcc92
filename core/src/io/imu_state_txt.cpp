#include "evio/core/io/imu_state_txt.h"

#include <array>
#include <cmath>

namespace evio::io {

namespace {

constexpr std::size_t kValues = 22;

std::vector<std::string> columnNames() {
  return {"px", "py", "pz", "qx", "qy", "qz", "qw", "vx", "vy", "vz", "wx", "wy",
          "wz", "ax", "ay", "az", "bax", "bay", "baz", "bgx", "bgy", "bgz"};
}

}  // namespace

bool ImuTruthState::operator==(const ImuTruthState& o) const {
  return t_ns == o.t_ns && T_W_B.translation() == o.T_W_B.translation() &&
         T_W_B.quaternion().coeffs() == o.T_W_B.quaternion().coeffs() && v_W == o.v_W &&
         omega_B == o.omega_B && a_W == o.a_W && accel_bias == o.accel_bias && gyro_bias == o.gyro_bias;
}

ImuStateReader::ImuStateReader(std::string path)
    : table_(std::move(path), columnNames(), "imu_state.txt") {}

bool ImuStateReader::next(ImuTruthState& s) {
  std::array<double, kValues> v{};
  if (!table_.next(&s.t_ns, v.data())) return false;
  const Quat q(v[6], v[3], v[4], v[5]);
  if (std::abs(q.norm() - 1.0) > 0.01) table_.fail("qw", "quaternion is not of unit norm");
  s.T_W_B = Pose(q, Vec3(v[0], v[1], v[2]));
  s.v_W = Vec3(v[7], v[8], v[9]);
  s.omega_B = Vec3(v[10], v[11], v[12]);
  s.a_W = Vec3(v[13], v[14], v[15]);
  s.accel_bias = Vec3(v[16], v[17], v[18]);
  s.gyro_bias = Vec3(v[19], v[20], v[21]);
  return true;
}

std::vector<ImuTruthState> readImuStateText(const std::string& path) {
  ImuStateReader reader(path);
  std::vector<ImuTruthState> states;
  ImuTruthState s;
  while (reader.next(s)) states.push_back(s);
  return states;
}

ImuStateWriter::ImuStateWriter(std::string path, const std::vector<std::string>& header)
    : table_(std::move(path), header) {}

void ImuStateWriter::append(const ImuTruthState& s) {
  const Vec3& p = s.T_W_B.translation();
  const Quat& q = s.T_W_B.quaternion();
  const std::array<double, kValues> v = {
      p.x(),          p.y(),          p.z(),          q.x(),          q.y(),
      q.z(),          q.w(),          s.v_W.x(),      s.v_W.y(),      s.v_W.z(),
      s.omega_B.x(),  s.omega_B.y(),  s.omega_B.z(),  s.a_W.x(),      s.a_W.y(),
      s.a_W.z(),      s.accel_bias.x(), s.accel_bias.y(), s.accel_bias.z(), s.gyro_bias.x(),
      s.gyro_bias.y(), s.gyro_bias.z()};
  table_.append(s.t_ns, v.data(), v.size());
}

void ImuStateWriter::close() { table_.close(); }

void writeImuStateText(const std::string& path, const std::vector<ImuTruthState>& states,
                       const std::vector<std::string>& header) {
  ImuStateWriter writer(path, header);
  for (const auto& s : states) writer.append(s);
  writer.close();
}

}  // namespace evio::io
