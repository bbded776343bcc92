// evio_fake_estimator: a stand-in for `evio estimate` in campaign tests and
// the smoke campaign (experiments/campaigns/smoke.yaml). It reads a
// sequence's groundtruth.txt and writes an estimate folder (estimate_files.h)
// whose errors are known by construction:
//   p̂(t) = p(t) + [offset_m, drift_percent/100 · d(t), 0] + n_p,   n_p ~ N(0, σ_p² I)
//   R̂(t) = Rz(yaw_drift · (t − t0)) · R(t) · Exp(−n_θ),            n_θ ~ N(0, σ_θ² I)
// (d the distance travelled), sampled at rate_hz from start_s after the
// first ground-truth time, with trajectory_covariance.txt stating σ_p², σ_θ²
// (so NEES ≈ 6 without offset and drift), timing.txt with processing time
// rtf · (data time), event_rate_hz events per second and `features` tracked
// features, and status.yaml
// (diverged at diverge_at_s, when >= 0: the output stops there). Seeds in
// crash_seeds abort (SIGABRT) before writing anything, like a crashing estimator.
//
// Usage: evio_fake_estimator <sequence> -o <folder> --seed S [--set key=value]...
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <numbers>
#include <set>
#include <string>
#include <vector>

#include "evio/core/error.h"
#include "evio/core/io/status_yaml.h"
#include "evio/core/io/timing_txt.h"
#include "evio/core/io/tum.h"
#include "evio/core/random_stream.h"
#include "evio/core/so3.h"
#include "evio/experiments/trajectory_alignment.h"
#include "evio/experiments/trajectory_association.h"

namespace {

using namespace evio;

int run(int argc, char** argv) {
  std::string sequence, output;
  std::uint64_t seed = 0;
  std::map<std::string, double> p = {{"rate_hz", 50.0},          {"start_s", 0.5},
                                     {"offset_m", 0.0},          {"drift_percent", 0.0},
                                     {"yaw_drift_deg_per_s", 0.0}, {"noise_position_m", 0.01},
                                     {"noise_rotation_rad", 0.002}, {"rtf", 0.4},
                                     {"event_rate_hz", 3e5},     {"diverge_at_s", -1.0},
                                     {"features", 45.0}};
  std::set<std::uint64_t> crash_seeds;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if ((a == "-o" || a == "--seed" || a == "--set") && i + 1 >= argc) throw Error(a + ": missing value");
    if (a == "-o") {
      output = argv[++i];
    } else if (a == "--seed") {
      seed = std::strtoull(argv[++i], nullptr, 10);
    } else if (a == "--set") {
      const std::string kv = argv[++i];
      const auto eq = kv.find('=');
      if (eq == std::string::npos) throw Error("--set " + kv + ": expected key=value");
      const std::string key = kv.substr(0, eq), value = kv.substr(eq + 1);
      if (key == "crash_seeds") {
        std::string list = value;
        for (char& c : list)
          if (c == '[' || c == ']' || c == ',') c = ' ';
        char* s = list.data();
        for (char* end = nullptr;; s = end) {
          const unsigned long long v = std::strtoull(s, &end, 10);
          if (end == s) break;
          crash_seeds.insert(v);
        }
      } else if (p.count(key)) {
        char* end = nullptr;
        p[key] = std::strtod(value.c_str(), &end);
        if (end == value.c_str() || *end != '\0') throw Error("--set " + kv + ": not a number");
      } else {
        throw Error("--set " + key + ": unknown key");
      }
    } else if (sequence.empty()) {
      sequence = a;
    } else {
      throw Error("unexpected argument '" + a + "'");
    }
  }
  if (sequence.empty() || output.empty()) throw Error("usage: evio_fake_estimator <sequence> -o <folder> --seed S");
  if (crash_seeds.count(seed)) {
    std::fprintf(stderr, "evio_fake_estimator: simulated crash for seed %llu\n", static_cast<unsigned long long>(seed));
    std::abort();
  }
  const Trajectory gt = io::readTum((std::filesystem::path(sequence) / "groundtruth.txt").string());
  require(gt.size() >= 2, "ground truth too short");
  std::filesystem::create_directories(output);

  RandomStream rng(seed, "fake_estimator");
  const double sp = p["noise_position_m"], sr = p["noise_rotation_rad"];
  const TimeNs t0 = gt.front().t_ns + secondsToNs(p["start_s"]);
  const TimeNs step = secondsToNs(1.0 / p["rate_hz"]);
  const bool diverges = p["diverge_at_s"] >= 0.0;
  const TimeNs t_diverge = gt.front().t_ns + secondsToNs(p["diverge_at_s"]);
  Trajectory estimate;
  std::vector<io::StampedPoseCovariance> covariance;
  std::vector<io::TimingSample> timing;
  double distance = 0.0;
  Vec3 last_p = gt.front().pose.translation();
  for (TimeNs t = t0; t <= gt.back().t_ns; t += step) {
    if (diverges && t > t_diverge) break;
    Pose T;
    experiments::interpolatePose(gt, t, step, &T);
    distance += (T.translation() - last_p).norm();
    last_p = T.translation();
    const Vec3 n_p(sp * rng.normal(), sp * rng.normal(), sp * rng.normal());
    const Vec3 n_r(sr * rng.normal(), sr * rng.normal(), sr * rng.normal());
    const double dt = nsToSeconds(t - gt.front().t_ns);
    const Vec3 pos = T.translation() + Vec3(p["offset_m"], p["drift_percent"] / 100.0 * distance, 0.0) + n_p;
    const Mat3 R = experiments::rotationZ(p["yaw_drift_deg_per_s"] * std::numbers::pi / 180.0 * dt) * T.rotation() *
                   so3::exp(-n_r);
    const Pose es(R, pos);
    estimate.push_back({t, es});
    covariance.push_back({t, es, Mat3::Identity() * sr * sr, Mat3::Identity() * sp * sp});
    const double data_s = nsToSeconds(t - t0);
    timing.push_back({t, p["rtf"] * data_s, static_cast<std::int64_t>(std::llround(p["event_rate_hz"] * data_s)),
                      static_cast<std::int64_t>(std::llround(p["features"]))});
  }
  io::writeTum((std::filesystem::path(output) / "trajectory.txt").string(), estimate,
               {"fake estimate (evio_fake_estimator): t px py pz qx qy qz qw"});
  io::writeTumCovariance((std::filesystem::path(output) / "trajectory_covariance.txt").string(), covariance);
  io::writeTimingText((std::filesystem::path(output) / "timing.txt").string(), timing);
  io::EstimateStatus status;
  status.initialization_t_ns = t0;
  if (diverges && t_diverge < gt.back().t_ns) {
    status.code = io::EstimateStatus::Code::kDiverged;
    status.t_ns = t_diverge;
    status.cause = "fake divergence (diverge_at_s)";
  }
  io::writeStatusYaml((std::filesystem::path(output) / "status.yaml").string(), status);
  std::printf("evio_fake_estimator: %zu poses, status %s\n", estimate.size(),
              std::string(io::estimateStatusName(status.code)).c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "evio_fake_estimator: error: %s\n", e.what());
    return 1;
  }
}
