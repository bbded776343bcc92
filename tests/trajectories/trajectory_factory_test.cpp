#include "evio/trajectories/trajectory_factory.h"

#include <gtest/gtest.h>

#include <fstream>

#include "temp_dir.h"

namespace evio {
namespace {

std::string errorOf(const std::string& yaml, const std::string& path = "") {
  try {
    makeTrajectory(config::loadString(yaml, "preset.yaml"), path);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

TEST(TrajectoryFactory, UnknownKeysAreRejectedWithFileAndLine) {
  const std::string msg = errorOf("type: hover\nduration_s: 30\ncentre_m: [0, 0, 1]\n");
  EXPECT_TRUE(contains(msg, "preset.yaml:3")) << msg;
  EXPECT_TRUE(contains(msg, "centre_m")) << msg;
  EXPECT_TRUE(contains(msg, "unknown key")) << msg;
  // A key of another preset is unknown here too.
  EXPECT_TRUE(contains(errorOf("type: circle\ndrift_amplitude_m: [1, 1, 1]\n"), "preset.yaml:2"));
}

TEST(TrajectoryFactory, MissingOrUnknownTypeIsNamed) {
  const std::string missing = errorOf("duration_s: 30\n");
  EXPECT_TRUE(contains(missing, "type")) << missing;
  EXPECT_TRUE(contains(missing, "rotation_only")) << missing;
  const std::string unknown = errorOf("duration_s: 30\ntype: loop\n");
  EXPECT_TRUE(contains(unknown, "preset.yaml:2")) << unknown;
  EXPECT_TRUE(contains(unknown, "loop")) << unknown;
}

TEST(TrajectoryFactory, InvalidValuesNameTheField) {
  const std::string msg = errorOf("type: flight\nduration_s: 20\n");
  EXPECT_TRUE(contains(msg, "duration_s")) << msg;
  EXPECT_TRUE(contains(msg, "preset.yaml")) << msg;
  EXPECT_TRUE(contains(errorOf("type: rotation_only\nfrequency_spread: 0.9\n"), "frequency_spread"));
  EXPECT_TRUE(contains(errorOf("type: hover\nwobble_min_frequency_hz: 2\n"), "wobble_max_frequency_hz"));
  EXPECT_TRUE(contains(errorOf("type: circle\ndiameter_m: -1\n"), "diameter_m"));
  EXPECT_TRUE(contains(errorOf("type: six_dof\nseed: -1\n"), "seed"));
}

TEST(TrajectoryFactory, BuildsFromAnEmbeddedSectionWithDefaults) {
  const auto doc = config::loadString(
      "scene: mars_yard\ntrajectory:\n  type: circle\n  duration_s: 12.5\n  diameter_m: 2\n", "scenario.yaml");
  const auto traj = makeTrajectory(doc, "trajectory");
  EXPECT_EQ(traj->endTime(), secondsToNs(12.5));
  EXPECT_NEAR(traj->evaluate(0).T_W_B.translation().head<2>().norm(), 1.0, 1e-12);
  const std::string yaml = traj->configYaml();
  EXPECT_TRUE(contains(yaml, "type: circle")) << yaml;
  EXPECT_TRUE(contains(yaml, "frequency_end_hz: 0.3")) << yaml;  // defaults are written out
  EXPECT_TRUE(contains(errorOf("trajectory:\n  type: circle\n  radius: 1\n", "trajectory"),
                       "trajectory.radius"));
}

TEST(TrajectoryFactory, OverridesApply) {
  test::TempDir dir;
  {
    std::ofstream f(dir.file("p.yaml"));
    f << "type: rotation_only\nduration_s: 10\n";
  }
  const auto traj = makeTrajectory(dir.file("p.yaml"), {"duration_s=5", "position_m=[1, 2, 3]"});
  EXPECT_EQ(traj->endTime(), 5 * kNsPerSecond);
  EXPECT_EQ(traj->evaluate(kNsPerSecond).T_W_B.translation(), Vec3(1, 2, 3));
}

TEST(TrajectoryFactory, FromFileChecksItsSource) {
  EXPECT_TRUE(contains(errorOf("type: from_file\n"), "file"));
  EXPECT_TRUE(contains(errorOf("type: from_file\nfile: a.txt\nwaypoints: [[0, 0, 0, 0, 0, 0, 0, 1], "
                               "[1, 0, 0, 0, 0, 0, 0, 1]]\n"),
                       "exactly one"));
  EXPECT_TRUE(contains(errorOf("type: from_file\nwaypoints: [[0, 0, 0, 0, 0, 0, 0, 1], "
                               "[0, 1, 0, 0, 0, 0, 0, 1]]\n"),
                       "waypoints[1]"));
  EXPECT_TRUE(contains(errorOf("type: from_file\nwaypoints: [[0, 0, 0, 0, 0, 0, 0, 2], "
                               "[1, 1, 0, 0, 0, 0, 0, 1]]\n"),
                       "unit norm"));
  EXPECT_TRUE(contains(errorOf("type: from_file\nwaypoints: [[0, 0, 0, 0, 0, 0, 1]]\n"), "8 numbers"));
  test::TempDir dir;
  {
    std::ofstream f(dir.file("p.yaml"));
    f << "type: from_file\nfile: missing.txt\n";
  }
  try {
    makeTrajectory(dir.file("p.yaml"));
    FAIL();
  } catch (const Error& e) {
    EXPECT_TRUE(contains(e.what(), "missing.txt")) << e.what();
  }
}

}  // namespace
}  // namespace evio
