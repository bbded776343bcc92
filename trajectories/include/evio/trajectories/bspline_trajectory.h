#pragma once
/// @file bspline_trajectory.h
/// A smooth trajectory through sampled poses: a uniform quintic (degree 5)
/// B-spline in position and a cumulative quintic B-spline on SO(3) in
/// attitude (Kim, Kim & Shin 1995; Sommer et al. 2020), both C⁴, with
/// derivatives in closed form (Taylor series of the basis, taylor.h).
///
/// The poses are first resampled at the uniform knot times τ_i = t_first + iΔ
/// (linear in position, slerp in attitude) into control poses (R_i, c_i).
/// For t in [τ_j, τ_{j+1}), u = (t − τ_j)/Δ and the six weights N_r(u),
/// r = 0…5, of the uniform quintic basis act on the control poses j−2 … j+3:
///   p(t) = Σ_r N_r(u) c_{j−2+r},
///   R(t) = R_{j−2} Π_{r=1..5} Exp(Ñ_r(u) Log(R_{j−3+r}ᵀ R_{j−2+r})),
///   Ñ_r = Σ_{l≥r} N_l (cumulative basis).
/// Indices outside the samples are clamped (constant extension). The spline
/// approximates the samples rather than interpolating them: at a knot the
/// position is (c_{j−2} + 26c_{j−1} + 66c_j + 26c_{j+1} + c_{j+2})/120, so it
/// smooths noise and rounds corners over about ±2.5 Δ.

#include <array>
#include <string>
#include <vector>

#include "evio/core/pose.h"
#include "evio/trajectories/continuous_trajectory.h"
#include "evio/trajectories/taylor.h"

namespace evio {

/// The six weights N_0 … N_5 of the uniform quintic B-spline basis at the
/// local parameter u ∈ [0, 1] (a series, so derivatives come along).
std::array<taylor::Scalar<2>, 6> quinticBasis(const taylor::Scalar<2>& u);

class BSplineTrajectory final : public ContinuousTrajectory {
 public:
  /// `samples`: at least two poses T_W_B with strictly increasing times.
  /// `knot_interval_s` > 0. The trajectory spans [first sample time,
  /// min(last sample time, first + duration)] (duration 0: the whole span).
  /// `config_yaml` is returned by configYaml().
  BSplineTrajectory(const std::vector<StampedPose>& samples, double knot_interval_s,
                    double duration_s, std::string config_yaml);

  std::string configYaml() const override { return config_yaml_; }
  /// Control poses (resampled at the knots).
  const std::vector<Pose>& controlPoses() const { return control_; }

 protected:
  Motion motion(double t_s) const override;

 private:
  std::vector<Pose> control_;
  std::vector<Vec3> delta_;  // delta_[i] = Log(R_{i-1}ᵀ R_i), delta_[0] = 0
  double knot_interval_s_;
  std::string config_yaml_;
};

}  // namespace evio
