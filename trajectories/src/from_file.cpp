#include "evio/trajectories/from_file.h"

#include <filesystem>

#include "evio/core/error.h"
#include "evio/core/io/tum.h"
#include "preset_util.h"

namespace evio {

void FromFileOptions::validate() const {
  requireField(type == "from_file", "type", "must be 'from_file' for these options");
  requireNonNegative("duration_s", duration_s);
  requirePositive("gravity_mps2", gravity_mps2);
  requirePositive("knot_interval_s", knot_interval_s);
  requireField(file.empty() != waypoints.empty(), "file",
               "give exactly one of 'file' and 'waypoints'");
  if (!waypoints.empty()) {
    requireField(waypoints.size() >= 2, "waypoints", "needs at least two waypoints");
    for (std::size_t i = 0; i < waypoints.size(); ++i) {
      const std::string name = "waypoints[" + std::to_string(i) + "]";
      requireField(waypoints[i].allFinite(), name, "must be finite");
      const double qn = waypoints[i].tail<4>().norm();
      requireField(std::abs(qn - 1.0) < 0.01, name, "quaternion must have unit norm (within 1 %)");
      if (i > 0)
        requireField(waypoints[i](0) > waypoints[i - 1](0), name, "times must increase strictly");
    }
  }
}

std::unique_ptr<BSplineTrajectory> makeFromFileTrajectory(const FromFileOptions& options,
                                                          const std::string& base_folder) {
  options.validate();
  std::vector<StampedPose> poses;
  if (!options.file.empty()) {
    std::filesystem::path path(options.file);
    if (path.is_relative() && !base_folder.empty()) path = std::filesystem::path(base_folder) / path;
    poses = io::readTum(path.string());
    require(poses.size() >= 2, path.string() + ": from_file needs at least two poses");
  } else {
    for (const auto& w : options.waypoints) {
      const Quat q(w(7), w(4), w(5), w(6));
      poses.push_back({secondsToNs(w(0)), Pose(q.normalized(), Vec3(w(1), w(2), w(3)))});
    }
  }
  return std::make_unique<BSplineTrajectory>(poses, options.knot_interval_s, options.duration_s,
                                             preset::yamlOf(options));
}

}  // namespace evio
