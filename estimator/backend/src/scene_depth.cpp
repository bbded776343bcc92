#include "evio/estimator/backend/scene_depth.h"

#include <algorithm>
#include <cmath>

namespace evio::estimator {

void TriangulatedPoints::add(const Vec3& p_W) {
  if (capacity_ == 0 || !p_W.allFinite()) return;
  if (points_.size() < capacity_) {
    points_.push_back(p_W);
    return;
  }
  points_[next_] = p_W;
  next_ = (next_ + 1) % capacity_;
}

std::vector<Vec3> convergedSlamPoints(const FilterState& state, double max_relative_sigma) {
  std::vector<Vec3> out;
  for (std::size_t j = 0; j < state.features.size(); ++j) {
    const SlamFeature& f = state.features[j];
    const double rho = f.abr.z();
    const int k = state.featureIndex(j) + 2;
    if (!(rho > 0.0) || !(std::sqrt(state.P(k, k)) <= max_relative_sigma * rho)) continue;
    const int a = state.findClone(f.anchor_clone_id);
    if (a < 0) continue;
    const CameraClone& anchor = state.clones[static_cast<std::size_t>(a)];
    out.push_back(anchor.p_W_C + anchor.R_W_C() * Vec3(f.abr.x(), f.abr.y(), 1.0) / rho);
  }
  return out;
}

std::optional<double> medianInverseDepth(const CameraClone& clone, const std::vector<Vec3>& points,
                                         int min_points) {
  const Mat3 R_C_W = clone.R_W_C().transpose();
  std::vector<double> inverse_depths;
  inverse_depths.reserve(points.size());
  for (const Vec3& p_W : points) {
    const double z = (R_C_W * (p_W - clone.p_W_C)).z();
    if (z > 0.0 && std::isfinite(z)) inverse_depths.push_back(1.0 / z);
  }
  if (inverse_depths.empty() || static_cast<int>(inverse_depths.size()) < min_points) return std::nullopt;
  // The lower median: an element of the set, whatever the count's parity.
  const auto mid = inverse_depths.begin() + static_cast<std::ptrdiff_t>((inverse_depths.size() - 1) / 2);
  std::nth_element(inverse_depths.begin(), mid, inverse_depths.end());
  return *mid;
}

}  // namespace evio::estimator
