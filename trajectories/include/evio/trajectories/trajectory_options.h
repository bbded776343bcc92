#pragma once
/// @file trajectory_options.h
/// The fields every trajectory preset has (`type`, `duration_s`, `seed`,
/// `gravity_mps2`). Each preset's Options derives from this and lists these
/// fields first in its `fields()`.

#include <cstdint>
#include <string>
#include <string_view>

#include "evio/core/options.h"

namespace evio {

struct TrajectoryCommonOptions {
  /// Preset type: hover, rotation_only, circle, six_dof, translation, flight,
  /// lava_tube_entry or from_file. Fixed by the preset's Options.
  std::string type;
  /// Length of the trajectory in seconds; it starts at t = 0.
  double duration_s = 60.0;
  /// Seed of the run: random draws of the motion come from
  /// RandomStream(seed, "trajectory"); the IMU's noise uses the same seed.
  std::uint64_t seed = 1;
  /// Gravity of the world the motion happens in, m/s², along −z of W:
  /// Mars 3.721, Earth 9.81. Used by motion models that depend on it (the
  /// thrust-aligned attitude of a helicopter) and by the trajectory exporter
  /// for the IMU it synthesises.
  double gravity_mps2 = 3.721;

  template <class V>
  void commonFields(V& v) {
    v("type", type, "preset type");
    v("duration_s", duration_s, "length of the trajectory in seconds");
    v("seed", seed, "seed of the run's random streams");
    v("gravity_mps2", gravity_mps2, "gravity magnitude of the world, m/s^2 (Mars 3.721, Earth 9.81)");
  }

  /// Checks the common fields; `expected_type` is the preset's own type.
  void validateCommon(std::string_view expected_type) const {
    requireField(type == expected_type, "type",
                 "must be '" + std::string(expected_type) + "' for these options (got '" + type + "')");
    requirePositive("duration_s", duration_s);
    requirePositive("gravity_mps2", gravity_mps2);
  }
};

}  // namespace evio
