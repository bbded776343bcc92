// Every preset in trajectories/presets/: exact derivatives against finite
// differences of the pose, and the properties each preset promises.

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "evio/core/error.h"
#include "evio/core/so3.h"
#include "evio/trajectories/flight.h"
#include "evio/trajectories/hand_held.h"
#include "evio/trajectories/hover.h"
#include "evio/trajectories/rotation_only.h"
#include "evio/trajectories/trajectory_factory.h"
#include "trajectory_presets.h"

namespace evio {
namespace {

constexpr double kRadToDeg = 180.0 / std::numbers::pi;

// Fourth-order central difference: f'(t) = [f(t−2h) − 8f(t−h) + 8f(t+h) − f(t+2h)]/(12h) + O(h⁴).
// h = 1 ms: the truncation term is ≈ (hΩ)⁴/30 relative for a motion of angular
// frequency Ω (Ω < 30 rad/s in every preset: < 2e-8), and the round-off term
// ≈ ε|f|/(h|f'|) stays below 1e-10 for positions of tens of metres. A 2nd-order
// stencil would need h ≈ 1e-5 s and would then be dominated by round-off.
constexpr TimeNs kStepNs = 1'000'000;

template <class F>
auto fourthOrderDerivative(const F& f, TimeNs t) {
  using Value = decltype(f(t));
  const double h = nsToSeconds(kStepNs);
  const Value d =
      ((f(t - 2 * kStepNs) - f(t + 2 * kStepNs)) + 8.0 * (f(t + kStepNs) - f(t - kStepNs))) / (12.0 * h);
  return d;
}

/// ‖num − ana‖ / max(‖ana‖, floor): relative error, with a floor of 1e-3 of
/// the quantity's peak over the sequence so instants where it passes through
/// zero (rest, turning points) are judged against its scale, not against 0.
struct RelativeError {
  double max = 0.0;
  TimeNs worst_t = 0;
  void add(const Vec3& num, const Vec3& ana, double floor, TimeNs t) {
    const double denom = std::max(ana.norm(), floor);
    const double e = denom == 0.0 ? (num.norm() > 1e-12 ? 1.0 : 0.0) : (num - ana).norm() / denom;
    if (e > max) {
      max = e;
      worst_t = t;
    }
  }
};

class PresetTest : public ::testing::TestWithParam<std::string> {
 protected:
  std::unique_ptr<ContinuousTrajectory> load() const {
    return makeTrajectory(test::trajectoryPresetPath(GetParam()));
  }
};

std::vector<TimeNs> sampleTimes(const ContinuousTrajectory& traj, int count) {
  // A prime count of evenly spaced times, kept 2h clear of both ends.
  std::vector<TimeNs> times;
  const TimeNs a = traj.startTime() + 2 * kStepNs, b = traj.endTime() - 2 * kStepNs;
  for (int k = 0; k < count; ++k) times.push_back(a + (b - a) * k / (count - 1));
  return times;
}

TEST_P(PresetTest, AnalyticDerivativesMatchFiniteDifferencesOfThePose) {
  const auto traj = load();
  const auto times = sampleTimes(*traj, 1009);
  const auto position = [&](TimeNs t) { return traj->evaluate(t).T_W_B.translation(); };
  const auto rotation = [&](TimeNs t) { return traj->evaluate(t).T_W_B.rotation(); };
  const auto velocity = [&](TimeNs t) { return traj->evaluate(t).v_W; };
  const auto omega = [&](TimeNs t) { return traj->evaluate(t).omega_B; };

  double peak_v = 0, peak_a = 0, peak_w = 0, peak_alpha = 0;
  for (const TimeNs t : times) {
    const TrajectoryState s = traj->evaluate(t);
    peak_v = std::max(peak_v, s.v_W.norm());
    peak_a = std::max(peak_a, s.a_W.norm());
    peak_w = std::max(peak_w, s.omega_B.norm());
    peak_alpha = std::max(peak_alpha, s.alpha_B.norm());
  }
  RelativeError ev, ea, ew, ealpha;
  for (const TimeNs t : times) {
    const TrajectoryState s = traj->evaluate(t);
    ev.add(fourthOrderDerivative(position, t), s.v_W, 1e-3 * peak_v, t);
    ea.add(fourthOrderDerivative(velocity, t), s.a_W, 1e-3 * peak_a, t);
    const Mat3 R_dot = fourthOrderDerivative(rotation, t);
    const Mat3 skew = s.T_W_B.rotation().transpose() * R_dot;
    ew.add(so3::vee(0.5 * (skew - skew.transpose())), s.omega_B, 1e-3 * peak_w, t);
    ealpha.add(fourthOrderDerivative(omega, t), s.alpha_B, 1e-3 * peak_alpha, t);
  }
  EXPECT_LT(ev.max, 1e-6) << "velocity, worst at " << nsToSeconds(ev.worst_t) << " s";
  EXPECT_LT(ea.max, 1e-6) << "acceleration, worst at " << nsToSeconds(ea.worst_t) << " s";
  EXPECT_LT(ew.max, 1e-6) << "angular velocity, worst at " << nsToSeconds(ew.worst_t) << " s";
  EXPECT_LT(ealpha.max, 1e-6) << "angular acceleration, worst at " << nsToSeconds(ealpha.worst_t) << " s";
  RecordProperty("max_rel_err_v", std::to_string(ev.max));
  RecordProperty("max_rel_err_a", std::to_string(ea.max));
  RecordProperty("max_rel_err_omega", std::to_string(ew.max));
  RecordProperty("max_rel_err_alpha", std::to_string(ealpha.max));
  std::printf("[%s] peak |v| %.3f m/s, |a| %.3f m/s^2, |w| %.1f deg/s, |alpha| %.1f deg/s^2; "
              "max rel err v %.1e a %.1e w %.1e alpha %.1e\n",
              GetParam().c_str(), peak_v, peak_a, peak_w * kRadToDeg, peak_alpha * kRadToDeg, ev.max,
              ea.max, ew.max, ealpha.max);
}

TEST_P(PresetTest, IsDeterministicInItsSeedAndLastsAtLeastAMinute) {
  const auto a = load();
  const auto b = load();
  EXPECT_GE(nsToSeconds(a->endTime() - a->startTime()), 60.0);
  for (const TimeNs t : sampleTimes(*a, 101)) {
    const TrajectoryState sa = a->evaluate(t), sb = b->evaluate(t);
    ASSERT_EQ(sa.T_W_B.translation(), sb.T_W_B.translation());
    ASSERT_EQ(sa.T_W_B.quaternion().coeffs(), sb.T_W_B.quaternion().coeffs());
    ASSERT_EQ(sa.a_W, sb.a_W);
    ASSERT_EQ(sa.alpha_B, sb.alpha_B);
  }
  EXPECT_THROW(a->evaluate(a->startTime() - 1), Error);
  EXPECT_THROW(a->evaluate(a->endTime() + 1), Error);
}

TEST_P(PresetTest, ResolvedConfigurationRebuildsTheSameTrajectory) {
  const auto a = load();
  const auto doc = config::loadString(a->configYaml(), "resolved.yaml");
  const auto b = makeTrajectory(doc, "");
  EXPECT_EQ(a->configYaml(), b->configYaml());
  const TimeNs t = (a->startTime() + a->endTime()) / 2;
  EXPECT_EQ(a->evaluate(t).T_W_B.translation(), b->evaluate(t).T_W_B.translation());
}

INSTANTIATE_TEST_SUITE_P(AllPresets, PresetTest, ::testing::ValuesIn(test::trajectoryPresetFiles()),
                         [](const auto& param_info) { return test::presetTestName(param_info.param); });

TEST(Presets, EveryTypeHasAPresetFile) {
  const auto files = test::trajectoryPresetFiles();
  for (const auto& type : trajectoryTypes())
    EXPECT_NE(std::find(files.begin(), files.end(), type + ".yaml"), files.end()) << type;
}

TEST(Presets, DifferentSeedsGiveDifferentMotion) {
  const auto a = makeTrajectory(test::trajectoryPresetPath("hover.yaml"), {"seed=1"});
  const auto b = makeTrajectory(test::trajectoryPresetPath("hover.yaml"), {"seed=2"});
  const TimeNs t = 10 * kNsPerSecond;
  EXPECT_GT((a->evaluate(t).T_W_B.translation() - b->evaluate(t).T_W_B.translation()).norm(), 1e-3);
}

TEST(Presets, RotationOnlyHasExactlyZeroTranslation) {
  const auto traj = makeTrajectory(test::trajectoryPresetPath("rotation_only.yaml"));
  double peak_rate = 0.0;
  for (TimeNs t = traj->startTime(); t <= traj->endTime(); t += kNsPerMs) {
    const TrajectoryState s = traj->evaluate(t);
    ASSERT_EQ(s.T_W_B.translation(), Vec3::Zero()) << nsToSeconds(t);
    ASSERT_EQ(s.v_W, Vec3::Zero());
    ASSERT_EQ(s.a_W, Vec3::Zero());
    peak_rate = std::max(peak_rate, s.omega_B.norm());
  }
  // "Peak rates of several hundred deg/s", as in the dataset's rotation sequences.
  EXPECT_GT(peak_rate * kRadToDeg, 300.0);
  EXPECT_LT(peak_rate * kRadToDeg, 1500.0);
}

TEST(Presets, OnsetStartsAtRestAndEndsOnTheOscillation) {
  // onset_s = T multiplies every axis by the C∞ smoothstep S(t/T): at t = 0
  // the pose is the rest pose and every rate is exactly 0; for t ≥ T the
  // motion is the one without onset, exactly (S = 1 there).
  RotationOnlyOptions rot = config::load<RotationOnlyOptions>(test::trajectoryPresetPath("rotation_only.yaml"));
  HandHeldOptions six = config::load<HandHeldOptions>(test::trajectoryPresetPath("six_dof.yaml"));
  const RotationOnlyTrajectory rot_free(rot);
  const HandHeldTrajectory six_free(six);
  rot.onset_s = six.onset_s = 2.0;
  const RotationOnlyTrajectory rot_onset(rot);
  const HandHeldTrajectory six_onset(six);
  for (const auto* traj : {static_cast<const ContinuousTrajectory*>(&rot_onset), static_cast<const ContinuousTrajectory*>(&six_onset)}) {
    const TrajectoryState s0 = traj->evaluate(0);
    EXPECT_EQ(s0.omega_B, Vec3::Zero());
    EXPECT_EQ(s0.v_W, Vec3::Zero());
    EXPECT_EQ(s0.alpha_B, Vec3::Zero());
    EXPECT_EQ(s0.a_W, Vec3::Zero());
  }
  for (TimeNs t = 2000 * kNsPerMs; t <= 3000 * kNsPerMs; t += 100 * kNsPerMs) {
    EXPECT_LT((rot_onset.evaluate(t).omega_B - rot_free.evaluate(t).omega_B).norm(), 1e-12);
    EXPECT_LT((six_onset.evaluate(t).v_W - six_free.evaluate(t).v_W).norm(), 1e-12);
  }
  rot.onset_s = -1.0;
  EXPECT_THROW(rot.validate(), Error);
}

TEST(Presets, HoverStaysWithinItsStatedBox) {
  for (const char* file : {"hover.yaml", "hover_oscillation.yaml"}) {
    HoverOptions options = config::load<HoverOptions>(test::trajectoryPresetPath(file));
    options.duration_s = 1200.0;  // long enough for every drift component to reach its extremes
    const HoverTrajectory traj(options);
    Vec3 extent = Vec3::Zero();
    double max_tilt = 0.0;
    for (TimeNs t = 0; t <= traj.endTime(); t += 10 * kNsPerMs) {
      const TrajectoryState s = traj.evaluate(t);
      const Vec3 d = (s.T_W_B.translation() - options.center_m).cwiseAbs();
      ASSERT_TRUE((d.array() <= options.drift_amplitude_m.array()).all())
          << file << " at " << nsToSeconds(t) << " s: " << d.transpose();
      extent = extent.cwiseMax(d);
      const Vec3 z_B = s.T_W_B.rotation().col(2);
      max_tilt = std::max(max_tilt, std::acos(std::clamp(z_B.z(), -1.0, 1.0)));
    }
    // The drift really uses its box (not a motion stuck at the centre).
    EXPECT_TRUE((extent.array() > 0.5 * options.drift_amplitude_m.array()).all()) << extent.transpose();
    if (options.oscillation_amplitude_deg > 0.0) {
      EXPECT_GT(max_tilt * kRadToDeg, 20.0) << file;  // Ingenuity flight 6: > 20°
    } else {
      EXPECT_LT(max_tilt * kRadToDeg, 5.0) << file;  // a few degrees of wobble
    }
  }
}

TEST(Presets, CircleKeepsItsDiameterAndSpeedsUp) {
  const auto traj = makeTrajectory(test::trajectoryPresetPath("circle.yaml"));
  const Vec3 center(0, 0, 1.0);
  double first_speed = 0.0, last_speed = 0.0;
  for (TimeNs t = traj->startTime(); t <= traj->endTime(); t += 10 * kNsPerMs) {
    const TrajectoryState s = traj->evaluate(t);
    const Vec3 d = s.T_W_B.translation() - center;
    ASSERT_NEAR(d.head<2>().norm(), 0.75, 1e-12);
    ASSERT_LE(std::abs(d.z()), 0.02);
    if (t == traj->startTime()) first_speed = s.v_W.head<2>().norm();
    last_speed = s.v_W.head<2>().norm();
  }
  EXPECT_NEAR(first_speed, 2 * std::numbers::pi * 0.75 * 0.05, 1e-12);
  EXPECT_NEAR(last_speed, 2 * std::numbers::pi * 0.75 * 0.30, 1e-9);
}

TEST(Presets, FlightTakesOffTraversesAndLandsAtRest) {
  const auto traj = makeTrajectory(test::trajectoryPresetPath("flight.yaml"));
  const TrajectoryState first = traj->evaluate(traj->startTime());
  const TrajectoryState last = traj->evaluate(traj->endTime());
  EXPECT_EQ(first.T_W_B.translation(), Vec3::Zero());
  EXPECT_EQ(first.v_W, Vec3::Zero());
  EXPECT_EQ(first.omega_B, Vec3::Zero());
  EXPECT_LT((last.T_W_B.translation() - Vec3(50, 0, 0)).norm(), 1e-12);
  EXPECT_LT(last.v_W.norm(), 1e-12);
  double max_z = 0.0, max_tilt = 0.0;
  for (TimeNs t = traj->startTime(); t <= traj->endTime(); t += 10 * kNsPerMs) {
    const TrajectoryState s = traj->evaluate(t);
    max_z = std::max(max_z, s.T_W_B.translation().z());
    ASSERT_GE(s.T_W_B.translation().z(), -1e-12);
    max_tilt = std::max(max_tilt, std::acos(std::min(1.0, s.T_W_B.rotation()(2, 2))));
  }
  EXPECT_NEAR(max_z, 10.0, 1e-9);
  EXPECT_GT(max_tilt * kRadToDeg, 5.0);   // it leans into the traverse
  EXPECT_LT(max_tilt * kRadToDeg, 30.0);
}

TEST(Presets, FlightKeepsTheThrustUpAndRefusesAClimbThatWouldNeedDownwardThrust) {
  // Mars gravity 3.721 m/s²: 10 m in 7 s peaks at 10·9.841/49 = 2.0 m/s², so
  // the body's z axis (thrust) stays within 90° of up all through the climb.
  FlightOptions o;
  o.duration_s = 30, o.ground_time_s = 1, o.climb_s = 7, o.hover_before_traverse_s = 2, o.traverse_s = 12,
  o.descent_s = 6, o.altitude_m = 10, o.traverse_distance_m = 30;
  const FlightTrajectory ok(o);
  for (TimeNs t = ok.startTime(); t <= ok.endTime(); t += 5 * kNsPerMs)
    ASSERT_GT(ok.evaluate(t).T_W_B.rotation()(2, 2), 0.5) << nsToSeconds(t);
  // 10 m in 5 s peaks at 3.94 m/s² > g: the thrust-aligned attitude would flip
  // upside down in mid-climb (what the mars campaign's first compression did).
  o.climb_s = 5;
  try {
    FlightTrajectory bad(o);
    FAIL() << "a 5-s climb of 10 m under Mars gravity was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("climb_s"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("pull down"), std::string::npos) << e.what();
  }
  o.climb_s = 7, o.descent_s = 5;
  EXPECT_THROW(FlightTrajectory{o}, Error);
  o.descent_s = 6, o.gravity_mps2 = 9.81, o.climb_s = 3.2;  // Earth: 10·9.841/3.2² = 9.61 < 9.81
  EXPECT_NO_THROW(FlightTrajectory{o});
}

TEST(Presets, LavaTubeEntryGoesFromOutsideToInside) {
  const auto traj = makeTrajectory(test::trajectoryPresetPath("lava_tube_entry.yaml"));
  const Vec3 p0 = traj->evaluate(traj->startTime()).T_W_B.translation();
  const Vec3 p1 = traj->evaluate(traj->endTime()).T_W_B.translation();
  EXPECT_LT((p0 - Vec3(-20, 0, 8)).norm(), 1e-12);   // in the sun, before the mouth
  EXPECT_LT((p1 - Vec3(15, 0, 2.5)).norm(), 1e-12);  // inside, low
  // The descent is over before the mouth (x = 0) is passed.
  for (TimeNs t = traj->startTime(); t <= traj->endTime(); t += 10 * kNsPerMs) {
    const Vec3 p = traj->evaluate(t).T_W_B.translation();
    if (p.x() >= 0.0) {
      ASSERT_NEAR(p.z(), 2.5, 1e-9) << nsToSeconds(t);
    }
  }
}

}  // namespace
}  // namespace evio
