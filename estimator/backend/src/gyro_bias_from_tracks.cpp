#include "evio/estimator/backend/gyro_bias_from_tracks.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>

#include "evio/core/so3.h"

namespace evio::estimator {
namespace {

/// The gyroscope reading at t (IMU clock), linear between samples a and b.
Vec3 gyroAt(const ImuSample& a, const ImuSample& b, TimeNs t) {
  if (b.t_ns == a.t_ns) return a.gyro_B;
  const double w = static_cast<double>(t - a.t_ns) / static_cast<double>(b.t_ns - a.t_ns);
  return (1.0 - w) * a.gyro_B + w * b.gyro_B;
}

/// One feature seen at both keyframes of a pair: f_i in Ci, f_j in Cj.
struct Correspondence {
  Vec3 f_i, f_j;
};

struct Pair {
  TimeNs t_i = 0, t_j = 0;
  std::vector<Correspondence> features;
};

/// Features the two keyframes share (both lists sorted by id).
std::vector<Correspondence> shared(const BearingKeyframe& a, const BearingKeyframe& b) {
  std::vector<Correspondence> out;
  auto ia = a.bearings_C.begin(), ib = b.bearings_C.begin();
  while (ia != a.bearings_C.end() && ib != b.bearings_C.end()) {
    if (ia->first < ib->first) {
      ++ia;
    } else if (ib->first < ia->first) {
      ++ib;
    } else {
      out.push_back({ia->second, ib->second});
      ++ia, ++ib;
    }
  }
  return out;
}

/// The pair's rotation R_Ci_Cj(b).
Mat3 cameraRotation(const Pair& p, const ImuSamples& imu, const Mat3& R_B_C, const Vec3& b) {
  return R_B_C.transpose() * integrateGyroRotation(imu, p.t_i, p.t_j, b) * R_B_C;
}

/// The epipolar normals n_k = f_i × R f_j of a pair.
std::vector<Vec3> normals(const Pair& p, const Mat3& R_Ci_Cj) {
  std::vector<Vec3> n;
  n.reserve(p.features.size());
  for (const Correspondence& c : p.features) n.push_back(c.f_i.cross(R_Ci_Cj * c.f_j));
  return n;
}

double median(std::vector<double> v) {
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

/// The unit t minimising Σ w_k (tᵀ n_k)² over the kept normals: the
/// eigenvector of the smallest eigenvalue of Σ w_k n_k n_kᵀ. The weights are
/// Huber's at 1.345 robust σ of tᵀ n_k, re-weighted three times from the
/// normals' directions alone (w = 1/‖n_k‖²): a wrong correspondence has a
/// long normal and would otherwise set t alone.
Vec3 translationDirection(const std::vector<Vec3>& n, const std::vector<bool>& kept) {
  std::vector<double> w(n.size());
  for (std::size_t k = 0; k < n.size(); ++k) w[k] = 1.0 / std::max(n[k].squaredNorm(), 1e-12);
  Vec3 t = Vec3::UnitZ();
  for (int round = 0; round < 4; ++round) {
    Mat3 M = Mat3::Zero();
    for (std::size_t k = 0; k < n.size(); ++k)
      if (kept[k]) M += w[k] * n[k] * n[k].transpose();
    Eigen::SelfAdjointEigenSolver<Mat3> eig;
    eig.computeDirect(M);
    t = eig.eigenvectors().col(0);  // eigenvalues ascending
    std::vector<double> a;
    for (std::size_t k = 0; k < n.size(); ++k)
      if (kept[k]) a.push_back(std::abs(t.dot(n[k])));
    const double c = 1.345 * 1.4826 * median(a);
    for (std::size_t k = 0; k < n.size(); ++k) {
      const double r = std::abs(t.dot(n[k]));
      w[k] = r > c && c > 0.0 ? c / r : 1.0;
    }
  }
  return t;
}

/// First-order σ of r = tᵀ(f_i × g), g = R f_j, per unit bearing noise on
/// f_i and on g (each in its tangent plane). Floored: a bearing along t
/// (the focus of expansion) constrains nothing and must not get all the weight.
double residualScale(const Vec3& f_i, const Vec3& g, const Vec3& t) {
  const Vec3 d_fi = g.cross(t), d_g = t.cross(f_i);
  const double s2 = (d_fi - f_i * f_i.dot(d_fi)).squaredNorm() + (d_g - g * g.dot(d_g)).squaredNorm();
  return std::max(std::sqrt(s2), 0.05);
}

/// The linearised problem of all pairs at b: residuals r (normalised) and
/// their Jacobian J (by central differences in b, t and the scales held).
struct Linearization {
  Eigen::VectorXd r;
  Eigen::Matrix<double, Eigen::Dynamic, 3> J;
};

/// Which residuals take part: kept[p][k].
using Mask = std::vector<std::vector<bool>>;

Linearization linearize(const std::vector<Pair>& pairs, const Mask& kept, const ImuSamples& imu, const Mat3& R_B_C,
                        const Vec3& b) {
  constexpr double kStep = 1e-5;  // rad/s
  std::vector<double> r;
  std::vector<Eigen::RowVector3d> J;
  for (std::size_t p = 0; p < pairs.size(); ++p) {
    const Pair& pair = pairs[p];
    const Mat3 R = cameraRotation(pair, imu, R_B_C, b);
    const Vec3 t = translationDirection(normals(pair, R), kept[p]);
    Mat3 R_plus[3], R_minus[3];
    for (int d = 0; d < 3; ++d) {
      R_plus[d] = cameraRotation(pair, imu, R_B_C, b + kStep * Vec3::Unit(d));
      R_minus[d] = cameraRotation(pair, imu, R_B_C, b - kStep * Vec3::Unit(d));
    }
    for (std::size_t k = 0; k < pair.features.size(); ++k) {
      if (!kept[p][k]) continue;
      const Correspondence& c = pair.features[k];
      const double s = residualScale(c.f_i, R * c.f_j, t);
      const auto residual = [&](const Mat3& Rx) { return t.dot(c.f_i.cross(Rx * c.f_j)) / s; };
      r.push_back(residual(R));
      Eigen::RowVector3d row;
      for (int d = 0; d < 3; ++d) row(d) = (residual(R_plus[d]) - residual(R_minus[d])) / (2.0 * kStep);
      J.push_back(row);
    }
  }
  Linearization lin;
  lin.r = Eigen::Map<const Eigen::VectorXd>(r.data(), static_cast<Eigen::Index>(r.size()));
  lin.J.resize(static_cast<Eigen::Index>(J.size()), 3);
  for (std::size_t i = 0; i < J.size(); ++i) lin.J.row(static_cast<Eigen::Index>(i)) = J[i];
  return lin;
}



/// The robust spread of the residuals: 1.4826 · median |r|.
double robustSigma(const Eigen::VectorXd& r) {
  std::vector<double> a(static_cast<std::size_t>(r.size()));
  for (Eigen::Index i = 0; i < r.size(); ++i) a[static_cast<std::size_t>(i)] = std::abs(r(i));
  return 1.4826 * median(std::move(a));
}

/// Gauss–Newton from b over the kept residuals; returns the final
/// linearisation at b. Robust: each step weighs the residuals by Huber's
/// weights at 1.345 robust σ, so a few wrong correspondences cannot drag b
/// away before they are gated; otherwise plain least squares.
Linearization solve(const std::vector<Pair>& pairs, const Mask& kept, const ImuSamples& imu, const Mat3& R_B_C,
                    int max_iterations, bool robust, Vec3* b) {
  Linearization lin = linearize(pairs, kept, imu, R_B_C, *b);
  for (int it = 0; it < max_iterations; ++it) {
    Eigen::VectorXd w = Eigen::VectorXd::Ones(lin.r.size());
    if (robust) {
      const double c = 1.345 * robustSigma(lin.r);
      for (Eigen::Index i = 0; i < w.size(); ++i) w(i) = std::abs(lin.r(i)) > c ? c / std::abs(lin.r(i)) : 1.0;
    }
    const Mat3 H = lin.J.transpose() * w.asDiagonal() * lin.J;
    const Vec3 step = -H.ldlt().solve(lin.J.transpose() * w.asDiagonal() * lin.r);
    if (!step.allFinite()) break;
    *b += step;
    lin = linearize(pairs, kept, imu, R_B_C, *b);
    if (step.norm() < 1e-9) break;
  }
  return lin;
}

}  // namespace

Mat3 integrateGyroRotation(const ImuSamples& imu, TimeNs t0_ns, TimeNs t1_ns, const Vec3& b_g) {
  Mat3 R = Mat3::Identity();
  for (std::size_t k = 0; k + 1 < imu.size(); ++k) {
    const ImuSample& a = imu[k];
    const ImuSample& c = imu[k + 1];
    const TimeNs lo = std::max(a.t_ns, t0_ns), hi = std::min(c.t_ns, t1_ns);
    if (hi <= lo) continue;
    const Vec3 w = 0.5 * (gyroAt(a, c, lo) + gyroAt(a, c, hi)) - b_g;
    R = R * so3::exp(w * nsToSeconds(hi - lo));
  }
  return so3::orthonormalize(R);
}

GyroBiasEstimate estimateGyroBiasFromTracks(const std::vector<BearingKeyframe>& keyframes, const ImuSamples& imu,
                                            const Mat3& R_B_C, const Vec3& prior_b_g, const Mat3& prior_covariance,
                                            const GyroBiasFromTracksOptions& options) {
  GyroBiasEstimate out;
  out.b_g = prior_b_g;
  out.covariance = prior_covariance;
  std::vector<Pair> pairs;
  // Keyframe i pairs with i + m, m = ⌈K/2⌉: each keyframe in one pair at
  // most, so white bearing errors do not correlate the pairs, and every pair
  // spans half the window (the bias's signal grows with the span).
  const std::size_t m = (keyframes.size() + 1) / 2;
  for (std::size_t i = 0; i + m < keyframes.size(); ++i) {
    Pair p{keyframes[i].t_imu_ns, keyframes[i + m].t_imu_ns, shared(keyframes[i], keyframes[i + m])};
    if (static_cast<int>(p.features.size()) >= options.min_features) pairs.push_back(std::move(p));
  }
  if (pairs.size() < 2) return out;
  Mask kept(pairs.size());
  for (std::size_t p = 0; p < pairs.size(); ++p) kept[p].assign(pairs[p].features.size(), true);
  // A robust solve on everything, then the residuals beyond outlier_sigmas
  // of the robust spread dropped and a least-squares solve on the rest.
  Vec3 b = prior_b_g;
  Linearization lin = solve(pairs, kept, imu, R_B_C, options.max_iterations, true, &b);
  const double gate = options.outlier_sigmas * robustSigma(lin.r);
  Eigen::Index i = 0;
  for (std::size_t p = 0; p < pairs.size(); ++p)
    for (std::size_t k = 0; k < pairs[p].features.size(); ++k, ++i)
      if (std::abs(lin.r(i)) > gate) kept[p][k] = false, ++out.outliers;
  lin = solve(pairs, kept, imu, R_B_C, options.max_iterations, false, &b);

  // Each pair's direction t takes two degrees of freedom, the bias three.
  const int dof = static_cast<int>(lin.r.size()) - 3 - 2 * static_cast<int>(pairs.size());
  if (dof < 1 || !b.allFinite()) return out;
  const double sigma2 = lin.r.squaredNorm() / dof;
  const Mat3 data_information = lin.J.transpose() * lin.J / sigma2;
  const Mat3 prior_information = prior_covariance.inverse();
  const Mat3 posterior = (data_information + prior_information).inverse();
  out.b_g = posterior * (data_information * b + prior_information * prior_b_g);
  out.covariance = 0.5 * (posterior + posterior.transpose());
  out.from_tracks = true;
  out.pairs = static_cast<int>(pairs.size());
  out.residuals = static_cast<int>(lin.r.size());
  out.bearing_sigma_rad = std::sqrt(sigma2);
  out.data_b_g = b;
  out.data_covariance = data_information.inverse();
  return out;
}

}  // namespace evio::estimator
