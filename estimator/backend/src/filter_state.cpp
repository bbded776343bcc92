#include "evio/estimator/backend/filter_state.h"

#include <cmath>

#include "evio/core/error.h"
#include "evio/core/so3.h"

namespace evio::estimator {

int FilterState::findClone(std::int64_t id) const {
  for (std::size_t i = 0; i < clones.size(); ++i)
    if (clones[i].id == id) return static_cast<int>(i);
  return -1;
}

int FilterState::findFeature(FeatureId id) const {
  for (std::size_t j = 0; j < features.size(); ++j)
    if (features[j].id == id) return static_cast<int>(j);
  return -1;
}

void FilterState::correct(const VecX& dx) {
  require(dx.size() == dim(), "FilterState::correct: correction has the wrong size");
  imu.p_W_B += dx.segment<3>(kIdxP);
  imu.v_W += dx.segment<3>(kIdxV);
  imu.q_W_B = (imu.q_W_B * so3::expQuat(dx.segment<3>(kIdxTheta))).normalized();
  imu.b_g += dx.segment<3>(kIdxBg);
  imu.b_a += dx.segment<3>(kIdxBa);
  for (std::size_t i = 0; i < clones.size(); ++i) {
    const int k = cloneIndex(i);
    clones[i].p_W_C += dx.segment<3>(k + kCloneP);
    clones[i].q_W_C = (clones[i].q_W_C * so3::expQuat(dx.segment<3>(k + kCloneTheta))).normalized();
  }
  for (std::size_t j = 0; j < features.size(); ++j) {
    features[j].abr += dx.segment<3>(featureIndex(j));
    if (hasTrackErrors()) features[j].track_error += dx.segment<2>(featureIndex(j) + kFeatureDim);
  }
  if (has_image_shift) image_shift += dx.segment<kImageShiftDim>(imageShiftIndex());
  if (has_scene_depth) scene_rho += dx(sceneDepthIndex());
}

namespace {

// Inserts `rows` new rows/columns at `index` of the square P: the new block B
// (k×k) and cross terms C (k × n, in the old index space).
void insertRowsCols(MatX& P, int index, const MatX& C, const MatX& B) {
  const int n = static_cast<int>(P.rows());
  const int k = static_cast<int>(B.rows());
  const int tail = n - index;
  MatX out(n + k, n + k);
  out.topLeftCorner(index, index) = P.topLeftCorner(index, index);
  out.topRightCorner(index, tail) = P.topRightCorner(index, tail);
  out.bottomLeftCorner(tail, index) = P.bottomLeftCorner(tail, index);
  out.bottomRightCorner(tail, tail) = P.bottomRightCorner(tail, tail);
  out.block(index, index, k, k) = B;
  out.block(index, 0, k, index) = C.leftCols(index);
  out.block(index, index + k, k, tail) = C.rightCols(tail);
  out.block(0, index, index, k) = C.leftCols(index).transpose();
  out.block(index + k, index, tail, k) = C.rightCols(tail).transpose();
  P.swap(out);
}

}  // namespace

void addImageShiftToRows(const FilterState& state, std::size_t c, const Mat2& W, Eigen::Index row, MatX* H,
                         VecX* r) {
  if (!state.has_image_shift || !state.isNewestClone(c)) return;
  H->block<2, kImageShiftDim>(row, state.imageShiftIndex()) += W;
  r->segment<2>(row) -= W * state.image_shift;
}

void removeRowsCols(MatX& P, int index, int size) {
  const int n = static_cast<int>(P.rows());
  const int tail = n - index - size;
  MatX out(n - size, n - size);
  out.topLeftCorner(index, index) = P.topLeftCorner(index, index);
  out.topRightCorner(index, tail) = P.topRightCorner(index, tail);
  out.bottomLeftCorner(tail, index) = P.bottomLeftCorner(tail, index);
  out.bottomRightCorner(tail, tail) = P.bottomRightCorner(tail, tail);
  P.swap(out);
}

void FilterState::addClone(const CameraClone& clone,
                           const Eigen::Matrix<double, kCloneDim, Eigen::Dynamic>& J) {
  require(J.cols() == dim(), "FilterState::addClone: Jacobian has the wrong size");
  const MatX C = J * P;                       // cov(δc, δx)
  const MatX B = C * J.transpose();           // cov(δc, δc)
  insertRowsCols(P, featureIndex(0), C, B);   // after the last clone
  clones.push_back(clone);
}

void FilterState::removeClone(std::size_t i) {
  require(i < clones.size(), "FilterState::removeClone: no such clone");
  removeRowsCols(P, cloneIndex(i), kCloneDim);
  clones.erase(clones.begin() + static_cast<std::ptrdiff_t>(i));
}

void FilterState::addFeature(const SlamFeature& f, const Mat3& P_ff,
                             const Eigen::Matrix<double, 3, Eigen::Dynamic>& P_fx) {
  require(P_fx.cols() == dim(), "FilterState::addFeature: cross-covariance has the wrong size");
  if (!hasTrackErrors()) {
    insertRowsCols(P, featureIndex(features.size()), P_fx, P_ff);  // after the last feature, before s and ρ_s
    features.push_back(f);
    return;
  }
  MatX B = MatX::Zero(feature_dim, feature_dim);
  B.topLeftCorner<3, 3>() = P_ff;
  B.topLeftCorner<2, 2>() += track_error_cov;
  B.block<2, 2>(0, kFeatureDim) = -track_error_cov;
  B.block<2, 2>(kFeatureDim, 0) = -track_error_cov;
  B.block<2, 2>(kFeatureDim, kFeatureDim) = track_error_cov;
  MatX C = MatX::Zero(feature_dim, dim());
  C.topRows<3>() = P_fx;
  insertRowsCols(P, featureIndex(features.size()), C, B);
  SlamFeature g = f;
  g.track_error.setZero();
  features.push_back(g);
}

void FilterState::removeFeature(std::size_t j) {
  require(j < features.size(), "FilterState::removeFeature: no such feature");
  removeRowsCols(P, featureIndex(j), feature_dim);
  features.erase(features.begin() + static_cast<std::ptrdiff_t>(j));
}

void FilterState::addSceneDepth(double rho, double variance) {
  require(!has_scene_depth, "FilterState::addSceneDepth: the state has a scene depth already");
  require(std::isfinite(rho) && variance > 0.0 && std::isfinite(variance),
          "FilterState::addSceneDepth: the scene depth needs a finite mean and a positive variance");
  insertRowsCols(P, dim(), MatX::Zero(1, dim()), MatX::Constant(1, 1, variance));
  has_scene_depth = true;
  scene_rho = rho;
}

void FilterState::addImageShift(const Mat2& cov, double time_s) {
  require(!has_image_shift, "FilterState::addImageShift: the state has an image shift already");
  require(cov.allFinite() && cov.determinant() > 0.0 && cov(0, 0) > 0.0 && time_s > 0.0,
          "FilterState::addImageShift: the shift needs a positive-definite covariance and a positive time");
  insertRowsCols(P, imageShiftIndex(), MatX::Zero(kImageShiftDim, dim()), cov);
  has_image_shift = true;
  image_shift.setZero();
  image_shift_cov = cov;
  image_shift_time_s = time_s;
}

VecX FilterState::yawDirection(const ImuState& x) const {
  // The rotation is about the vertical through the centroid c of the position
  // states (IMU and clones, first estimates), so that n is orthogonal to every
  // global translation t (Σ_k e_z × (p_k − c) = 0): projecting n out of a row
  // that is blind to translation (H t = 0) then keeps it blind.
  const Vec3 e_z = Vec3::UnitZ();
  Vec3 c = x.p_W_B;
  for (const CameraClone& clone : clones) c += clone.p_fej;
  c /= static_cast<double>(clones.size() + 1);
  VecX n = VecX::Zero(dim());
  n.segment<3>(kIdxP) = e_z.cross(x.p_W_B - c);
  n.segment<3>(kIdxV) = e_z.cross(x.v_W);
  n.segment<3>(kIdxTheta) = x.q_W_B.conjugate() * e_z;
  for (std::size_t i = 0; i < clones.size(); ++i) {
    const int k = cloneIndex(i);
    n.segment<3>(k + kCloneP) = e_z.cross(clones[i].p_fej - c);
    n.segment<3>(k + kCloneTheta) = clones[i].q_fej.conjugate() * e_z;
  }
  return n;
}

VecX FilterState::minus(const FilterState& ref) const {
  require(clones.size() == ref.clones.size() && features.size() == ref.features.size() &&
              has_scene_depth == ref.has_scene_depth && has_image_shift == ref.has_image_shift &&
              feature_dim == ref.feature_dim,
          "FilterState::minus: states of different layouts");
  VecX d(dim());
  d.segment<3>(kIdxP) = imu.p_W_B - ref.imu.p_W_B;
  d.segment<3>(kIdxV) = imu.v_W - ref.imu.v_W;
  d.segment<3>(kIdxTheta) = so3::log(Quat(ref.imu.q_W_B.conjugate() * imu.q_W_B));
  d.segment<3>(kIdxBg) = imu.b_g - ref.imu.b_g;
  d.segment<3>(kIdxBa) = imu.b_a - ref.imu.b_a;
  for (std::size_t i = 0; i < clones.size(); ++i) {
    const int k = cloneIndex(i);
    d.segment<3>(k + kCloneP) = clones[i].p_W_C - ref.clones[i].p_W_C;
    d.segment<3>(k + kCloneTheta) = so3::log(Quat(ref.clones[i].q_W_C.conjugate() * clones[i].q_W_C));
  }
  for (std::size_t j = 0; j < features.size(); ++j) {
    d.segment<3>(featureIndex(j)) = features[j].abr - ref.features[j].abr;
    if (hasTrackErrors())
      d.segment<2>(featureIndex(j) + kFeatureDim) = features[j].track_error - ref.features[j].track_error;
  }
  if (has_image_shift) d.segment<kImageShiftDim>(imageShiftIndex()) = image_shift - ref.image_shift;
  if (has_scene_depth) d(sceneDepthIndex()) = scene_rho - ref.scene_rho;
  return d;
}

void FilterState::symmetrize() {
  const MatX Pt = P.transpose();
  P = 0.5 * (P + Pt);
}

}  // namespace evio::estimator
