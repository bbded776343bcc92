// The Ceres reference minimiser of the EKLT cost (eklt_cost.h), kept as in
// the paper: automatic differentiation, dense QR, Levenberg–Marquardt with
// non-monotonic steps.
#include <ceres/ceres.h>
#include <ceres/cubic_interpolation.h>

#include <cmath>
#include <vector>

#include "evio/estimator/frontend/eklt_solver.h"

namespace evio::estimator {

namespace {

using Grid = ceres::Grid2D<float, 2, /*kRowMajor=*/true, /*kInterleaved=*/true>;
using Interpolator = ceres::BiCubicInterpolator<Grid>;

struct EkltResidual {
  const Interpolator* interpolator;
  const float* measured;
  int patch_size;
  double origin_x;
  double origin_y;

  template <class T>
  bool operator()(const T* p, T* residuals) const {
    using std::cos;
    using std::sin;
    using std::sqrt;
    const int P = patch_size;
    const double h = 0.5 * (P - 1);
    const T c = cos(p[0]);
    const T s = sin(p[0]);
    const T vx = cos(p[3]);
    const T vy = sin(p[3]);
    const T wx = c * vx - s * vy;  // R v
    const T wy = s * vx + c * vy;
    T norm2(0.0);
    for (int i = 0; i < P; ++i) {
      for (int j = 0; j < P; ++j) {
        const double ux = j - h;
        const double uy = i - h;
        const T Wx = c * ux - s * uy + p[1];
        const T Wy = s * ux + c * uy + p[2];
        T g[2];
        interpolator->Evaluate(Wy - origin_y, Wx - origin_x, g);
        const T a = -(g[0] * wx + g[1] * wy);
        residuals[i * P + j] = a;
        norm2 += a * a;
      }
    }
    if (!(norm2 > T(0.0))) return false;
    const T n = sqrt(norm2);
    for (int k = 0; k < P * P; ++k) residuals[k] = residuals[k] / n - T(static_cast<double>(measured[k]));
    return true;
  }
};

}  // namespace

EkltSolution solveEkltCeres(const EkltBatch& batch, const Vec4& p0, const EkltSolverSettings& settings) {
  EkltSolution sol;
  sol.p = p0;
  const GradientTemplate& templ = *batch.templ;
  const Grid grid(templ.data(), 0, templ.size(), 0, templ.size());
  const Interpolator interpolator(grid);
  const int n_residuals = batch.patch_size * batch.patch_size;

  double params[4] = {p0[0], p0[1], p0[2], p0[3]};
  ceres::Problem::Options problem_options;
  problem_options.cost_function_ownership = ceres::TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  auto* cost = new ceres::AutoDiffCostFunction<EkltResidual, ceres::DYNAMIC, 4>(
      new EkltResidual{&interpolator, batch.measured, batch.patch_size, static_cast<double>(templ.originX()),
                       static_cast<double>(templ.originY())},
      n_residuals);
  problem.AddResidualBlock(cost, nullptr, params);

  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  options.minimizer_type = ceres::TRUST_REGION;
  options.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  options.use_nonmonotonic_steps = true;
  options.max_num_iterations = settings.max_iterations;
  options.function_tolerance = settings.function_tolerance;
  options.parameter_tolerance = settings.parameter_tolerance;
  options.gradient_tolerance = settings.gradient_tolerance;
  options.num_threads = 1;
  options.logging_type = ceres::SILENT;
  options.minimizer_progress_to_stdout = false;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);

  sol.p = Vec4(params[0], params[1], params[2], params[3]);
  sol.iterations = summary.num_successful_steps + summary.num_unsuccessful_steps;
  EkltEvaluation eval;
  sol.valid = summary.IsSolutionUsable() && evaluateEklt(batch, sol.p, true, &eval);
  if (sol.valid) {
    sol.cost = eval.cost;
    sol.abs_sum = eval.abs_sum;
    sol.jtj = eval.jtj;
  }
  return sol;
}

}  // namespace evio::estimator
