#include <algorithm>
#include <cmath>

#include <Eigen/Cholesky>

#include "evio/core/error.h"
#include "evio/estimator/frontend/eklt_solver.h"

namespace evio::estimator {

EkltSolverKind parseEkltSolverKind(std::string_view name) {
  if (name == "lm") return EkltSolverKind::kLevenbergMarquardt;
  if (name == "ceres") return EkltSolverKind::kCeres;
  throw Error("solver: must be 'lm' or 'ceres' (got '" + std::string(name) + "')");
}

EkltSolution solveEklt(EkltSolverKind kind, const EkltBatch& batch, const Vec4& p0,
                       const EkltSolverSettings& settings) {
  return kind == EkltSolverKind::kCeres ? solveEkltCeres(batch, p0, settings)
                                        : solveEkltLm(batch, p0, settings);
}

EkltSolution solveEkltLm(const EkltBatch& batch, const Vec4& p0, const EkltSolverSettings& settings) {
  EkltSolution sol;
  sol.p = p0;
  EkltEvaluation cur;
  if (!evaluateEklt(batch, p0, true, &cur)) return sol;
  sol.valid = true;
  sol.iterations = 1;
  // Ceres defaults: initial trust region radius 1e4, diagonal of JᵀJ clamped
  // to [1e-6, 1e32].
  double radius = 1e4;
  double nu = 2.0;
  EkltEvaluation next;
  while (sol.iterations < settings.max_iterations) {
    if (cur.jtr.cwiseAbs().maxCoeff() <= settings.gradient_tolerance) break;
    const Vec4 diag = cur.jtj.diagonal().cwiseMax(1e-6).cwiseMin(1e32);
    Mat4 A = cur.jtj;
    A.diagonal() += diag / radius;
    const Vec4 delta = A.ldlt().solve(-cur.jtr);
    if (!delta.allFinite()) break;
    if (delta.norm() <= settings.parameter_tolerance * (sol.p.norm() + settings.parameter_tolerance)) break;
    const Vec4 candidate = sol.p + delta;
    const bool ok = evaluateEklt(batch, candidate, true, &next);
    ++sol.iterations;
    // Decrease predicted by the linear model ½‖J δ + r‖².
    const double model_decrease = -(delta.dot(cur.jtr) + 0.5 * delta.dot(cur.jtj * delta));
    const double actual_decrease = ok ? cur.cost - next.cost : -1.0;
    const double ratio = model_decrease > 0.0 ? actual_decrease / model_decrease : -1.0;
    if (ok && ratio > 1e-3) {
      const bool converged = std::abs(actual_decrease) <= settings.function_tolerance * cur.cost;
      sol.p = candidate;
      cur = next;
      radius = std::min(1e16, radius / std::max(1.0 / 3.0, 1.0 - std::pow(2.0 * ratio - 1.0, 3)));
      nu = 2.0;
      if (converged) break;
    } else {
      radius /= nu;
      nu *= 2.0;
      if (radius < 1e-32) break;
    }
  }
  sol.cost = cur.cost;
  sol.abs_sum = cur.abs_sum;
  sol.jtj = cur.jtj;
  return sol;
}

}  // namespace evio::estimator
