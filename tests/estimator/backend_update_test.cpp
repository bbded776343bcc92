// Triangulation, null-space projection, re-anchoring, QR compression and the
// EKF update of the backend against exact ground truth.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>

#include "evio/core/random_stream.h"
#include "random_state.h"
#include "evio/core/so3.h"
#include "evio/estimator/backend/chi_squared.h"
#include "evio/estimator/backend/ekf_update.h"
#include "evio/estimator/backend/msckf_update.h"
#include "evio/estimator/backend/slam_features.h"
#include "evio/estimator/backend/triangulation.h"
#include "evio/estimator/backend/updater.h"
#include "evio/estimator/backend/visual_models.h"

namespace evio::estimator {
namespace {

using test::randomSpdCovariance;
using test::randomVec3;

// n clones along a short arc, looking along +x of W.
std::vector<CameraClone> arcOfClones(int n, std::uint64_t seed, double baseline_m = 0.3) {
  RandomStream rng(seed, "clones");
  Mat3 R_look;
  R_look.col(0) = Vec3(0, -1, 0);
  R_look.col(1) = Vec3(0, 0, -1);
  R_look.col(2) = Vec3(1, 0, 0);
  std::vector<CameraClone> out;
  for (int i = 0; i < n; ++i) {
    CameraClone c;
    c.id = i;
    c.p_W_C = Vec3(0.0, baseline_m * i / std::max(1, n - 1), 0.05 * std::sin(i)) + randomVec3(rng, 0.01);
    c.q_W_C = Quat(R_look * so3::exp(randomVec3(rng, 0.05)));
    out.push_back(c);
  }
  return out;
}

/// The exact projections of p_W in every clone (fewer when one fails).
std::vector<Vec2> exactObservations(const std::vector<CameraClone>& clones, const Vec3& p_W) {
  std::vector<Vec2> z;
  for (const CameraClone& c : clones) {
    Vec2 zi;
    if (!projectWorldPoint(c, p_W, &zi)) break;
    z.push_back(zi);
  }
  return z;
}

FilterState stateWith(const std::vector<CameraClone>& clones, std::uint64_t seed) {
  RandomStream rng(seed, "cov");
  FilterState s;
  s.clones = clones;
  s.P = randomSpdCovariance(s.dim(), 1e-4, rng);
  return s;
}

TEST(BackendTriangulation, ExactObservationsGiveTheExactPoint) {
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    RandomStream rng(seed, "point");
    const auto clones = arcOfClones(2 + static_cast<int>(seed % 9), seed);
    const Vec3 p_true = Vec3(rng.uniform(1.0, 20.0), rng.uniform(-2, 2), rng.uniform(-2, 2));
    std::vector<Vec2> z;
    for (const CameraClone& c : clones) {
      Vec2 zi;
      ASSERT_TRUE(projectWorldPoint(c, p_true, &zi));
      z.push_back(zi);
    }
    TriangulationResult res;
    ASSERT_TRUE(triangulateFeature(clones, z, clones.size() - 1, TriangulationOptions{}, &res)) << seed;
    EXPECT_LT((res.p_W - p_true).norm(), 1e-9 * p_true.norm()) << "seed " << seed;
    EXPECT_LT(res.rms_residual, 1e-12);
  }
}

TEST(BackendTriangulation, RejectsDegenerateAndBehindPoints) {
  auto clones = arcOfClones(3, 5);
  for (auto& c : clones) c.p_W_C = clones[0].p_W_C;  // no baseline at all
  std::vector<Vec2> z(3, Vec2(0.01, 0.02));
  TriangulationResult res;
  EXPECT_FALSE(triangulateFeature(clones, z, 2, TriangulationOptions{}, &res));
  EXPECT_FALSE(triangulateFeature({clones[0]}, {z[0]}, 0, TriangulationOptions{}, &res));
  // Rays that meet behind the cameras.
  auto arc = arcOfClones(3, 6);
  std::vector<Vec2> zb;
  for (const auto& c : arc) {
    const Vec3 h = c.R_W_C().transpose() * (Vec3(-5.0, 0.1, 0.0) - c.p_W_C);
    zb.push_back(h.head<2>() / h.z());
  }
  EXPECT_FALSE(triangulateFeature(arc, zb, 2, TriangulationOptions{}, &res));
}

TEST(BackendTriangulation, RotationCompensatedDisparity) {
  auto clones = arcOfClones(3, 7);
  for (auto& c : clones) c.p_W_C.setZero();  // pure rotation: no parallax
  const Vec3 p(6.0, 0.5, -0.3);
  std::vector<Vec2> z;
  for (const auto& c : clones) {
    Vec2 zi;
    ASSERT_TRUE(projectWorldPoint(c, p, &zi));
    z.push_back(zi);
  }
  EXPECT_LT(rotationCompensatedDisparity(clones, z), 1e-12);
  clones[0].p_W_C = Vec3(0.0, 0.6, 0.0);  // 0.6 m sideways at 6 m: about 0.1 rad
  ASSERT_TRUE(projectWorldPoint(clones[0], p, &z[0]));
  EXPECT_NEAR(rotationCompensatedDisparity(clones, z), 0.1, 0.02);
}

// σ_ρ of the triangulation is the spread of the inverse depth it returns when
// the observations carry Gaussian noise: 4000 noisy triangulations of one
// point (noise 1e-4 normalised, the linear regime) give a sample σ of ρ
// within 5 % of σ_z · sigma_rho_unit (the sample σ of 4000 draws is itself
// within ±2.2 % at 2σ). A shorter baseline gives a larger σ_ρ; knowsDepth
// compares it with the bound.
TEST(BackendTriangulation, InverseDepthSigmaIsTheSpreadOfNoisyTriangulations) {
  const auto clones = arcOfClones(6, 11, 0.2);
  const Vec3 p(4.0, 0.3, -0.2);
  const std::vector<Vec2> z = exactObservations(clones, p);
  ASSERT_EQ(z.size(), clones.size());
  TriangulationResult exact;
  ASSERT_TRUE(triangulateFeature(clones, z, clones.size() - 1, TriangulationOptions{}, &exact));
  ASSERT_TRUE(std::isfinite(exact.sigma_rho_unit));
  const double sigma_z = 1e-4;
  RandomStream rng(3, "noise");
  double sum = 0.0, sum2 = 0.0;
  const int draws = 4000;
  for (int k = 0; k < draws; ++k) {
    std::vector<Vec2> zn = z;
    for (Vec2& v : zn) v += sigma_z * Vec2(rng.normal(), rng.normal());
    TriangulationResult res;
    ASSERT_TRUE(triangulateFeature(clones, zn, clones.size() - 1, TriangulationOptions{}, &res));
    sum += res.abr.z();
    sum2 += res.abr.z() * res.abr.z();
  }
  const double mean = sum / draws;
  const double spread = std::sqrt(sum2 / draws - mean * mean);
  EXPECT_NEAR(spread / (sigma_z * exact.sigma_rho_unit), 1.0, 0.05);

  // Half the baseline: less information about the depth.
  const auto shorter = arcOfClones(6, 11, 0.1);
  const std::vector<Vec2> zs = exactObservations(shorter, p);
  ASSERT_EQ(zs.size(), shorter.size());
  TriangulationResult near_baseline;
  ASSERT_TRUE(triangulateFeature(shorter, zs, shorter.size() - 1, TriangulationOptions{}, &near_baseline));
  EXPECT_GT(near_baseline.sigma_rho_unit, exact.sigma_rho_unit);

  TriangulationOptions bound;
  bound.sigma_z = sigma_z;
  bound.max_sigma_rho = 1.01 * sigma_z * exact.sigma_rho_unit;
  EXPECT_TRUE(knowsDepth(exact, bound));
  bound.max_sigma_rho = 0.99 * sigma_z * exact.sigma_rho_unit;
  EXPECT_FALSE(knowsDepth(exact, bound));
  bound.max_sigma_rho = 0.0;  // no bound
  EXPECT_TRUE(knowsDepth(exact, bound));
}

TEST(BackendNullSpace, ProjectionRemovesTheFeature) {
  const auto clones = arcOfClones(6, 8);
  FilterState s = stateWith(clones, 8);
  const Vec3 p_true(5.0, 0.4, -0.2);
  FeatureTrack track;
  track.id = 1;
  RandomStream rng(8, "noise");
  for (const auto& c : clones) {
    Vec2 zi;
    ASSERT_TRUE(projectWorldPoint(c, p_true, &zi));
    track.observations.push_back({c.id, zi + Vec2(rng.normal(), rng.normal()) * 1e-3});
  }
  MsckfResidual res;
  ASSERT_EQ(msckfResidual(s, track, 0.0, TriangulationOptions{}, &res), MsckfOutcome::kOk);
  EXPECT_EQ(res.r.size(), 2 * 6 - 3);
  EXPECT_EQ(res.H.cols(), s.dim());

  // H_fᵀ N = 0 for the null space N the projection used.
  MatX H_f(12, 3), H_x = MatX::Zero(12, s.dim());
  VecX r(12);
  for (std::size_t i = 0; i < clones.size(); ++i) {
    Vec2 zh;
    Mat26 Hc;
    Mat23 Hp;
    ASSERT_TRUE(projectWorldPoint(clones[i], res.p_W, &zh, &Hc, &Hp));
    H_f.block<2, 3>(2 * static_cast<Eigen::Index>(i), 0) = Hp;
    H_x.block<2, 6>(2 * static_cast<Eigen::Index>(i), s.cloneIndex(i)) = Hc;
    r.segment<2>(2 * static_cast<Eigen::Index>(i)) = track.observations[i].z - zh;
  }
  MatX N;
  MatX Hx2 = H_x;
  VecX r2 = r;
  projectOnLeftNullSpace(H_f, &Hx2, &r2, &N);
  EXPECT_LT((H_f.transpose() * N).norm(), 1e-12 * H_f.norm());
  EXPECT_LT((N.transpose() * N - MatX::Identity(9, 9)).norm(), 1e-12);
  EXPECT_LT((r2 - res.r).norm(), 1e-12);

  // The projected residual does not depend on the feature's error (to first
  // order): moving the point by 1 mm changes r by ~1e-4, N^T r by O(1e-8).
  for (const Vec3& d : {Vec3(1e-3, 0, 0), Vec3(0, 1e-3, 0), Vec3(0, 0, 1e-3)}) {
    VecX rd(12);
    for (std::size_t i = 0; i < clones.size(); ++i) {
      Vec2 zh;
      ASSERT_TRUE(projectWorldPoint(clones[i], res.p_W + d, &zh));
      rd.segment<2>(2 * static_cast<Eigen::Index>(i)) = track.observations[i].z - zh;
    }
    EXPECT_GT((rd - r).norm(), 1e-5);
    EXPECT_LT((N.transpose() * (rd - r)).norm(), 1e-7);
  }
}

// World point of feature j and its covariance, J P Jᵀ with J = ∂p_W/∂δx.
std::pair<Vec3, Mat3> worldPointAndCovariance(const FilterState& s, std::size_t j) {
  const SlamFeature& f = s.features[j];
  const auto a = static_cast<std::size_t>(s.findClone(f.anchor_clone_id));
  Mat36 J_a;
  Mat3 J_f;
  const Vec3 p = anchoredToWorld(s.clones[a], f.abr, &J_a, &J_f);
  MatX J = MatX::Zero(3, s.dim());
  J.block<3, 6>(0, s.cloneIndex(a)) = J_a;
  J.block<3, 3>(0, s.featureIndex(j)) = J_f;
  return {p, J * s.P * J.transpose()};
}

TEST(BackendReanchoring, PreservesWorldPointAndItsCovariance) {
  const auto clones = arcOfClones(5, 9);
  FilterState s = stateWith(clones, 9);
  RandomStream rng(9, "features");
  for (int j = 0; j < 3; ++j) {
    SlamFeature f;
    f.id = j;
    f.anchor_clone_id = 0;
    ASSERT_TRUE(worldToAnchored(clones[0], Vec3(4.0 + j, 0.3 * j, -0.2), &f.abr));
    MatX C(3, s.dim());
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < s.dim(); ++c) C(r, c) = 1e-6 * rng.normal();
    s.addFeature(f, Vec3(1e-4, 1e-4, 4e-3).asDiagonal(), C);
  }
  ASSERT_GT(Eigen::SelfAdjointEigenSolver<MatX>(s.P).eigenvalues().minCoeff(), 0.0);
  for (std::size_t j = 0; j < 3; ++j) {
    const auto [p0, C0] = worldPointAndCovariance(s, j);
    const MatX P_before = s.P;
    ASSERT_TRUE(reanchorSlamFeature(s, j, 4));
    EXPECT_EQ(s.features[j].anchor_clone_id, 4);
    const auto [p1, C1] = worldPointAndCovariance(s, j);
    EXPECT_LT((p1 - p0).norm(), 1e-12 * p0.norm());
    EXPECT_LT((C1 - C0).norm(), 1e-9 * C0.norm()) << "feature " << j;
    // Everything but the feature's rows and columns is untouched.
    const int k = s.featureIndex(j);
    EXPECT_TRUE(s.P.topLeftCorner(k, k) == P_before.topLeftCorner(k, k));
    EXPECT_LT((s.P - s.P.transpose()).norm(), 1e-18);
  }
  EXPECT_GT(Eigen::SelfAdjointEigenSolver<MatX>(s.P).eigenvalues().minCoeff(), 0.0);
}

/// m random residual rows over n states: H ~ N(0, 1), r ~ N(0, 1e-6).
UpdateRows randomRows(int m, int n, std::uint64_t seed) {
  RandomStream rng(seed, "H");
  UpdateRows rows{MatX(m, n), VecX(m)};
  for (int i = 0; i < m; ++i) {
    rows.r(i) = 1e-3 * rng.normal();
    for (int k = 0; k < n; ++k) rows.H(i, k) = rng.normal();
  }
  return rows;
}

TEST(BackendEkfUpdate, QrCompressionAndJosephFormGiveTheSameUpdate) {
  const auto clones = arcOfClones(4, 10);
  const FilterState s0 = stateWith(clones, 10);
  const int n = s0.dim();
  const auto [H, r] = randomRows(60, n, 10);
  const double sigma2 = 1e-4;
  FilterState a = s0, b = s0, c = s0;
  ASSERT_TRUE(ekfUpdate(a, H, r, sigma2, true));
  MatX Hc = H;
  VecX rc = r;
  compressMeasurement(&Hc, &rc);
  EXPECT_EQ(Hc.rows(), n);
  ASSERT_TRUE(ekfUpdate(b, Hc, rc, sigma2, true));
  ASSERT_TRUE(ekfUpdate(c, H, r, sigma2, false));
  EXPECT_LT((a.P - b.P).norm(), 1e-10 * a.P.norm());
  EXPECT_LT((a.P - c.P).norm(), 1e-10 * a.P.norm());
  for (std::size_t i = 0; i < clones.size(); ++i) {
    EXPECT_LT((a.clones[i].p_W_C - b.clones[i].p_W_C).norm(), 1e-12);
    EXPECT_LT(angleBetween(a.clones[i].q_W_C, b.clones[i].q_W_C), 1e-12);
  }
  EXPECT_LT((a.P - a.P.transpose()).norm(), 1e-18);
  EXPECT_GT(Eigen::SelfAdjointEigenSolver<MatX>(a.P).eigenvalues().minCoeff(), 0.0);
  // The default update P − K S Kᵀ (no Joseph form) is symmetric and positive definite too.
  EXPECT_LT((c.P - c.P.transpose()).norm(), 1e-18);
  EXPECT_GT(Eigen::SelfAdjointEigenSolver<MatX>(c.P).eigenvalues().minCoeff(), 0.0);
  EXPECT_DOUBLE_EQ(mahalanobisSquared(MatX::Identity(1, n), VecX::Zero(1), s0.P, 1.0), 0.0);
}

// ekfUpdate's Joseph form is evaluated in O(n² m); it must equal the textbook
// (I − KH) P (I − KH)ᵀ + σ² K Kᵀ with K = P Hᵀ (H P Hᵀ + σ² I)⁻¹, written out
// with explicit n × n products, for a few rows (m ≪ n, the usual case).
TEST(BackendEkfUpdate, JosephFormEqualsTheTextbookProduct) {
  const FilterState s0 = stateWith(arcOfClones(4, 10), 10);
  const int m = 5, n = s0.dim();
  const auto [H, r] = randomRows(m, n, 11);
  const double sigma2 = 1e-4;
  FilterState a = s0;
  ASSERT_TRUE(ekfUpdate(a, H, r, sigma2, true));
  const MatX S = H * s0.P * H.transpose() + sigma2 * MatX::Identity(m, m);
  const MatX K = s0.P * H.transpose() * S.inverse();
  const MatX IKH = MatX::Identity(n, n) - K * H;
  const MatX expected = IKH * s0.P * IKH.transpose() + sigma2 * K * K.transpose();
  EXPECT_LT((a.P - expected).norm(), 1e-10 * s0.P.norm());
  EXPECT_LT((a.P - a.P.transpose()).norm(), 1e-18);
}

// covariance_factor κ: the gain keeps σ², the covariance is that of the
// estimate under noise κ σ², (I − KH) P (I − KH)ᵀ + κ σ² K Kᵀ, in both forms;
// the mean moves exactly as with κ = 1. The iterated update passes κ on.
TEST(BackendEkfUpdate, CovarianceFactorKeepsTheGainAndWidensTheNoiseTerm) {
  const FilterState s0 = stateWith(arcOfClones(4, 10), 10);
  const int m = 5, n = s0.dim();
  const auto [H, r] = randomRows(m, n, 12);
  const double sigma2 = 1e-4, kappa = 3.0;
  const MatX S = H * s0.P * H.transpose() + sigma2 * MatX::Identity(m, m);
  const MatX K = s0.P * H.transpose() * S.inverse();
  const MatX IKH = MatX::Identity(n, n) - K * H;
  const MatX expected = IKH * s0.P * IKH.transpose() + kappa * sigma2 * K * K.transpose();
  FilterState optimal = s0;
  ASSERT_TRUE(ekfUpdate(optimal, H, r, sigma2, false));
  for (const bool joseph : {true, false}) {
    FilterState a = s0;
    ASSERT_TRUE(ekfUpdate(a, H, r, sigma2, joseph, kappa));
    EXPECT_LT((a.P - expected).norm(), 1e-10 * s0.P.norm()) << "joseph " << joseph;
    EXPECT_LT(a.minus(optimal).norm(), 1e-12) << "joseph " << joseph;
    // Wider than the optimal update's covariance by exactly (κ − 1) σ² K Kᵀ.
    EXPECT_LT((a.P - optimal.P - (kappa - 1.0) * sigma2 * K * K.transpose()).norm(), 1e-10 * s0.P.norm());
  }
  FilterState iterated = s0;
  const auto no_relinearized_rows = [](const FilterState&, MatX* Hl, VecX* rl) {
    Hl->resize(0, 0);
    rl->resize(0);
  };
  ASSERT_TRUE(iteratedEkfUpdate(iterated, no_relinearized_rows, H, r, sigma2, 1, false, kappa));
  // The iterated update compresses (H, r) by QR first: the same information.
  EXPECT_LT((iterated.P - expected).norm(), 1e-8 * s0.P.norm());
}

TEST(BackendSlamInit, DepthPriorAndTriangulatedInitialisation) {
  const auto clones = arcOfClones(8, 11, 1.0);
  FilterState s = stateWith(clones, 11);
  const Vec3 p_true(4.0, 0.5, 0.3);
  FeatureTrack track;
  track.id = 7;
  for (const auto& c : clones) {
    Vec2 zi;
    ASSERT_TRUE(projectWorldPoint(c, p_true, &zi));
    track.observations.push_back({c.id, zi});
  }
  // Depth prior on the newest clone: ρ0 = 1/(2 d_min), σ = 1/(4 d_min), no cross terms.
  FilterState prior = s;
  addSlamFeatureWithPrior(prior, 7, 7, track.observations.back().z, 1.3, 0.65, 0.01);
  ASSERT_EQ(prior.features.size(), 1u);
  EXPECT_EQ(prior.features[0].anchor_clone_id, 7);
  EXPECT_DOUBLE_EQ(prior.features[0].abr.z(), 1.3);
  EXPECT_DOUBLE_EQ(prior.P(prior.featureIndex(0) + 2, prior.featureIndex(0) + 2), 0.65 * 0.65);
  EXPECT_EQ(prior.P.block(prior.featureIndex(0), 0, 3, prior.featureIndex(0)).norm(), 0.0);

  // Triangulated (Li & Mourikis): exact observations give the exact point.
  std::vector<CameraClone> cl;
  std::vector<std::size_t> pos;
  std::vector<Vec2> z;
  gatherTrack(s, track, &cl, &pos, &z);
  TriangulationResult tri;
  ASSERT_TRUE(triangulateFeature(cl, z, cl.size() - 1, TriangulationOptions{}, &tri));
  const Chi2Table chi2(0.95);
  ASSERT_EQ(addSlamFeatureTriangulated(s, track, tri.abr, 1e-6, true, chi2, [](MatX*) {}), SlamInitOutcome::kOk);
  ASSERT_EQ(s.features.size(), 1u);
  const Vec3 p_est = anchoredToWorld(s.clones.back(), s.features[0].abr);
  EXPECT_LT((p_est - p_true).norm(), 1e-8);
  EXPECT_LT((s.P - s.P.transpose()).norm(), 1e-18);
  EXPECT_GT(Eigen::SelfAdjointEigenSolver<MatX>(s.P).eigenvalues().minCoeff(), 0.0);
}

}  // namespace
}  // namespace evio::estimator
