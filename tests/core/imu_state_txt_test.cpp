#include "evio/core/io/imu_state_txt.h"

#include <gtest/gtest.h>

#include <fstream>

#include "evio/core/error.h"
#include "evio/core/io/atomic_file.h"
#include "evio/core/random_stream.h"
#include "evio/core/so3.h"
#include "temp_dir.h"

namespace evio {
namespace {

Vec3 randomVec(RandomStream& rng, double scale) {
  return Vec3(rng.normal(0, scale), rng.normal(0, scale), rng.normal(0, scale));
}

TEST(ImuStateText, RoundTripsBitForBit) {
  RandomStream rng(7, "test");
  std::vector<io::ImuTruthState> states;
  for (int i = 0; i < 200; ++i) {
    io::ImuTruthState s;
    s.t_ns = 1'000'000'000 + i * 1'000'123;
    s.T_W_B = Pose(so3::expQuat(randomVec(rng, 1.0)), randomVec(rng, 10.0));
    s.v_W = randomVec(rng, 2.0);
    s.omega_B = randomVec(rng, 3.0);
    s.a_W = randomVec(rng, 5.0);
    s.accel_bias = randomVec(rng, 0.1);
    s.gyro_bias = randomVec(rng, 0.01);
    states.push_back(s);
  }
  test::TempDir dir;
  io::writeImuStateText(dir.file("imu_state.txt"), states, {"true IMU state"});
  const auto back = io::readImuStateText(dir.file("imu_state.txt"));
  ASSERT_EQ(back.size(), states.size());
  for (std::size_t i = 0; i < states.size(); ++i) EXPECT_TRUE(back[i] == states[i]) << i;
  EXPECT_EQ(io::readFile(dir.file("imu_state.txt")).rfind("# true IMU state\n", 0), 0u);
}

TEST(ImuStateText, RejectsBadRowsWithFileAndLine) {
  test::TempDir dir;
  const std::string row = " 0 0 0 0 0 0 1 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0\n";
  const auto errorOf = [&](const std::string& text) -> std::string {
    io::writeFileAtomic(dir.file("s.txt"), text);
    try {
      io::readImuStateText(dir.file("s.txt"));
    } catch (const Error& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_EQ(errorOf("0.0" + row + "0.1" + row), "");
  EXPECT_NE(errorOf("0.0" + row + "0.0" + row).find("s.txt:2"), std::string::npos);  // time not increasing
  EXPECT_NE(errorOf("0.0 1 2 3\n").find("s.txt:1"), std::string::npos);              // columns
  EXPECT_NE(errorOf("0.0 0 0 0 0 0 0 2 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0\n").find("qw"),
            std::string::npos);                                                       // not unit
  EXPECT_NE(errorOf("0.0 0 0 0 0 0 0 1 nan 0 0 0 0 0 0 0 0 0 0 0 0 0 0\n").find("vx"),
            std::string::npos);
}

}  // namespace
}  // namespace evio
