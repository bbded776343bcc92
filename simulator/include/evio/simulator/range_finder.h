#pragma once
/// @file range_finder.h
/// A single-beam laser range finder: the distance along +z of its frame L
/// to the first surface, by ray casting, with Gaussian noise and a minimum
/// and maximum range (core/sensor_rig.h, RangeFinderSensor).
///
///   T_W_L = T_W_B · T_B_L,   ray  o = p_W_L,  d = R_W_L · (0, 0, 1)
///   ρ     = distance from o to the first surface along d (+inf: none)
///   valid = min_range_m ≤ ρ ≤ max_range_m
///   range = max(0, ρ + σ n),  n ~ N(0, 1)   (stream "range_finder")
///
/// In a sequence loop: call measure(t, T_W_B) at the range finder's own
/// clock with the true body pose at t, and write `reading` to range.txt
/// (core/io/range_txt.h); `true_range_m` is the ground truth.

#include <functional>
#include <limits>

#include "evio/core/eigen_types.h"
#include "evio/core/io/range_txt.h"
#include "evio/core/pose.h"
#include "evio/core/random_stream.h"
#include "evio/core/sensor_rig.h"
#include "evio/scenes/scene.h"

namespace evio::simulator {

/// One measurement with its truth.
struct RangeMeasurement {
  io::RangeSample reading;   ///< what the sensor reports (range.txt row)
  double true_range_m = std::numeric_limits<double>::infinity();  ///< ρ, +inf when no surface
};

class RangeFinder {
 public:
  /// Distance (m) from `origin_W` along the unit direction `dir_W` to the
  /// first surface, +inf when there is none.
  using RayCast = std::function<double(const Vec3& origin_W, const Vec3& dir_W)>;

  /// A RayCast against an Embree scene (which must outlive it).
  static RayCast sceneRayCast(const scenes::Scene& scene);

  /// Validates `sensor` (throws evio::Error naming the field).
  RangeFinder(const RangeFinderSensor& sensor, RayCast cast, std::uint64_t seed);

  /// The measurement at t_ns with the body (IMU) at pose T_W_B.
  RangeMeasurement measure(TimeNs t_ns, const Pose& T_W_B);

  const RangeFinderSensor& sensor() const { return sensor_; }

 private:
  RangeFinderSensor sensor_;
  RayCast cast_;
  RandomStream noise_;
};

}  // namespace evio::simulator
