#include "evio/experiments/estimate_files.h"

#include <filesystem>

#include "evio/core/error.h"

namespace evio::experiments {

namespace fs = std::filesystem;

EstimateFiles findEstimateFiles(const std::string& estimate) {
  EstimateFiles f;
  fs::path folder;
  if (fs::is_directory(estimate)) {
    folder = estimate;
    f.trajectory = (folder / "trajectory.txt").string();
  } else {
    f.trajectory = estimate;
    folder = fs::path(estimate).parent_path();
  }
  if (!fs::is_regular_file(f.trajectory)) throw Error(f.trajectory + ": estimate trajectory not found");
  const auto beside = [&](const char* name) {
    const fs::path p = folder / name;
    return fs::is_regular_file(p) ? p.string() : std::string();
  };
  f.covariance = beside("trajectory_covariance.txt");
  f.timing = beside("timing.txt");
  f.status = beside("status.yaml");
  return f;
}

std::string findGroundtruthFile(const std::string& groundtruth) {
  const std::string file =
      fs::is_directory(groundtruth) ? (fs::path(groundtruth) / "groundtruth.txt").string() : groundtruth;
  if (!fs::is_regular_file(file)) throw Error(file + ": ground truth not found");
  return file;
}

}  // namespace evio::experiments
