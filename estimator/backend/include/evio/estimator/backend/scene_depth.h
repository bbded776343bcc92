#pragma once
/// @file scene_depth.h
/// What the filter has learnt of the scene's depth, for the depth prior of
/// features it cannot triangulate (docs/algorithms.md#depth-prior-from-the-map):
/// the world points of its latest triangulations (MSCKF features and
/// triangulated SLAM initialisations) and of its converged SLAM features.

#include <cstddef>
#include <optional>
#include <vector>

#include "evio/core/eigen_types.h"
#include "evio/estimator/backend/filter_state.h"

namespace evio::estimator {

/// The last `capacity` triangulated points, world frame (m), oldest replaced first.
class TriangulatedPoints {
 public:
  explicit TriangulatedPoints(std::size_t capacity) : capacity_(capacity) {}
  void add(const Vec3& p_W);
  const std::vector<Vec3>& points() const { return points_; }

 private:
  std::size_t capacity_;
  std::size_t next_ = 0;  // slot the next point replaces once full
  std::vector<Vec3> points_;
};

/// World points (m) of the SLAM features whose inverse depth the data have
/// fixed: σ_ρ = √P_ρρ at most max_relative_sigma · ρ (ρ > 0, anchor in the window).
/// p_W = p_a + R_a [α, β, 1]ᵀ / ρ.
std::vector<Vec3> convergedSlamPoints(const FilterState& state, double max_relative_sigma);

/// The lower median of 1/z over the points in front of `clone` (z: depth
/// in the clone's camera frame, z = e_zᵀ R_W_Cᵀ (p_W − p_W_C)), 1/m;
/// nullopt when fewer than min_points are in front.
std::optional<double> medianInverseDepth(const CameraClone& clone, const std::vector<Vec3>& points,
                                         int min_points);

}  // namespace evio::estimator
