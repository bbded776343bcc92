#include "evio/estimator/backend/gyro_bias_from_tracks.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Eigenvalues>

#include "evio/core/so3.h"
#include "robust_fit.h"

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

/// The unit t minimising Σ w_k (tᵀ n_k)² over the kept normals: the
/// eigenvector of the smallest eigenvalue of Σ w_k n_k n_kᵀ, its sign that of
/// `near`.
Vec3 weightedDirection(const std::vector<Vec3>& n, const std::vector<bool>& kept, const std::vector<double>& w,
                       const Vec3& near) {
  Mat3 M = Mat3::Zero();
  for (std::size_t k = 0; k < n.size(); ++k)
    if (kept[k]) M += w[k] * n[k] * n[k].transpose();
  Eigen::SelfAdjointEigenSolver<Mat3> eig;
  eig.computeDirect(M);
  const Vec3 t = eig.eigenvectors().col(0);  // eigenvalues ascending
  return t.dot(near) < 0.0 ? Vec3(-t) : t;
}

/// Robust weights for weightedDirection: Huber's at 1.345 robust σ of
/// tᵀ n_k, re-weighted three times from the normals' directions alone
/// (w = 1/‖n_k‖²): a wrong correspondence has a long normal and would
/// otherwise set t alone.
std::vector<double> directionWeights(const std::vector<Vec3>& n, const std::vector<bool>& kept) {
  std::vector<double> w(n.size());
  for (std::size_t k = 0; k < n.size(); ++k) w[k] = 1.0 / std::max(n[k].squaredNorm(), 1e-12);
  for (int round = 0; round < 3; ++round) {
    const Vec3 t = weightedDirection(n, kept, w, Vec3::UnitZ());
    std::vector<double> a;
    for (std::size_t k = 0; k < n.size(); ++k)
      if (kept[k]) a.push_back(std::abs(t.dot(n[k])));
    const double c = robust::kHuberSigmas * robust::kMadToSigma * robust::median(std::move(a));
    for (std::size_t k = 0; k < n.size(); ++k) w[k] = robust::huberWeight(t.dot(n[k]), c);
  }
  return w;
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
/// their Jacobian J by central differences in b, each pair's t following b
/// (re-solved with the weights of b; variable projection: with t held, the
/// steps crawl along the valley where a rotation error and a tilted t trade
/// off), the scales s_k held.
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
    const std::vector<Vec3> n = normals(pair, R);
    // t minimises the normalised cost Σ w_k (tᵀ n_k / s_k)², the scales
    // s_k taken at the previous t (twice from the robust fit): with t from
    // the raw cost, t and b would minimise different costs and b is biased
    // (0.56 °/s at 0.5 px of noise on a simulated cloud).
    std::vector<double> w = directionWeights(n, kept[p]);
    Vec3 t = weightedDirection(n, kept[p], w, Vec3::UnitZ());
    const std::vector<double> w_robust = w;
    for (int round = 0; round < 2; ++round) {
      for (std::size_t k = 0; k < n.size(); ++k) {
        const Correspondence& c = pair.features[k];
        const double s = residualScale(c.f_i, R * c.f_j, t);
        w[k] = w_robust[k] / (s * s);
      }
      t = weightedDirection(n, kept[p], w, t);
    }
    Mat3 R_plus[3], R_minus[3];
    Vec3 t_plus[3], t_minus[3];
    for (int d = 0; d < 3; ++d) {
      R_plus[d] = cameraRotation(pair, imu, R_B_C, b + kStep * Vec3::Unit(d));
      R_minus[d] = cameraRotation(pair, imu, R_B_C, b - kStep * Vec3::Unit(d));
      t_plus[d] = weightedDirection(normals(pair, R_plus[d]), kept[p], w, t);
      t_minus[d] = weightedDirection(normals(pair, R_minus[d]), kept[p], w, t);
    }
    for (std::size_t k = 0; k < pair.features.size(); ++k) {
      if (!kept[p][k]) continue;
      const Correspondence& c = pair.features[k];
      const double s = residualScale(c.f_i, R * c.f_j, t);
      const auto residual = [&](const Mat3& Rx, const Vec3& tx) { return tx.dot(c.f_i.cross(Rx * c.f_j)) / s; };
      r.push_back(residual(R, t));
      Eigen::RowVector3d row;
      for (int d = 0; d < 3; ++d)
        row(d) = (residual(R_plus[d], t_plus[d]) - residual(R_minus[d], t_minus[d])) / (2.0 * kStep);
      J.push_back(row);
    }
  }
  Linearization lin;
  lin.r = Eigen::Map<const Eigen::VectorXd>(r.data(), static_cast<Eigen::Index>(r.size()));
  lin.J.resize(static_cast<Eigen::Index>(J.size()), 3);
  for (std::size_t i = 0; i < J.size(); ++i) lin.J.row(static_cast<Eigen::Index>(i)) = J[i];
  return lin;
}

/// The robust σ of the residuals (robust_fit.h).
double robustSigma(const Eigen::VectorXd& r) {
  std::vector<double> a(static_cast<std::size_t>(r.size()));
  for (Eigen::Index i = 0; i < r.size(); ++i) a[static_cast<std::size_t>(i)] = std::abs(r(i));
  return robust::sigmaOfAbsolute(std::move(a));
}

/// Gauss–Newton from b over the kept residuals; returns the final
/// linearisation at b. Robust: each step weighs the residuals by Huber's
/// weights at 1.345 robust σ, so a few wrong correspondences cannot drag b
/// away before they are gated; otherwise plain least squares.
Linearization solve(const std::vector<Pair>& pairs, const Mask& kept, const ImuSamples& imu, const Mat3& R_B_C,
                    int max_iterations, bool huber, Vec3* b) {
  Linearization lin = linearize(pairs, kept, imu, R_B_C, *b);
  for (int it = 0; it < max_iterations; ++it) {
    Eigen::VectorXd w = Eigen::VectorXd::Ones(lin.r.size());
    if (huber) {
      const double c = robust::kHuberSigmas * robustSigma(lin.r);
      for (Eigen::Index i = 0; i < w.size(); ++i) w(i) = robust::huberWeight(lin.r(i), c);
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

/// A pair's body rotation near b0 to first order: R(b) ≈ R0 · Exp(G (b − b0)).
struct PairRotationModel {
  Mat3 R0, G;
};

/// The search's cost at b0 + delta: Σ over pairs of λ_min(Σ_k u_k u_kᵀ), u_k
/// the unit epipolar normals (each feature the same weight).
double eigenvalueCost(const std::vector<Pair>& pairs, const std::vector<PairRotationModel>& models, const Mat3& R_B_C,
                      const Vec3& delta) {
  double cost = 0.0;
  for (std::size_t p = 0; p < pairs.size(); ++p) {
    const Mat3 R = R_B_C.transpose() * models[p].R0 * so3::exp(models[p].G * delta) * R_B_C;
    Mat3 M = Mat3::Zero();
    for (const Correspondence& c : pairs[p].features) {
      const Vec3 n = c.f_i.cross(R * c.f_j);
      M += n * n.transpose();
    }
    Eigen::SelfAdjointEigenSolver<Mat3> eig;
    eig.computeDirect(M, Eigen::EigenvaluesOnly);
    cost += eig.eigenvalues()(0);
  }
  return cost;
}

/// Starting points for Gauss–Newton: the options.starts lowest points of
/// the eigenvalue cost on a grid over the prior's ±grid_sigmas · σ box (per
/// axis, grid_steps_per_sigma points per σ), the rotations to first order in
/// the bias.
std::vector<Vec3> gridStarts(const std::vector<Pair>& pairs, const ImuSamples& imu, const Mat3& R_B_C,
                             const Vec3& prior_b_g, const Mat3& prior_covariance,
                             const GyroBiasFromTracksOptions& options) {
  constexpr double kStep = 1e-3;  // rad/s, for G
  std::vector<PairRotationModel> models;
  for (const Pair& p : pairs) {
    PairRotationModel m;
    m.R0 = integrateGyroRotation(imu, p.t_i, p.t_j, prior_b_g);
    for (int d = 0; d < 3; ++d)
      m.G.col(d) =
          so3::log(m.R0.transpose() * integrateGyroRotation(imu, p.t_i, p.t_j, prior_b_g + kStep * Vec3::Unit(d))) /
          kStep;
    models.push_back(m);
  }
  const int half = static_cast<int>(std::lround(options.grid_sigmas * options.grid_steps_per_sigma));
  const Vec3 step = prior_covariance.diagonal().cwiseSqrt() / options.grid_steps_per_sigma;
  std::vector<std::pair<double, Vec3>> scored;
  for (int x = -half; x <= half; ++x)
    for (int y = -half; y <= half; ++y)
      for (int z = -half; z <= half; ++z) {
        const Vec3 delta = step.cwiseProduct(Vec3(x, y, z));
        scored.emplace_back(eigenvalueCost(pairs, models, R_B_C, delta), prior_b_g + delta);
      }
  const std::size_t n = std::min(static_cast<std::size_t>(options.starts), scored.size());
  std::partial_sort(scored.begin(), scored.begin() + static_cast<std::ptrdiff_t>(n), scored.end(),
                    [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<Vec3> starts;
  for (std::size_t i = 0; i < n; ++i) starts.push_back(scored[i].second);
  return starts;
}

/// The covariance's check against the data: the bundle adjustment on each
/// half of the window (keyframes 0..m−1 and m..K−1, m = K/2, no keyframe in
/// both) gives b₁ and b₂, independent estimates for white track errors, so
/// d = b₁ − b₂ has covariance
/// C₁ + C₂. q = dᵀ(C₁ + C₂)⁻¹d / 3 is then about 1; track errors that are
/// correlated over the window, which σ²(JᵀJ)⁻¹ takes as white, make it
/// larger. Returns max(1, q) (1 when a half cannot be solved), q in *q_out.
double splitHalfInflation(const std::vector<BearingKeyframe>& keyframes, const ImuSamples& imu, const Mat3& R_B_C,
                          const Vec3& b, const GyroBiasFromTracksOptions& options, double* q_out) {
  *q_out = 0.0;
  const std::size_t m = keyframes.size() / 2;
  if (m < 3 || keyframes.size() - m < 3) return 1.0;
  const std::vector<BearingKeyframe> first(keyframes.begin(), keyframes.begin() + static_cast<std::ptrdiff_t>(m));
  const std::vector<BearingKeyframe> second(keyframes.begin() + static_cast<std::ptrdiff_t>(m), keyframes.end());
  const BundleBiasEstimate e1 = refineGyroBiasByBundleAdjustment(first, imu, R_B_C, b, options);
  const BundleBiasEstimate e2 = refineGyroBiasByBundleAdjustment(second, imu, R_B_C, b, options);
  if (!e1.valid || !e2.valid) return 1.0;
  const Vec3 d = e1.b_g - e2.b_g;
  const double q = d.dot((e1.covariance + e2.covariance).inverse() * d) / 3.0;
  if (!std::isfinite(q)) return 1.0;
  *q_out = q;
  return std::max(1.0, q);
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
  // Gauss–Newton from each start; the solution with the smallest robust
  // spread of its residuals wins.
  Vec3 b = prior_b_g;
  Linearization lin;
  double best = std::numeric_limits<double>::infinity();
  for (const Vec3& start : gridStarts(pairs, imu, R_B_C, prior_b_g, prior_covariance, options)) {
    Vec3 candidate = start;
    Linearization l = solve(pairs, kept, imu, R_B_C, options.max_iterations, true, &candidate);
    const double spread = robustSigma(l.r);
    if (spread < best && candidate.allFinite()) best = spread, b = candidate, lin = std::move(l);
  }
  if (!std::isfinite(best)) return out;
  const double gate = options.outlier_sigmas * robustSigma(lin.r);
  Eigen::Index i = 0;
  for (std::size_t p = 0; p < pairs.size(); ++p)
    for (std::size_t k = 0; k < pairs[p].features.size(); ++k, ++i)
      if (std::abs(lin.r(i)) > gate) kept[p][k] = false, ++out.outliers;
  // A pair left with fewer than min_features residuals is dropped whole.
  int pairs_used = 0;
  for (std::size_t p = 0; p < pairs.size(); ++p) {
    if (std::count(kept[p].begin(), kept[p].end(), true) >= options.min_features)
      ++pairs_used;
    else
      std::fill(kept[p].begin(), kept[p].end(), false);
  }
  if (pairs_used < 2) return out;
  lin = solve(pairs, kept, imu, R_B_C, options.max_iterations, false, &b);

  // Each pair's direction t takes two degrees of freedom, the bias three.
  const int dof = static_cast<int>(lin.r.size()) - 3 - 2 * pairs_used;
  if (dof < 1 || !b.allFinite()) return out;
  double sigma2 = lin.r.squaredNorm() / dof;
  Mat3 data_covariance = sigma2 * (lin.J.transpose() * lin.J).inverse();
  if (options.bundle_adjustment) {
    const BundleBiasEstimate ba = refineGyroBiasByBundleAdjustment(keyframes, imu, R_B_C, b, options);
    if (ba.valid && ba.b_g.allFinite()) {
      b = ba.b_g;
      data_covariance = ba.covariance;
      if (options.split_half_check)
        data_covariance *= splitHalfInflation(keyframes, imu, R_B_C, b, options, &out.split_half_q);
      sigma2 = ba.bearing_sigma_rad * ba.bearing_sigma_rad;
    }
  }
  const Mat3 data_information = data_covariance.inverse();
  const Mat3 prior_information = prior_covariance.inverse();
  const Mat3 posterior = (data_information + prior_information).inverse();
  // A degenerate window (no residual spread, a singular information) leaves
  // the prior standing rather than giving the filter a covariance it cannot take.
  if (!data_information.allFinite() || !posterior.allFinite() ||
      Eigen::SelfAdjointEigenSolver<Mat3>(0.5 * (posterior + posterior.transpose()), Eigen::EigenvaluesOnly)
              .eigenvalues()(0) <= 0.0)
    return out;
  out.b_g = posterior * (data_information * b + prior_information * prior_b_g);
  out.covariance = 0.5 * (posterior + posterior.transpose());
  out.from_tracks = true;
  out.pairs = static_cast<int>(pairs.size());
  out.residuals = static_cast<int>(lin.r.size());
  out.bearing_sigma_rad = std::sqrt(sigma2);
  out.data_b_g = b;
  out.data_covariance = data_covariance;
  return out;
}

}  // namespace evio::estimator
