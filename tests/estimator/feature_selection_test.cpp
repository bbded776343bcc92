// The steps of one visual update that choose its features
// (feature_selection.h): undistortion and whitening, track bookkeeping, SLAM
// candidates and MSCKF tracks, each on its own, against exact answers.
#include <gtest/gtest.h>

#include <unordered_set>
#include <vector>

#include "evio/estimator/backend/feature_selection.h"
#include "track_builders.h"
#include "updater_bench.h"

namespace evio::estimator {
namespace {

const Camera kCamera = Camera(PinholeCamera(200, 100, Vec4(100, 100, 100, 50)));

using test::restingState;
using test::track;
using test::tracksOf;

TEST(BackendSteps, UndistortObservationsGivesNormalisedCoordinatesOncePerFeature) {
  MeasurementSet set;
  set.features = {{1, Vec2(150, 75)}, {2, Vec2(100, 50)}, {1, Vec2(0, 0)}};
  BackendStats stats;
  const auto obs = undistortObservations(set, kCamera, 0.01, &stats);
  ASSERT_EQ(obs.size(), 2u);
  EXPECT_EQ(obs[0].id, 1);
  EXPECT_TRUE(obs[0].z.isApprox(Vec2(0.5, 0.25)));  // ((150−100)/100, (75−50)/100)
  EXPECT_EQ(obs[1].id, 2);
  EXPECT_TRUE(obs[1].z.isZero(0.0));
  EXPECT_EQ(stats.features_undistort_failed, 0);
}

// A stated pixel covariance becomes Σ_z = K⁻¹ Σ_px K⁻ᵀ in normalised units
// and the observation's whitening W satisfies W Σ_z Wᵀ = σ_z² I; no
// covariance (zero) or one that is not positive definite gives W = I.
TEST(BackendSteps, UndistortObservationsWhitensAStatedCovarianceToSigmaZ) {
  const Camera camera(PinholeCamera(200, 100, Vec4(100, 80, 100, 50)));  // fx ≠ fy
  MeasurementSet set;
  FeatureMeasurement a, b, c;
  a.id = 1;
  a.uv = Vec2(120, 60);
  a.cov_px << 0.5, 0.2, 0.2, 2.0;
  b.id = 2;
  b.uv = Vec2(90, 40);
  c.id = 3;
  c.uv = Vec2(80, 30);
  c.cov_px << 1.0, 2.0, 2.0, 1.0;  // indefinite
  c.informative = false;
  c.error_time_s = 0.054;
  set.features = {a, b, c};
  BackendStats stats;
  const double sigma_z = 0.05;
  const auto obs = undistortObservations(set, camera, sigma_z, &stats);
  ASSERT_EQ(obs.size(), 3u);
  const Mat2 K_inv = Vec2(1.0 / 100.0, 1.0 / 80.0).asDiagonal();
  const Mat2 cov_z = K_inv * a.cov_px * K_inv;
  const Mat2 white = obs[0].whiten * cov_z * obs[0].whiten.transpose();
  EXPECT_LT((white - sigma_z * sigma_z * Mat2::Identity()).cwiseAbs().maxCoeff(), 1e-15);
  EXPECT_EQ(obs[1].whiten, Mat2::Identity());
  EXPECT_EQ(obs[2].whiten, Mat2::Identity());
  EXPECT_TRUE(obs[0].informative);
  EXPECT_FALSE(obs[2].informative);
  EXPECT_EQ(obs[0].error_time_s, 0.0);
  EXPECT_EQ(obs[2].error_time_s, 0.054);  // the tracker's statement, as it came
}

// A feature flagged not informative keeps its track alive (not lost, not
// erased) without an observation in this clone, cannot become a SLAM
// candidate here (its newest observation is older than the anchor would
// be), and starts no track when it has none.
TEST(BackendSteps, NonInformativeObservationsKeepTracksAliveWithoutObservations) {
  FilterState state = restingState(1);
  TrackMap tracks = tracksOf({track(3, {1, 2, 3, 4})});
  FeatureObservation stale{3, Vec2(0.1, 0.2)};
  stale.informative = false;
  FeatureObservation fresh_stale{8, Vec2::Zero()};
  fresh_stale.informative = false;
  extendTracks({stale, fresh_stale}, state, 5, &tracks);
  ASSERT_EQ(tracks.size(), 1u);
  EXPECT_EQ(tracks[3].observations.size(), 4u);
  EXPECT_EQ(tracks[3].seen_clone_id, 5);
  const MsckfChoice c = chooseMsckfTracks(tracks, 5, 1, false, {}, 3, true);
  EXPECT_TRUE(c.update.empty());
  EXPECT_TRUE(c.erase.empty());
  EXPECT_TRUE(chooseSlamCandidates(tracks, 5, 3, 2).empty());
  // Not seen at clone 6: lost.
  EXPECT_EQ(chooseMsckfTracks(tracks, 6, 1, false, {}, 3, true).erase, (std::vector<FeatureId>{3}));
}

TEST(BackendSteps, ExtendTracksSkipsSlamFeaturesAndStartsNewTracks) {
  FilterState state = restingState(1);
  SlamFeature f;
  f.id = 7;
  state.features.push_back(f);
  state.P = MatX::Identity(state.dim(), state.dim());
  TrackMap tracks = tracksOf({track(3, {4})});
  extendTracks({{3, Vec2(0.1, 0.2)}, {7, Vec2::Zero()}, {9, Vec2(0.3, 0.4)}}, state, 5, &tracks);
  ASSERT_EQ(tracks.size(), 2u);
  EXPECT_EQ(tracks.count(7), 0u);
  ASSERT_EQ(tracks[3].observations.size(), 2u);
  EXPECT_EQ(tracks[3].observations.back().clone_id, 5);
  EXPECT_TRUE(tracks[3].observations.back().z.isApprox(Vec2(0.1, 0.2)));
  ASSERT_EQ(tracks[9].observations.size(), 1u);
  EXPECT_EQ(tracks[9].id, 9);
}

TEST(BackendSteps, SlamCandidatesAreTheLongestLiveTracksTiesByTheSmallerId) {
  // Newest clone 10. Track 1 is lost (last seen in clone 9); 2 too short.
  const TrackMap tracks = tracksOf({track(1, {5, 6, 7, 8, 9}), track(2, {9, 10}), track(3, {7, 8, 9, 10}),
                                    track(4, {6, 7, 8, 9, 10}), track(5, {7, 8, 9, 10})});
  EXPECT_EQ(chooseSlamCandidates(tracks, 10, 2, 3), (std::vector<FeatureId>{4, 3}));
  EXPECT_EQ(chooseSlamCandidates(tracks, 10, 5, 3), (std::vector<FeatureId>{4, 3, 5}));
  EXPECT_TRUE(chooseSlamCandidates(tracks, 10, 0, 3).empty());
  EXPECT_EQ(chooseSlamCandidates(tracks, 10, 5, 2), (std::vector<FeatureId>{4, 3, 5, 2}));
}

TEST(BackendSteps, SlamCandidatesBySpanNeedTheSpanAndThreeObservations) {
  // Clones 6..10 at 0, 0.1, 0.3, 0.4 and 0.5 s; newest 10. Track 1: three
  // observations over 0.5 s; 3: three over 0.2 s; 2: two over 0.5 s.
  FilterState state;
  const double t_s[] = {0.0, 0.1, 0.3, 0.4, 0.5};
  for (int k = 0; k < 5; ++k) {
    CameraClone c;
    c.id = 6 + k;
    c.t_ns = secondsToNs(t_s[k]);
    state.clones.push_back(c);
  }
  const TrackMap tracks = tracksOf({track(1, {6, 8, 10}), track(2, {6, 10}), track(3, {8, 9, 10})});
  const auto choose = [&](double span_s) {
    return chooseSlamCandidates(tracks, state, 10, 5, SlamEligibility{10, secondsToNs(span_s), 3});
  };
  EXPECT_TRUE(choose(0.0).empty());                             // off: ten observations, none has them
  EXPECT_EQ(choose(0.45), (std::vector<FeatureId>{1}));         // 0.5 s >= 0.45 s
  EXPECT_EQ(choose(0.5), (std::vector<FeatureId>{1}));          // the bound itself counts
  EXPECT_EQ(choose(0.2), (std::vector<FeatureId>{1, 3}));       // track 2: two observations only
  EXPECT_TRUE(choose(0.51).empty());
  // The count rule still applies beside the span rule.
  EXPECT_EQ(chooseSlamCandidates(tracks, state, 10, 5, SlamEligibility{2, secondsToNs(0.45), 3}),
            (std::vector<FeatureId>{1, 3, 2}));
  // A track not observed in the newest clone is never a candidate, however
  // long it spans; with fewer slots the longest tracks win, ties by id.
  TrackMap more = tracks;
  more.emplace(4, track(4, {6, 7, 8, 9}));              // lost: not in clone 10
  more.emplace(5, track(5, {6, 7, 8, 9, 10}));          // five observations over 0.5 s
  const SlamEligibility rule{.min_length = 10, .min_span_ns = secondsToNs(0.2), .span_min_length = 3};
  EXPECT_EQ(chooseSlamCandidates(more, state, 10, 5, rule), (std::vector<FeatureId>{5, 1, 3}));
  EXPECT_EQ(chooseSlamCandidates(more, state, 10, 2, rule), (std::vector<FeatureId>{5, 1}));
}

TEST(BackendSteps, MsckfTracksAreThoseLeavingTheWindowAndTheLostOnes) {
  // Oldest clone 0, newest 4. Track 1 starts in the oldest clone (leaves when
  // sliding); 2 too; but 2 is a SLAM candidate; 3 is lost; 4 is lost and short;
  // 5 is live and does not start in the oldest clone.
  const TrackMap tracks = tracksOf({track(1, {0, 1, 2, 3, 4}), track(2, {0, 1, 2, 3, 4}), track(3, {1, 2, 3}),
                                    track(4, {3}), track(5, {2, 3, 4})});
  const std::unordered_set<FeatureId> slam{2};
  MsckfChoice c = chooseMsckfTracks(tracks, 4, 0, true, slam, 3, true);
  EXPECT_EQ(c.update, (std::vector<FeatureId>{1, 3}));
  EXPECT_EQ(c.erase, (std::vector<FeatureId>{3, 4}));
  c = chooseMsckfTracks(tracks, 4, 0, false, slam, 3, true);  // not sliding: lost tracks only
  EXPECT_EQ(c.update, (std::vector<FeatureId>{3}));
  c = chooseMsckfTracks(tracks, 4, 0, true, slam, 3, false);  // lost tracks erased, not used
  EXPECT_EQ(c.update, (std::vector<FeatureId>{1}));
  EXPECT_EQ(c.erase, (std::vector<FeatureId>{3, 4}));
}

}  // namespace
}  // namespace evio::estimator
