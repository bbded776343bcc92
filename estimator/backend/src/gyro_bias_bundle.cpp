// The gyroscope bias by a bundle adjustment of the window's keyframes
// (gyro_bias_from_tracks.h, refineGyroBiasByBundleAdjustment): the two-view
// epipolar cost is biased along the valley where a rotation error trades
// off against a tilted translation (a narrow field of view: 1.88 °/s mean
// error at 0.5 px of noise on a synthetic wall), the reprojection error
// much less (0.37 °/s).
//
// Unknowns: the bias b; the camera centres c_k of keyframes 1..K−1 in the
// first keyframe's camera frame C0 (c_0 = 0); per feature the inverse depth
// ρ along its bearing u at its first keyframe a (the anchor). The rotations
// are the gyroscope's, R_k(b) = R_B_Cᵀ ΔR_B(t_0 → t_k; b) R_B_C. The feature
// is X = c_a + R_a u / ρ, seen from keyframe k along
//   d = R_kᵀ (ρ (c_a − c_k) + R_a u)          (X − c_k scaled by ρ: finite at ρ = 0),
// and its residual is d/‖d‖ − f in the tangent plane of the measured f (two
// angles). The scale is fixed by the inverse depth of the feature seen most
// often (ρ = 1). Levenberg–Marquardt with Huber weights, then a 3σ gate and a
// least-squares solve; the covariance is the bias block of σ² (JᵀJ)⁻¹ with σ²
// from the residuals.
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include "evio/core/so3.h"
#include "evio/estimator/backend/gyro_bias_from_tracks.h"
#include "robust_fit.h"

namespace evio::estimator {
namespace {

struct Observation {
  int feature = 0;   // index into the features
  int keyframe = 0;  // k, never the feature's anchor
  Vec3 f;            // measured unit bearing in C_k
  Mat23 tangent;     // rows: an orthonormal basis of f's tangent plane
};

struct Feature {
  int anchor = 0;  // keyframe a
  Vec3 u;          // unit bearing in C_a
};

struct Problem {
  std::vector<Feature> features;
  std::vector<Observation> observations;
  std::vector<TimeNs> t_imu;  // keyframe times
  int reference = 0;          // the feature whose ρ fixes the scale
};

Mat23 tangentBasis(const Vec3& f) {
  const Vec3 e1 = f.unitOrthogonal();
  Mat23 T;
  T.row(0) = e1.transpose();
  T.row(1) = f.cross(e1).transpose();
  return T;
}

/// Features seen at min_keyframes keyframes or more, anchored at the first.
Problem buildProblem(const std::vector<BearingKeyframe>& keyframes, int min_keyframes) {
  std::map<FeatureId, std::vector<std::pair<int, Vec3>>> seen;
  for (std::size_t k = 0; k < keyframes.size(); ++k)
    for (const auto& [id, f] : keyframes[k].bearings_C) seen[id].emplace_back(static_cast<int>(k), f);
  Problem p;
  for (const BearingKeyframe& kf : keyframes) p.t_imu.push_back(kf.t_imu_ns);
  std::size_t most = 0;
  for (const auto& [id, obs] : seen) {
    if (static_cast<int>(obs.size()) < min_keyframes) continue;
    const int j = static_cast<int>(p.features.size());
    p.features.push_back({obs.front().first, obs.front().second});
    for (std::size_t i = 1; i < obs.size(); ++i)
      p.observations.push_back({j, obs[i].first, obs[i].second, tangentBasis(obs[i].second)});
    if (obs.size() > most) most = obs.size(), p.reference = j;
  }
  return p;
}

/// The unknowns. Camera part: b and c_1..c_{K−1}, 3 + 3(K − 1) numbers;
/// point part, per feature: ρ and the anchor bearing's tangent offset δ (u =
/// normalise(u₀ + T(u₀)ᵀ δ)); the reference feature's ρ stays 1.
struct State {
  Vec3 b = Vec3::Zero();
  std::vector<Vec3> c;      // per keyframe, c[0] = 0
  std::vector<Vec3> point;  // per feature: (ρ, δ₁, δ₂)
};

Vec3 anchorBearing(const Feature& f, const Vec3& point) {
  return (f.u + tangentBasis(f.u).transpose() * point.tail<2>()).normalized();
}

/// R_C0_Ck(b) of every keyframe.
std::vector<Mat3> rotations(const Problem& p, const ImuSamples& imu, const Mat3& R_B_C, const Vec3& b) {
  std::vector<Mat3> R;
  for (TimeNs t : p.t_imu) R.push_back(R_B_C.transpose() * integrateGyroRotation(imu, p.t_imu.front(), t, b) * R_B_C);
  return R;
}

Vec2 residual(const Observation& o, const Feature& f, const std::vector<Mat3>& R, const Vec3& c_a, const Vec3& c_k,
              const Vec3& point) {
  const Vec3 d = R[static_cast<std::size_t>(o.keyframe)].transpose() *
                 (point(0) * (c_a - c_k) + R[static_cast<std::size_t>(f.anchor)] * anchorBearing(f, point));
  return o.tangent * (d.normalized() - o.f);
}

/// The anchor's own residual: the anchor bearing against its measurement.
Vec2 anchorResidual(const Feature& f, const Vec3& point) { return tangentBasis(f.u) * (anchorBearing(f, point) - f.u); }

/// All residuals at s, in a fixed order: per observation (kept or not), then per feature's anchor.
Eigen::VectorXd residuals(const Problem& p, const ImuSamples& imu, const Mat3& R_B_C, const State& s) {
  const std::vector<Mat3> R = rotations(p, imu, R_B_C, s.b);
  Eigen::VectorXd r(2 * (p.observations.size() + p.features.size()));
  Eigen::Index row = 0;
  for (const Observation& o : p.observations) {
    const Feature& f = p.features[static_cast<std::size_t>(o.feature)];
    r.segment<2>(row) = residual(o, f, R, s.c[static_cast<std::size_t>(f.anchor)],
                                 s.c[static_cast<std::size_t>(o.keyframe)], s.point[static_cast<std::size_t>(o.feature)]);
    row += 2;
  }
  for (std::size_t j = 0; j < p.features.size(); ++j, row += 2) r.segment<2>(row) = anchorResidual(p.features[j], s.point[j]);
  return r;
}

/// The normal equations in the camera / point split (Schur complement), the
/// weights w per residual (0: dropped).
struct Normal {
  Eigen::MatrixXd H_cc;
  Eigen::VectorXd g_c;
  std::vector<Mat3> H_pp;
  std::vector<Eigen::Matrix<double, Eigen::Dynamic, 3>> H_cp;
  std::vector<Vec3> g_p;
};

int cameraSize(const Problem& p) { return 3 + 3 * (static_cast<int>(p.t_imu.size()) - 1); }
int centreColumn(int k) { return k == 0 ? -1 : 3 + 3 * (k - 1); }

Normal normalEquations(const Problem& p, const ImuSamples& imu, const Mat3& R_B_C, const State& s,
                       const Eigen::VectorXd& r, const Eigen::VectorXd& w) {
  constexpr double kStepB = 1e-6, kStep = 1e-7;
  const int nc = cameraSize(p);
  Normal N;
  N.H_cc = Eigen::MatrixXd::Zero(nc, nc);
  N.g_c = Eigen::VectorXd::Zero(nc);
  N.H_pp.assign(p.features.size(), Mat3::Zero());
  N.H_cp.assign(p.features.size(), Eigen::Matrix<double, Eigen::Dynamic, 3>::Zero(nc, 3));
  N.g_p.assign(p.features.size(), Vec3::Zero());
  const std::vector<Mat3> R = rotations(p, imu, R_B_C, s.b);
  std::vector<Mat3> R_plus[3], R_minus[3];
  for (int d = 0; d < 3; ++d) {
    R_plus[d] = rotations(p, imu, R_B_C, s.b + kStepB * Vec3::Unit(d));
    R_minus[d] = rotations(p, imu, R_B_C, s.b - kStepB * Vec3::Unit(d));
  }
  Eigen::Index row = 0;
  for (const Observation& o : p.observations) {
    const std::size_t j = static_cast<std::size_t>(o.feature);
    const Feature& f = p.features[j];
    const Vec3& c_a = s.c[static_cast<std::size_t>(f.anchor)];
    const Vec3& c_k = s.c[static_cast<std::size_t>(o.keyframe)];
    const Vec3& pt = s.point[j];
    const Eigen::Vector2d w2 = w.segment<2>(row);
    const Vec2 r2 = r.segment<2>(row);
    row += 2;
    if (w2.isZero()) continue;
    Eigen::Matrix<double, 2, Eigen::Dynamic> Jc = Eigen::Matrix<double, 2, Eigen::Dynamic>::Zero(2, nc);
    Mat23 Jp = Mat23::Zero();
    for (int d = 0; d < 3; ++d) {
      Jc.col(d) = (residual(o, f, R_plus[d], c_a, c_k, pt) - residual(o, f, R_minus[d], c_a, c_k, pt)) / (2 * kStepB);
      const Vec3 h = kStep * Vec3::Unit(d);
      if (const int col = centreColumn(f.anchor); col >= 0)
        Jc.col(col + d) += (residual(o, f, R, c_a + h, c_k, pt) - residual(o, f, R, c_a - h, c_k, pt)) / (2 * kStep);
      if (const int col = centreColumn(o.keyframe); col >= 0)
        Jc.col(col + d) += (residual(o, f, R, c_a, c_k + h, pt) - residual(o, f, R, c_a, c_k - h, pt)) / (2 * kStep);
      if (d == 0 && static_cast<int>(j) == p.reference) continue;  // ρ of the reference is fixed
      Jp.col(d) = (residual(o, f, R, c_a, c_k, pt + h) - residual(o, f, R, c_a, c_k, pt - h)) / (2 * kStep);
    }
    const Eigen::Matrix2d W = w2.asDiagonal();
    N.H_cc += Jc.transpose() * W * Jc;
    N.g_c += Jc.transpose() * W * r2;
    N.H_cp[j] += Jc.transpose() * W * Jp;
    N.H_pp[j] += Jp.transpose() * W * Jp;
    N.g_p[j] += Jp.transpose() * W * r2;
  }
  for (std::size_t j = 0; j < p.features.size(); ++j, row += 2) {
    const Eigen::Vector2d w2 = w.segment<2>(row);
    Mat23 Jp = Mat23::Zero();
    for (int d = 1; d < 3; ++d) {
      const Vec3 h = kStep * Vec3::Unit(d);
      Jp.col(d) = (anchorResidual(p.features[j], s.point[j] + h) - anchorResidual(p.features[j], s.point[j] - h)) /
                  (2 * kStep);
    }
    N.H_pp[j] += Jp.transpose() * w2.asDiagonal() * Jp;
    N.g_p[j] += Jp.transpose() * w2.asDiagonal() * Vec2(r.segment<2>(row));
    if (static_cast<int>(j) == p.reference) N.H_pp[j](0, 0) = 1.0;  // δρ = 0
  }
  return N;
}

/// The LM step for damping λ: the camera part from the reduced system
/// S δc = −(g_c − Σ H_cp H_pp⁻¹ g_p), then each point's.
State step(const Normal& N, const State& s, double lambda, Eigen::MatrixXd* S_out = nullptr) {
  Eigen::MatrixXd S = N.H_cc;
  S.diagonal() += lambda * (N.H_cc.diagonal().array() + 1e-12).matrix();
  Eigen::VectorXd rhs = -N.g_c;
  std::vector<Mat3> H_pp_inv(N.H_pp.size());
  for (std::size_t j = 0; j < N.H_pp.size(); ++j) {
    // A ridge of 1e-12: a point whose observations were all gated, or any
    // point of a camera that only turned, has no information on its ρ.
    Mat3 H = N.H_pp[j];
    H.diagonal() += (lambda * N.H_pp[j].diagonal().array() + 1e-12).matrix();
    H_pp_inv[j] = H.inverse();
    S -= N.H_cp[j] * H_pp_inv[j] * N.H_cp[j].transpose();
    rhs += N.H_cp[j] * H_pp_inv[j] * N.g_p[j];
  }
  const Eigen::VectorXd dc = S.ldlt().solve(rhs);
  if (S_out) *S_out = S;
  State next = s;
  next.b += dc.head<3>();
  for (std::size_t k = 1; k < s.c.size(); ++k) next.c[k] += dc.segment<3>(centreColumn(static_cast<int>(k)));
  for (std::size_t j = 0; j < s.point.size(); ++j)
    next.point[j] += H_pp_inv[j] * (-N.g_p[j] - N.H_cp[j].transpose() * dc);
  return next;
}

/// The robust σ of the residuals the mask keeps (robust_fit.h).
double robustSpread(const Eigen::VectorXd& r, const Eigen::VectorXd& kept) {
  std::vector<double> a;
  for (Eigen::Index i = 0; i < r.size(); ++i)
    if (kept(i) > 0.0) a.push_back(std::abs(r(i)));
  return robust::sigmaOfAbsolute(std::move(a));
}

/// Huber's weights over the kept residuals (the mask's 0s stay 0).
Eigen::VectorXd weights(const Eigen::VectorXd& r, const Eigen::VectorXd& kept, bool huber) {
  Eigen::VectorXd w = kept;
  if (!huber) return w;
  const double c = robust::kHuberSigmas * robustSpread(r, kept);
  for (Eigen::Index i = 0; i < r.size(); ++i)
    if (kept(i) > 0.0) w(i) = robust::huberWeight(r(i), c);
  return w;
}

double cost(const Eigen::VectorXd& r, const Eigen::VectorXd& w) { return (w.array() * r.array().square()).sum(); }

/// Levenberg–Marquardt from s; each iteration's weights from its start.
void solve(const Problem& p, const ImuSamples& imu, const Mat3& R_B_C, const Eigen::VectorXd& kept,
           int max_iterations, bool huber, State* s) {
  Eigen::VectorXd r = residuals(p, imu, R_B_C, *s);
  double lambda = 1e-3;
  for (int it = 0; it < max_iterations; ++it) {
    const Eigen::VectorXd w = weights(r, kept, huber);
    const Normal N = normalEquations(p, imu, R_B_C, *s, r, w);
    const double before = cost(r, w);
    bool accepted = false;
    for (int attempt = 0; attempt < 10 && !accepted; ++attempt) {
      const State trial = step(N, *s, lambda);
      if (!trial.b.allFinite()) break;
      const Eigen::VectorXd r_trial = residuals(p, imu, R_B_C, trial);
      if (cost(r_trial, w) < before) {
        const bool converged = (trial.b - s->b).norm() < 1e-10 && before - cost(r_trial, w) < 1e-12 * before;
        *s = trial;
        r = r_trial;
        lambda = std::max(lambda / 10.0, 1e-9);
        accepted = true;
        if (converged) return;
      } else {
        lambda *= 10.0;
      }
    }
    if (!accepted) return;
  }
}

}  // namespace

BundleBiasEstimate refineGyroBiasByBundleAdjustment(const std::vector<BearingKeyframe>& keyframes,
                                                    const ImuSamples& imu, const Mat3& R_B_C, const Vec3& b_start,
                                                    const GyroBiasFromTracksOptions& options) {
  BundleBiasEstimate out;
  const Problem p = buildProblem(keyframes, options.min_keyframes_per_feature);
  if (p.features.size() < static_cast<std::size_t>(options.min_features) || keyframes.size() < 3) return out;
  State s;
  s.b = b_start;
  s.c.assign(keyframes.size(), Vec3::Zero());
  s.point.assign(p.features.size(), Vec3(1.0, 0.0, 0.0));
  Eigen::VectorXd kept = Eigen::VectorXd::Ones(static_cast<Eigen::Index>(2 * (p.observations.size() + p.features.size())));
  solve(p, imu, R_B_C, kept, options.max_iterations, true, &s);
  // Gate whole observations (both angles) beyond outlier_sigmas robust σ.
  Eigen::VectorXd r = residuals(p, imu, R_B_C, s);
  Eigen::VectorXd observation_rows = kept;  // the spread of the observations, not the anchors'
  observation_rows.tail(static_cast<Eigen::Index>(2 * p.features.size())).setZero();
  const double gate = options.outlier_sigmas * robustSpread(r, observation_rows);
  for (std::size_t i = 0; i < p.observations.size(); ++i) {
    const Eigen::Index row = static_cast<Eigen::Index>(2 * i);
    if (r.segment<2>(row).cwiseAbs().maxCoeff() > gate) kept.segment<2>(row).setZero(), ++out.outliers;
  }
  solve(p, imu, R_B_C, kept, options.max_iterations, false, &s);
  r = residuals(p, imu, R_B_C, s);
  // Unknowns: the camera part, three per feature, less the fixed ρ and the
  // ρ of features whose observations were all gated.
  std::vector<bool> observed(p.features.size(), false);
  for (std::size_t i = 0; i < p.observations.size(); ++i)
    if (kept(static_cast<Eigen::Index>(2 * i)) > 0.0) observed[static_cast<std::size_t>(p.observations[i].feature)] = true;
  const int unobserved = static_cast<int>(std::count(observed.begin(), observed.end(), false));
  const int unknowns = cameraSize(p) + 3 * static_cast<int>(p.features.size()) - 1 - unobserved;
  const int used = static_cast<int>(kept.sum());
  const int dof = used - unknowns;
  if (dof < 1 || !s.b.allFinite()) return out;
  const double sigma2 = cost(r, kept) / dof;
  const Normal N = normalEquations(p, imu, R_B_C, s, r, kept);
  Eigen::MatrixXd S;
  step(N, s, 0.0, &S);
  S.diagonal().array() += 1e-12 * S.diagonal().maxCoeff();  // a camera that only turned leaves the centres free
  const Eigen::MatrixXd cov = sigma2 * S.ldlt().solve(Eigen::MatrixXd::Identity(S.rows(), S.cols()));
  out.valid = cov.allFinite();
  out.b_g = s.b;
  out.covariance = 0.5 * (cov.topLeftCorner<3, 3>() + cov.topLeftCorner<3, 3>().transpose());
  out.bearing_sigma_rad = std::sqrt(sigma2);
  out.observations = (used - 2 * static_cast<int>(p.features.size())) / 2;
  out.features = static_cast<int>(p.features.size());
  return out;
}

}  // namespace evio::estimator
