#include "evio/simulator/trajectory_export.h"

#include <yaml-cpp/yaml.h>

#include <filesystem>

#include "evio/core/error.h"
#include "evio/core/io/atomic_file.h"
#include "evio/core/io/config.h"
#include "evio/core/io/imu_state_txt.h"
#include "evio/core/io/imu_txt.h"
#include "evio/core/io/tum.h"
#include "evio/trajectories/trajectory_factory.h"

namespace evio {

void TrajectoryExportOptions::validate() const {
  imu.validate();
  requireInRange("groundtruth_rate_hz", groundtruth_rate_hz, 0.01, 100000.0);
}

namespace {

std::string resolvedYaml(const ContinuousTrajectory& trajectory, const TrajectoryExportOptions& options,
                         std::uint64_t seed) {
  YAML::Emitter out;
  out << YAML::BeginMap;
  out << YAML::Key << "seed" << YAML::Value << seed;
  out << YAML::Key << "trajectory" << YAML::Value << YAML::Load(trajectory.configYaml());
  out << YAML::Key << "export" << YAML::Value << YAML::Load(config::toYaml(options));
  out << YAML::EndMap;
  return "# resolved by evio trajectory (simulator/trajectory_export.h)\n" + std::string(out.c_str()) + "\n";
}

}  // namespace

TrajectoryExportSummary exportTrajectory(const ContinuousTrajectory& trajectory,
                                         const TrajectoryExportOptions& options, std::uint64_t seed,
                                         const std::string& folder, const std::optional<Pose>& T_B_C) {
  options.validate();
  const std::filesystem::path dir(folder);
  std::error_code ec;
  std::filesystem::create_directories(dir / "truth", ec);
  if (ec) throw Error(folder + ": cannot create the output folder: " + ec.message());
  TrajectoryExportSummary summary;

  // groundtruth.txt at its own rate, always including the last instant's grid point.
  const std::string gt_path = (dir / "groundtruth.txt").string();
  io::TumWriter gt(gt_path, {std::string("pose of ") + (T_B_C ? "the camera C" : "the body B (IMU)") +
                                 " in W; t px py pz qx qy qz qw"});
  const double period_ns = 1e9 / options.groundtruth_rate_hz;
  for (std::int64_t k = 0;; ++k) {
    const TimeNs t = trajectory.startTime() + static_cast<TimeNs>(std::llround(static_cast<double>(k) * period_ns));
    if (t > trajectory.endTime()) break;
    const Pose T_W_B = trajectory.evaluate(t).T_W_B;
    gt.append({t, T_B_C ? T_W_B * *T_B_C : T_W_B});
    ++summary.groundtruth_poses;
  }
  gt.close();
  summary.files.push_back(gt_path);

  // imu.txt and the truth beside it, streamed together.
  const std::string imu_path = (dir / "imu.txt").string();
  const std::string state_path = (dir / "truth" / "imu_state.txt").string();
  io::ImuTextWriter imu(imu_path);
  io::ImuStateWriter state(state_path, {"true IMU state at each imu.txt sample (true time)",
                                        "t px py pz qx qy qz qw vx vy vz wx wy wz ax ay az bax bay baz bgx bgy bgz"});
  ImuSimulator sim(trajectory, options.imu, seed);
  ImuMeasurement m;
  while (sim.next(m)) {
    imu.append(m.sample);
    io::ImuTruthState s;
    s.t_ns = m.truth.t_ns;
    s.T_W_B = m.truth.T_W_B;
    s.v_W = m.truth.v_W;
    s.omega_B = m.truth.omega_B;
    s.a_W = m.truth.a_W;
    s.accel_bias = m.accel_bias;
    s.gyro_bias = m.gyro_bias;
    state.append(s);
    ++summary.imu_samples;
  }
  imu.close();
  state.close();
  summary.files.push_back(imu_path);
  summary.files.push_back(state_path);

  const std::string yaml_path = (dir / "trajectory.yaml").string();
  io::writeFileAtomic(yaml_path, resolvedYaml(trajectory, options, seed));
  summary.files.push_back(yaml_path);
  return summary;
}

TrajectoryExportSummary exportTrajectoryPreset(const std::string& preset_yaml, const std::string& folder,
                                               const std::vector<std::string>& overrides) {
  config::Document preset = config::loadFile(preset_yaml);
  config::Document exporter = config::loadString("{}", "--set");
  for (const auto& o : overrides) {
    if (o.rfind("imu.", 0) == 0) {
      config::applyOverride(exporter, o);
    } else if (o.rfind("export.", 0) == 0) {
      config::applyOverride(exporter, o.substr(7));
    } else {
      config::applyOverride(preset, o);
    }
  }
  const auto trajectory = makeTrajectory(preset, "");
  const YAML::Node resolved = YAML::Load(trajectory->configYaml());
  TrajectoryExportOptions options;
  options.imu.gravity_mps2 = resolved["gravity_mps2"].as<double>();
  config::fill(exporter, "", options);
  return exportTrajectory(*trajectory, options, resolved["seed"].as<std::uint64_t>(), folder);
}

}  // namespace evio
