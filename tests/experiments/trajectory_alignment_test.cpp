#include "evio/experiments/trajectory_alignment.h"

#include <gtest/gtest.h>

#include <numbers>

#include "evio/core/error.h"
#include "evio/core/so3.h"
#include "evio/experiments/trajectory_errors.h"
#include "support/test_trajectories.h"

namespace evio::experiments {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

/// The estimate that `S` maps exactly onto `gt`: es = S⁻¹(gt).
Trajectory transformedBack(const Trajectory& gt, const Similarity& S) {
  Trajectory es;
  for (const auto& p : gt) es.push_back({p.t_ns, S.applyInverse(p.pose)});
  return es;
}

Association associateExact(const Trajectory& es, const Trajectory& gt) {
  return associate(es, gt, AssociationOptions{});
}

double maxPositionError(const std::vector<PoseError>& errors) {
  double m = 0.0;
  for (const auto& e : errors) m = std::max(m, e.position_m);
  return m;
}

TEST(TrajectoryAlignment, PosYawRecoversKnownYawAndTranslationExactly) {
  const Trajectory gt = test::wavyTrajectory();
  Similarity S;
  S.R = rotationZ(37.0 * kDeg);
  S.t = Vec3(1.5, -2.0, 0.75);
  const Association a = associateExact(transformedBack(gt, S), gt);
  AlignmentOptions o;  // posyaw on all poses
  const Alignment al = align(a, gt.front().t_ns, o);
  EXPECT_FALSE(al.rotation_from_orientation);
  EXPECT_EQ(al.poses_used, gt.size());
  EXPECT_LT((al.transform.R - S.R).norm(), 1e-9);
  EXPECT_LT((al.transform.t - S.t).norm(), 1e-9);
  EXPECT_DOUBLE_EQ(al.transform.scale, 1.0);
  const auto errors = poseErrors(a, al);
  EXPECT_LT(maxPositionError(errors), 1e-9);
  for (const auto& e : errors) EXPECT_LT(e.rotation_deg, 1e-7);
}

TEST(TrajectoryAlignment, Se3RecoversAFullRotation) {
  const Trajectory gt = test::wavyTrajectory();
  Similarity S;
  S.R = so3::exp(Vec3(0.3, -0.5, 1.1));
  S.t = Vec3(-4.0, 0.5, 2.0);
  const Association a = associateExact(transformedBack(gt, S), gt);
  AlignmentOptions o;
  o.type = "se3";
  const Alignment al = align(a, gt.front().t_ns, o);
  EXPECT_LT((al.transform.R - S.R).norm(), 1e-9);
  EXPECT_LT((al.transform.t - S.t).norm(), 1e-9);
  EXPECT_LT(maxPositionError(poseErrors(a, al)), 1e-9);
}

TEST(TrajectoryAlignment, Sim3RecoversAKnownScale) {
  const Trajectory gt = test::wavyTrajectory();
  Similarity S;
  S.scale = 1.7;
  S.R = so3::exp(Vec3(-0.2, 0.4, 2.5));
  S.t = Vec3(3.0, 1.0, -1.0);
  const Association a = associateExact(transformedBack(gt, S), gt);
  AlignmentOptions o;
  o.type = "sim3";
  const Alignment al = align(a, gt.front().t_ns, o);
  EXPECT_NEAR(al.transform.scale, 1.7, 1e-9);
  EXPECT_LT((al.transform.R - S.R).norm(), 1e-9);
  EXPECT_LT((al.transform.t - S.t).norm(), 1e-9);
  EXPECT_LT(maxPositionError(poseErrors(a, al)), 1e-9);
}

TEST(TrajectoryAlignment, PosYawCannotRemoveATiltButSe3Can) {
  const Trajectory gt = test::wavyTrajectory();
  Similarity S;
  S.R = so3::exp(Vec3(4.0 * kDeg, 0.0, 0.0));  // a 4° roll of the whole estimate
  const Association a = associateExact(transformedBack(gt, S), gt);
  AlignmentOptions o;
  const auto posyaw = poseErrors(a, align(a, gt.front().t_ns, o));
  EXPECT_GT(maxPositionError(posyaw), 0.05);
  o.type = "se3";
  EXPECT_LT(maxPositionError(poseErrors(a, align(a, gt.front().t_ns, o))), 1e-9);
}

TEST(TrajectoryAlignment, TimeWindowAlignsOnTheWindowOnlyAndAppliesEverywhere) {
  const Trajectory gt = test::wavyTrajectory();
  Similarity S;
  S.R = rotationZ(-20.0 * kDeg);
  S.t = Vec3(0.3, 0.2, 0.1);
  Trajectory es = transformedBack(gt, S);
  // Outside t0+3..8 s the estimate drifts away; inside it is exact.
  for (auto& p : es) {
    const double t = nsToSeconds(p.t_ns);
    if (t > 8.0) p.pose = Pose(p.pose.quaternion(), p.pose.translation() + Vec3(0.1 * (t - 8.0), 0, 0));
  }
  const Association a = associateExact(es, gt);
  const Alignment al = align(a, gt.front().t_ns, AlignmentOptions::paper());
  EXPECT_EQ(al.poses_used, 501u);  // 3.00, 3.01, …, 8.00 s
  EXPECT_DOUBLE_EQ(al.window_start_s, 3.0);
  EXPECT_DOUBLE_EQ(al.window_end_s, 8.0);
  EXPECT_EQ(al.describe(), "posyaw on t0+3..8 s (501 poses)");
  EXPECT_LT((al.transform.R - S.R).norm(), 1e-9);
  const auto errors = poseErrors(a, al);
  for (const auto& e : errors) {
    const double t = nsToSeconds(e.t_ns);
    const double drift = t > 8.0 ? 0.1 * (t - 8.0) : 0.0;
    EXPECT_NEAR(e.position_m, drift, 1e-9) << t;
  }
}

TEST(TrajectoryAlignment, FirstNWindowUsesTheFirstPoses) {
  const Trajectory gt = test::wavyTrajectory();
  Trajectory es = gt;
  for (std::size_t k = 300; k < es.size(); ++k)
    es[k].pose = Pose(es[k].pose.quaternion(), es[k].pose.translation() + Vec3(0, 0, 1.0));
  const Association a = associateExact(es, gt);
  AlignmentOptions o;
  o.type = "se3";
  o.window = "first";
  o.first_n = 300;
  const Alignment al = align(a, gt.front().t_ns, o);
  EXPECT_EQ(al.poses_used, 300u);
  EXPECT_LT((al.transform.R - Mat3::Identity()).norm(), 1e-9);
  EXPECT_LT(al.transform.t.norm(), 1e-9);
}

TEST(TrajectoryAlignment, HoverTakesTheRotationFromOrientations) {
  // All positions equal: the positions say nothing about yaw.
  Trajectory gt;
  for (int k = 0; k <= 500; ++k)
    gt.push_back({TimeNs{k} * 10'000'000, Pose(so3::exp(Vec3(0.05 * std::sin(k * 0.1), 0.02, 0.3)), Vec3(0, 0, 10))});
  Similarity S;
  S.R = rotationZ(50.0 * kDeg);
  S.t = Vec3(1, 2, 3);
  const Association a = associateExact(transformedBack(gt, S), gt);
  const Alignment al = align(a, gt.front().t_ns, AlignmentOptions{});
  EXPECT_TRUE(al.rotation_from_orientation);
  EXPECT_LT((al.transform.R - S.R).norm(), 1e-9);
  EXPECT_LT((al.transform.t - S.t).norm(), 1e-9);
  AlignmentOptions sim3;
  sim3.type = "sim3";
  EXPECT_THROW(align(a, gt.front().t_ns, sim3), Error);
}

TEST(TrajectoryAlignment, AnEstimateDriftingOverAStillTruthDoesNotChooseTheYaw) {
  // The truth turns in place; the estimate (the truth moved by a known yaw
  // and offset) drifts 1 m sideways. The drift spreads the estimate's
  // positions, but the truth's do not determine a yaw: it must come from
  // the orientations, exactly.
  Trajectory gt;
  for (int k = 0; k <= 500; ++k)
    gt.push_back({TimeNs{k} * 10'000'000, Pose(so3::exp(Vec3(0.02, 0.01, 0.01 * k)), Vec3(0, -0.8, 1.5))});
  Similarity S;
  S.R = rotationZ(-30.0 * kDeg);
  S.t = Vec3(0.5, 0, 0);
  Trajectory es = transformedBack(gt, S);
  for (std::size_t k = 0; k < es.size(); ++k)
    es[k].pose = Pose(es[k].pose.quaternion(), es[k].pose.translation() + Vec3(0.002 * static_cast<double>(k), 0, 0));
  AlignmentOptions o;
  o.min_spread_m = 0.2;
  const Alignment al = align(associateExact(es, gt), gt.front().t_ns, o);
  EXPECT_TRUE(al.rotation_from_orientation);
  EXPECT_LT((al.transform.R - S.R).norm(), 1e-9);
}

TEST(TrajectoryAlignment, NoneIsTheIdentityAndAnEmptyWindowIsAnError) {
  const Trajectory gt = test::wavyTrajectory(5.0);
  const Association a = associateExact(gt, gt);
  AlignmentOptions none;
  none.type = "none";
  const Alignment al = align(a, gt.front().t_ns, none);
  EXPECT_EQ(al.transform.R, Mat3::Identity());
  EXPECT_EQ(al.describe(), "none");
  AlignmentOptions late = AlignmentOptions::paper();
  late.start_s = 6.0;
  late.end_s = 9.0;  // the trajectory ends at 5 s
  try {
    align(a, gt.front().t_ns, late);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("no associated pose in the window"), std::string::npos) << e.what();
  }
  AlignmentOptions bad;
  bad.type = "rigid";
  EXPECT_THROW(bad.validate(), Error);
}

}  // namespace
}  // namespace evio::experiments
