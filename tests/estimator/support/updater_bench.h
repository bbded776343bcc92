#pragma once
/// What an updater (updater.h) works on, owned by a test: the state, the
/// first-estimate IMU state, options, counters, the triangulated points, the
/// initialisation time and a χ² table; and a resting state to start from.

#include <utility>

#include "evio/estimator/backend/chi_squared.h"
#include "evio/estimator/backend/updater.h"

namespace evio::test {

/// A state with clones 0..n-1 at the origin looking along +z, the IMU at rest,
/// and P = p_var I.
inline estimator::FilterState restingState(int clones, double p_var = 1e-2) {
  estimator::FilterState s;
  for (int i = 0; i < clones; ++i) {
    estimator::CameraClone c;
    c.id = i;
    s.clones.push_back(c);
  }
  s.P = p_var * MatX::Identity(s.dim(), s.dim());
  return s;
}

struct UpdaterBench {
  explicit UpdaterBench(estimator::FilterState s) : state(std::move(s)), fej(state.imu) {}
  estimator::UpdaterContext context() {
    return estimator::UpdaterContext{&state, &fej, &options, &stats, nullptr, &triangulated, &initialized_at};
  }
  estimator::FilterState state;
  estimator::ImuState fej;
  estimator::BackendOptions options;
  estimator::BackendStats stats;
  estimator::TriangulatedPoints triangulated{30};
  TimeNs initialized_at = 0;
  estimator::Chi2Table chi2{0.95};
};

}  // namespace evio::test
