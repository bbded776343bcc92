#pragma once
/// @file eklt_solver.h
/// Minimisers of the EKLT cost (eklt_cost.h): the Ceres reference (dense QR,
/// Levenberg–Marquardt, non-monotonic steps, automatic differentiation through
/// ceres::BiCubicInterpolator) and a hand-written 4-parameter
/// Levenberg–Marquardt with the analytic Jacobian for the hot path. Both sample
/// the template with the same Catmull-Rom bicubic scheme and stop on the same
/// tolerances; tests/estimator/eklt_solver_test.cpp shows they agree.

#include <string_view>

#include "evio/core/eigen_types.h"
#include "evio/estimator/frontend/eklt_cost.h"

namespace evio::estimator {

/// Which minimiser the tracker uses.
enum class EkltSolverKind { kLevenbergMarquardt, kCeres };

/// "lm" / "ceres" ↔ EkltSolverKind; throws evio::Error "solver: ..." otherwise.
EkltSolverKind parseEkltSolverKind(std::string_view name);

/// Stopping rules (the meaning of Ceres' fields of the same names).
struct EkltSolverSettings {
  int max_iterations = 25;             ///< iterations (Ceres: max_num_iterations)
  double function_tolerance = 1e-6;    ///< stop when |Δcost| ≤ tol · cost
  double parameter_tolerance = 1e-8;   ///< stop when ‖δp‖ ≤ tol · (‖p‖ + tol)
  double gradient_tolerance = 1e-10;   ///< stop when max|Jᵀr| ≤ tol
};

struct EkltSolution {
  Vec4 p = Vec4::Zero();     ///< (θ, tx, ty, φ) at the minimum
  double cost = 0.0;         ///< ½‖r‖² at p
  double abs_sum = 0.0;      ///< Σ|a(u)| at p (eklt_cost.h)
  Mat4 jtj = Mat4::Zero();   ///< JᵀJ at p (for the position covariance)
  int iterations = 0;        ///< cost evaluations with a Jacobian
  bool valid = false;        ///< false when the cost could not be evaluated
  double quality() const { return 1.0 - 0.5 * cost; }
};

/// Hand-written Levenberg–Marquardt on the 4×4 normal equations, with Ceres'
/// trust-region rules (μ = 1/radius, radius grows by 1/max(1/3, 1 − (2ρ−1)³)
/// after a good step and shrinks by ν = 2, 4, 8, … after a bad one) and
/// Jacobian scaling by diag(JᵀJ). No allocation.
EkltSolution solveEkltLm(const EkltBatch& batch, const Vec4& p0, const EkltSolverSettings& settings);

/// The Ceres reference solver.
EkltSolution solveEkltCeres(const EkltBatch& batch, const Vec4& p0, const EkltSolverSettings& settings);

/// Dispatches on `kind`.
EkltSolution solveEklt(EkltSolverKind kind, const EkltBatch& batch, const Vec4& p0,
                       const EkltSolverSettings& settings);

}  // namespace evio::estimator
