#pragma once
/// @file numeric_state_jacobian.h
/// Central differences over the backend's full error state, for checking
/// analytic Jacobians: J(:, k) = (f(x ⊞ h e_k) − f(x ⊞ −h e_k)) / 2h, where
/// x ⊞ d is FilterState::correct(d) (rotations right-perturbed).

#include "evio/estimator/backend/filter_state.h"

namespace evio::test {

/// f: FilterState → a vector of `rows` entries.
template <class F>
MatX numericStateJacobian(const estimator::FilterState& s, F&& f, int rows, double h = 1e-6) {
  MatX J(rows, s.dim());
  for (int k = 0; k < s.dim(); ++k) {
    estimator::FilterState sp = s, sm = s;
    VecX d = VecX::Zero(s.dim());
    d(k) = h;
    sp.correct(d);
    sm.correct(-d);
    J.col(k) = (f(sp) - f(sm)) / (2.0 * h);
  }
  return J;
}

}  // namespace evio::test
