#include "evio/trajectories/bspline_trajectory.h"

#include <algorithm>
#include <cmath>

#include "evio/core/error.h"
#include "evio/core/so3.h"
#include "evio/trajectories/taylor_rotation.h"

namespace evio {

std::array<taylor::Scalar<2>, 6> quinticBasis(const taylor::Scalar<2>& u) {
  // Cox–de Boor triangle on the integer knots with the span [0, 1): at step j
  // the knot differences right(r+1) + left(j−r) all equal j, and
  // left(k) = u + k − 1, right(k) = k − u. N[r] is the basis function of the
  // control point (span − 5 + r).
  using S = taylor::Scalar<2>;
  constexpr int kDegree = 5;
  std::array<S, kDegree + 1> n;
  n[0] = S::constant(1.0);
  for (int j = 1; j <= kDegree; ++j) {
    S saved;
    for (int r = 0; r < j; ++r) {
      const S temp = (1.0 / j) * n[static_cast<std::size_t>(r)];
      const S right = static_cast<double>(r + 1) - u;
      const S left = u + static_cast<double>(j - r - 1);
      n[static_cast<std::size_t>(r)] = saved + right * temp;
      saved = left * temp;
    }
    n[static_cast<std::size_t>(j)] = saved;
  }
  return n;
}

namespace {

TimeNs spanEnd(const std::vector<StampedPose>& samples, double duration_s) {
  require(samples.size() >= 2, "bspline trajectory: needs at least two poses");
  for (std::size_t i = 1; i < samples.size(); ++i)
    require(samples[i].t_ns > samples[i - 1].t_ns,
            "bspline trajectory: pose times must increase strictly (pose " + std::to_string(i) + ")");
  const TimeNs last = samples.back().t_ns;
  if (duration_s <= 0.0) return last;
  return std::min(last, samples.front().t_ns + secondsToNs(duration_s));
}

}  // namespace

BSplineTrajectory::BSplineTrajectory(const std::vector<StampedPose>& samples, double knot_interval_s,
                                     double duration_s, std::string config_yaml)
    : ContinuousTrajectory(samples.empty() ? 0 : samples.front().t_ns, spanEnd(samples, duration_s)),
      knot_interval_s_(knot_interval_s),
      config_yaml_(std::move(config_yaml)) {
  require(knot_interval_s > 0.0 && std::isfinite(knot_interval_s),
          "bspline trajectory: knot interval must be > 0");
  const TimeNs t0 = samples.front().t_ns;
  const TimeNs t_last = samples.back().t_ns;
  const TimeNs step = secondsToNs(knot_interval_s);
  require(step > 0, "bspline trajectory: knot interval below 1 ns");
  const std::int64_t n = (t_last - t0 + step - 1) / step + 1;  // knots cover the whole span
  control_.reserve(static_cast<std::size_t>(n));
  std::size_t k = 0;
  for (std::int64_t i = 0; i < n; ++i) {
    const TimeNs tau = std::min(t0 + i * step, t_last);
    while (k + 2 < samples.size() && samples[k + 1].t_ns <= tau) ++k;
    control_.push_back(interpolatePose(samples[k], samples[k + 1], tau));
  }
  delta_.assign(control_.size(), Vec3::Zero());
  for (std::size_t i = 1; i < control_.size(); ++i)
    delta_[i] = so3::log(control_[i - 1].quaternion().conjugate() * control_[i].quaternion());
}

ContinuousTrajectory::Motion BSplineTrajectory::motion(double t_s) const {
  const auto last = static_cast<std::int64_t>(control_.size()) - 1;
  const double s = t_s / knot_interval_s_;
  const auto j = std::clamp(static_cast<std::int64_t>(std::floor(s)), std::int64_t{0}, last);
  const taylor::Scalar<2> u = (1.0 / knot_interval_s_) * taylor::variable<2>(t_s) - static_cast<double>(j);
  const auto N = quinticBasis(u);
  const auto idx = [&](std::int64_t i) { return static_cast<std::size_t>(std::clamp(i, std::int64_t{0}, last)); };

  Motion m;
  for (int r = 0; r <= 5; ++r)
    m.p_W = m.p_W + N[static_cast<std::size_t>(r)] * control_[idx(j - 2 + r)].translation();

  m.R_W_B = taylor::Matrix3<2>::constant(control_[idx(j - 2)].rotation());
  // Cumulative weights Ñ_r = Σ_{l≥r} N_l, factors applied in order r = 1 … 5.
  std::array<taylor::Scalar<2>, 6> cumulative;
  cumulative[5] = N[5];
  for (std::size_t r = 4; r >= 1; --r) cumulative[r] = cumulative[r + 1] + N[r];
  for (int r = 1; r <= 5; ++r) {
    const std::size_t a = idx(j - 3 + r), b = idx(j - 2 + r);
    if (a == b) continue;  // both clamped to the same pose: no rotation
    m.R_W_B = m.R_W_B * taylor::expScaled(delta_[b], cumulative[static_cast<std::size_t>(r)]);
  }
  return m;
}

}  // namespace evio
