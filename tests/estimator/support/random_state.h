#pragma once
/// @file random_state.h
/// Random draws for the backend's unit tests: vectors and a covariance that
/// is symmetric positive definite, from a seeded RandomStream.

#include "evio/core/eigen_types.h"
#include "evio/core/random_stream.h"

namespace evio::test {

/// s · (N(0,1), N(0,1), N(0,1)).
inline Vec3 randomVec3(RandomStream& rng, double s) { return Vec3(rng.normal(), rng.normal(), rng.normal()) * s; }

/// scale · (A Aᵀ / n + I), A an n × n matrix of N(0,1) drawn row by row:
/// symmetric, its eigenvalues at least `scale`.
inline MatX randomSpdCovariance(int n, double scale, RandomStream& rng) {
  MatX A(n, n);
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c) A(r, c) = rng.normal();
  return scale * (A * A.transpose() / n + MatX::Identity(n, n));
}

}  // namespace evio::test
