#pragma once
/// @file from_file.h
/// `from_file`: waypoints listed in the YAML, or a TUM trajectory file
/// (`t tx ty tz qx qy qz qw`, e.g. an Event-Camera Dataset groundtruth.txt),
/// turned into a smooth C⁴ trajectory by a quintic B-spline
/// (bspline_trajectory.h). The spline smooths: choose knot_interval_s near
/// the spacing of dense (e.g. motion-capture) poses, or of the order of the
/// spacing of sparse waypoints to round their corners.

#include <memory>
#include <string>
#include <vector>

#include "evio/core/eigen_types.h"
#include "evio/trajectories/bspline_trajectory.h"
#include "evio/trajectories/trajectory_options.h"

namespace evio {

struct FromFileOptions : TrajectoryCommonOptions {
  using Waypoint = Eigen::Matrix<double, 8, 1>;

  FromFileOptions() {
    type = "from_file";
    duration_s = 0.0;  // 0: the whole span of the poses
  }

  /// TUM file of poses T_W_B; a relative path is taken from the folder of
  /// the YAML file that names it. Exclusive with `waypoints`.
  std::string file;
  /// Waypoints, each `[t_s, px, py, pz, qx, qy, qz, qw]` (TUM column order:
  /// time in s, position of B in W in m, Hamilton quaternion of R_W_B).
  /// At least two, times strictly increasing. Exclusive with `file`.
  std::vector<Waypoint> waypoints;
  /// Spacing of the spline's knots, s.
  double knot_interval_s = 0.1;

  template <class V>
  void fields(V& v) {
    commonFields(v);
    v("file", file, "TUM file of poses of B in W (relative to this YAML's folder)");
    v("waypoints", waypoints, "list of [t_s, px, py, pz, qx, qy, qz, qw]");
    v("knot_interval_s", knot_interval_s, "spacing of the spline's knots, s");
  }
  /// duration_s here may be 0 (the whole span); otherwise it crops the span.
  void validate() const;
};

/// Builds the spline from the options. `base_folder` resolves a relative
/// `file` (empty: the current directory). Throws Error naming the file and
/// line for malformed poses.
std::unique_ptr<BSplineTrajectory> makeFromFileTrajectory(const FromFileOptions& options,
                                                          const std::string& base_folder = "");

}  // namespace evio
