// Every measurement Jacobian of the backend against central differences
// (tests/support/numeric_jacobian.h), in the error-state convention of
// filter_state.h: clone error [δp; δθ] with R = R̂ Exp(δθ).
#include <gtest/gtest.h>

#include "evio/core/random_stream.h"
#include "evio/core/so3.h"
#include "evio/estimator/backend/range_update.h"
#include "evio/estimator/backend/visual_models.h"
#include "numeric_jacobian.h"

namespace evio::estimator {
namespace {

CameraClone perturbed(const CameraClone& c, const Vec6& d) {
  CameraClone o = c;
  o.p_W_C += d.head<3>();
  o.q_W_C = (c.q_W_C * so3::expQuat(d.tail<3>())).normalized();
  return o;
}

// Two cameras looking roughly along +x of W at points around (5, 0, 0).
CameraClone cloneAt(const Vec3& p, const Vec3& rot_perturbation, std::int64_t id) {
  Mat3 R_look;
  R_look.col(0) = Vec3(0, -1, 0);
  R_look.col(1) = Vec3(0, 0, -1);
  R_look.col(2) = Vec3(1, 0, 0);
  CameraClone c;
  c.id = id;
  c.p_W_C = p;
  c.q_W_C = Quat(R_look * so3::exp(rot_perturbation));
  return c;
}

constexpr double kTol = 1e-7;

TEST(BackendModels, WorldPointProjectionJacobians) {
  const CameraClone c = cloneAt(Vec3(0.1, -0.2, 0.3), Vec3(0.1, -0.05, 0.2), 0);
  const Vec3 p_W(5.0, 0.7, -0.4);
  Vec2 z;
  Mat26 J_c;
  Mat23 J_p;
  ASSERT_TRUE(projectWorldPoint(c, p_W, &z, &J_c, &J_p));
  const auto f_c = [&](const Vec6& d) {
    Vec2 zz;
    EXPECT_TRUE(projectWorldPoint(perturbed(c, d), p_W, &zz));
    return zz;
  };
  const auto f_p = [&](const Vec3& d) {
    Vec2 zz;
    EXPECT_TRUE(projectWorldPoint(c, p_W + d, &zz));
    return zz;
  };
  EXPECT_LT((J_c - test::numericJacobian<2, 6>(f_c, Vec6::Zero())).norm(), kTol);
  EXPECT_LT((J_p - test::numericJacobian<2, 3>(f_p, Vec3::Zero())).norm(), kTol);
  Vec2 behind;
  EXPECT_FALSE(projectWorldPoint(c, Vec3(-5, 0, 0), &behind));
}

TEST(BackendModels, AnchoredProjectionJacobians) {
  const CameraClone a = cloneAt(Vec3(0.0, 0.0, 0.0), Vec3(0.02, 0.1, -0.1), 0);
  const CameraClone c = cloneAt(Vec3(0.3, 0.2, -0.1), Vec3(-0.1, 0.05, 0.15), 1);
  const Vec3 abr(0.1, -0.15, 0.25);
  Vec2 z;
  Mat26 J_a, J_c;
  Mat23 J_f;
  ASSERT_TRUE(projectAnchoredFeature(a, c, abr, &z, &J_a, &J_c, &J_f));
  const auto f_a = [&](const Vec6& d) {
    Vec2 zz;
    EXPECT_TRUE(projectAnchoredFeature(perturbed(a, d), c, abr, &zz));
    return zz;
  };
  const auto f_c = [&](const Vec6& d) {
    Vec2 zz;
    EXPECT_TRUE(projectAnchoredFeature(a, perturbed(c, d), abr, &zz));
    return zz;
  };
  const auto f_f = [&](const Vec3& d) {
    Vec2 zz;
    EXPECT_TRUE(projectAnchoredFeature(a, c, abr + d, &zz));
    return zz;
  };
  EXPECT_LT((J_a - test::numericJacobian<2, 6>(f_a, Vec6::Zero())).norm(), kTol);
  EXPECT_LT((J_c - test::numericJacobian<2, 6>(f_c, Vec6::Zero())).norm(), kTol);
  EXPECT_LT((J_f - test::numericJacobian<2, 3>(f_f, Vec3::Zero())).norm(), kTol);
  // Consistent with the world-point model.
  Vec2 z_world;
  ASSERT_TRUE(projectWorldPoint(c, anchoredToWorld(a, abr), &z_world));
  EXPECT_LT((z - z_world).norm(), 1e-12);
}

TEST(BackendModels, AnchoredProjectionInTheAnchorIsTheParameters) {
  const CameraClone a = cloneAt(Vec3(1, 2, 3), Vec3(0.3, -0.2, 0.1), 4);
  const Vec3 abr(-0.2, 0.3, 0.5);
  Vec2 z;
  Mat26 J_a, J_c;
  Mat23 J_f;
  ASSERT_TRUE(projectAnchoredFeature(a, a, abr, &z, &J_a, &J_c, &J_f));
  EXPECT_LT((z - abr.head<2>()).norm(), 1e-14);
  EXPECT_LT((J_a + J_c).norm(), 1e-12);  // the clone's total Jacobian vanishes
  Mat23 expected = Mat23::Zero();
  expected(0, 0) = expected(1, 1) = 1.0;
  EXPECT_LT((J_f - expected).norm(), 1e-12);
}

TEST(BackendModels, AnchoredProjectionAtInfinity) {
  // ρ = 0 is a point at infinity: the model stays defined and matches the ray.
  const CameraClone a = cloneAt(Vec3(0, 0, 0), Vec3(0.05, 0, 0), 0);
  const CameraClone c = cloneAt(Vec3(1, 1, 0), Vec3(0, 0.1, 0), 1);
  const Vec3 abr(0.1, 0.05, 0.0);
  Vec2 z;
  Mat23 J_f;
  ASSERT_TRUE(projectAnchoredFeature(a, c, abr, &z, nullptr, nullptr, &J_f));
  const Vec3 ray = c.R_W_C().transpose() * a.R_W_C() * Vec3(0.1, 0.05, 1.0);
  EXPECT_LT((z - ray.head<2>() / ray.z()).norm(), 1e-14);
  const auto f_f = [&](const Vec3& d) {
    Vec2 zz;
    EXPECT_TRUE(projectAnchoredFeature(a, c, abr + d, &zz));
    return zz;
  };
  EXPECT_LT((J_f - test::numericJacobian<2, 3>(f_f, Vec3::Zero())).norm(), kTol);
}

TEST(BackendModels, AnchoredToWorldJacobiansAndInverse) {
  const CameraClone a = cloneAt(Vec3(0.5, -0.3, 1.0), Vec3(0.2, 0.1, -0.3), 0);
  const Vec3 abr(0.2, -0.1, 0.4);
  Mat36 J_a;
  Mat3 J_f;
  const Vec3 p = anchoredToWorld(a, abr, &J_a, &J_f);
  const auto f_a = [&](const Vec6& d) { return anchoredToWorld(perturbed(a, d), abr); };
  const auto f_f = [&](const Vec3& d) { return anchoredToWorld(a, abr + d); };
  EXPECT_LT((J_a - test::numericJacobian<3, 6>(f_a, Vec6::Zero())).norm(), 1e-6);
  EXPECT_LT((J_f - test::numericJacobian<3, 3>(f_f, Vec3::Zero())).norm(), 1e-6);
  Vec3 back;
  ASSERT_TRUE(worldToAnchored(a, p, &back));
  EXPECT_LT((back - abr).norm(), 1e-13);
}

TEST(BackendModels, ReanchoringJacobiansAndWorldPoint) {
  const CameraClone from = cloneAt(Vec3(0, 0, 0), Vec3(0.1, -0.1, 0.05), 0);
  const CameraClone to = cloneAt(Vec3(0.4, -0.2, 0.3), Vec3(-0.2, 0.1, 0.1), 1);
  const Vec3 abr(0.05, 0.1, 0.3);
  Vec3 abr_new;
  Mat36 J_from, J_to;
  Mat3 J_f;
  ASSERT_TRUE(reanchorFeature(from, to, abr, &abr_new, &J_from, &J_to, &J_f));
  EXPECT_LT((anchoredToWorld(to, abr_new) - anchoredToWorld(from, abr)).norm(), 1e-12);
  auto g = [](const CameraClone& f, const CameraClone& t, const Vec3& x) {
    Vec3 y;
    EXPECT_TRUE(reanchorFeature(f, t, x, &y));
    return y;
  };
  const auto f_from = [&](const Vec6& d) { return g(perturbed(from, d), to, abr); };
  const auto f_to = [&](const Vec6& d) { return g(from, perturbed(to, d), abr); };
  const auto f_f = [&](const Vec3& d) { return g(from, to, abr + d); };
  EXPECT_LT((J_from - test::numericJacobian<3, 6>(f_from, Vec6::Zero())).norm(), kTol);
  EXPECT_LT((J_to - test::numericJacobian<3, 6>(f_to, Vec6::Zero())).norm(), kTol);
  EXPECT_LT((J_f - test::numericJacobian<3, 3>(f_f, Vec3::Zero())).norm(), kTol);
}

TEST(BackendModels, RangeToPlaneJacobians) {
  const Vec3 o(0.1, 0.2, 10.0), d = Vec3(0.05, -0.1, -1.0).normalized();
  const Vec3 q1(1.0, 0.5, 0.2), q2(-1.0, 1.5, -0.1), q3(0.3, -2.0, 0.05);
  double r = 0.0;
  Eigen::Matrix<double, 1, 3> J_o, J_d;
  Eigen::Matrix<double, 1, 9> J_q;
  ASSERT_TRUE(rangeToPlane(o, d, q1, q2, q3, &r, &J_o, &J_d, &J_q));
  // The intersection lies on the plane.
  const Vec3 hit = o + r * d;
  EXPECT_NEAR((q2 - q1).cross(q3 - q1).normalized().dot(hit - q1), 0.0, 1e-12);
  using V1 = Eigen::Matrix<double, 1, 1>;
  auto range = [](const Vec3& oo, const Vec3& dd, const Vec3& a, const Vec3& b, const Vec3& c) {
    double x = 0.0;
    EXPECT_TRUE(rangeToPlane(oo, dd, a, b, c, &x));
    return V1(x);
  };
  const auto f_o = [&](const Vec3& e) { return range(o + e, d, q1, q2, q3); };
  const auto f_d = [&](const Vec3& e) { return range(o, d + e, q1, q2, q3); };
  using Vec9 = Eigen::Matrix<double, 9, 1>;
  const auto f_q = [&](const Vec9& e) {
    return range(o, d, q1 + e.segment<3>(0), q2 + e.segment<3>(3), q3 + e.segment<3>(6));
  };
  EXPECT_LT((J_o - test::numericJacobian<1, 3>(f_o, Vec3::Zero())).norm(), kTol);
  EXPECT_LT((J_d - test::numericJacobian<1, 3>(f_d, Vec3::Zero())).norm(), kTol);
  EXPECT_LT((J_q - test::numericJacobian<1, 9>(f_q, Vec9::Zero())).norm(), kTol);
}

}  // namespace
}  // namespace evio::estimator
