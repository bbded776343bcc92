#pragma once
/// @file down_looking_state.h
/// A small backend state for the unit tests of the extra state blocks
/// (track errors, image shift): three clones looking down from 10 m, 10 ms
/// apart, and two ground points as SLAM features anchored in the first two.

#include <cstddef>

#include "evio/core/random_stream.h"
#include "evio/core/so3.h"
#include "evio/estimator/backend/filter_state.h"
#include "evio/estimator/backend/visual_models.h"
#include "random_state.h"

namespace evio::test {

/// The IMU 10 m up, slightly turned; clones ids 10–12, P = 1e-3 I.
inline void addDownLookingClones(estimator::FilterState& s, RandomStream& rng) {
  s.imu.p_W_B = Vec3(0.0, 0.0, 10.0);
  s.imu.q_W_B = so3::expQuat(randomVec3(rng, 0.1));
  const Mat3 R_down = Vec3(1.0, -1.0, -1.0).asDiagonal();
  for (int i = 0; i < 3; ++i) {
    estimator::CameraClone c;
    c.id = 10 + i;
    c.t_ns = secondsToNs(0.01 * i);
    c.p_W_C = Vec3(0.3 * i, 0.1 * i, 10.0) + randomVec3(rng, 0.05);
    c.q_W_C = Quat(R_down * so3::exp(randomVec3(rng, 0.05)));
    s.clones.push_back(c);
  }
  s.P = MatX::Identity(s.dim(), s.dim()) * 1e-3;
}

/// Features 100 and 101 on the ground, through addFeature (so with whatever
/// blocks the state adds per feature), each with P_ff = 1e-4 I. False when a
/// point is not in front of its anchor (not for the clones above).
inline bool addTwoGroundFeatures(estimator::FilterState& s) {
  bool in_front = true;
  const Vec3 ground[2] = {Vec3(1.0, 1.0, 0.3), Vec3(-1.5, 0.5, -0.2)};
  for (int j = 0; j < 2; ++j) {
    estimator::SlamFeature f;
    f.id = 100 + j;
    f.anchor_clone_id = 10 + j;
    in_front = estimator::worldToAnchored(s.clones[static_cast<std::size_t>(j)], ground[j], &f.abr) && in_front;
    s.addFeature(f, Mat3::Identity() * 1e-4, Eigen::Matrix<double, 3, Eigen::Dynamic>::Zero(3, s.dim()));
  }
  return in_front;
}

}  // namespace evio::test
