// Event pre-filters, the complementary-filter reconstruction and the gyro
// prediction, each against exact expectations.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include <opencv2/imgproc.hpp>

#include "evio/core/io/config.h"
#include "evio/core/so3.h"
#include "evio/estimator/frontend/frontend.h"
#include "evio/estimator/frontend/synchronizer.h"
#include "evio/estimator/frontend/event_prefilter.h"
#include "evio/estimator/frontend/gyro_predictor.h"
#include "evio/estimator/frontend/image_reconstructor.h"

namespace evio::estimator {
namespace {

TEST(EventPrefilter, RefractoryPeriodDropsEventsWithinTauOfTheLastKeptOne) {
  EventPrefilterOptions o;
  o.refractory_period_s = 0.010;
  EventPrefilter filter(o, 4, 4);
  EventArray in, out;
  // Pixel (1, 1) at 0, 5, 9.999, 10, 15, 25 ms; pixel (2, 3) at 6 ms.
  for (double ms : {0.0, 5.0, 9.999, 10.0}) in.push_back(secondsToNs(ms * 1e-3), 1, 1, true);
  in.push_back(secondsToNs(6e-3), 2, 3, false);
  for (double ms : {15.0, 25.0}) in.push_back(secondsToNs(ms * 1e-3), 1, 1, true);
  filter.filter(in, 0, in.size(), &out);
  std::vector<TimeNs> kept(out.t().begin(), out.t().end());
  // 0 kept; 5, 9.999 dropped; 10 kept (exactly τ after 0); 6 ms other pixel kept;
  // 15 dropped (5 ms after 10); 25 kept.
  EXPECT_EQ(kept, (std::vector<TimeNs>{0, secondsToNs(10e-3), secondsToNs(6e-3), secondsToNs(25e-3)}));
  EXPECT_EQ(filter.numSeen(), 7u);
  EXPECT_EQ(filter.numKept(), 4u);
}

TEST(EventPrefilter, RandomFilterKeepsOneInRAndIsSeeded) {
  EventPrefilterOptions o;
  o.random_keep_one_in = 4;
  EventArray in, a, b;
  for (int i = 0; i < 40000; ++i) in.push_back(i, static_cast<std::uint16_t>(i % 8), 0, true);
  EventPrefilter fa(o, 8, 1), fb(o, 8, 1);
  fa.filter(in, 0, in.size(), &a);
  fb.filter(in, 0, in.size(), &b);
  EXPECT_EQ(a, b);  // same seed, same events
  // Binomial(40000, 1/4): mean 10000, σ ≈ 86.6; 5σ bounds.
  EXPECT_NEAR(static_cast<double>(a.size()), 10000.0, 5 * 86.6);
  o.random_seed = 2;
  EventPrefilter fc(o, 8, 1);
  EventArray c;
  fc.filter(in, 0, in.size(), &c);
  EXPECT_NE(a, c);
  EventArray outside;
  outside.push_back(0, 9, 0, true);
  EXPECT_THROW(fa.filter(outside, 0, 1, &a), Error);
}

TEST(ImageReconstructor, HighPassFilterStepsAndDecaysExactly) {
  ImageReconstructorOptions o;
  o.cutoff_frequency_rad_s = 2.0;
  o.contrast_threshold = 0.3;
  o.fuse_frames = false;
  o.output_every_events = 0;
  ImageReconstructor rec(o, 3, 2);
  EventArray ev;
  ev.push_back(secondsToNs(1.0), 1, 0, true);
  ev.push_back(secondsToNs(1.5), 1, 0, true);
  ev.push_back(secondsToNs(1.5), 2, 1, false);
  EXPECT_EQ(rec.addEvents(ev, 0, ev.size()), ev.size());
  const cv::Mat img = rec.image(secondsToNs(2.0));
  // Pixel (1,0): 0.3 at 1.0 s, decays e^{-2·0.5}, +0.3 at 1.5 s, decays e^{-2·0.5}.
  const double expected = (0.3 * std::exp(-1.0) + 0.3) * std::exp(-1.0);
  EXPECT_NEAR(img.at<float>(0, 1), expected, 1e-6);
  EXPECT_NEAR(img.at<float>(1, 2), -0.3 * std::exp(-1.0), 1e-6);
  EXPECT_EQ(img.at<float>(0, 0), 0.0f);
}

TEST(ImageReconstructor, StepsByThePolaritysOwnThreshold) {
  ImageReconstructorOptions o;
  o.cutoff_frequency_rad_s = 0.0;  // no decay: the state is the sum of the steps
  o.contrast_threshold = 0.5;
  o.contrast_threshold_neg = 0.38;
  o.fuse_frames = false;
  o.output_every_events = 0;
  ImageReconstructor rec(o, 2, 1);
  EventArray ev;
  ev.push_back(secondsToNs(0.1), 0, 0, true);
  ev.push_back(secondsToNs(0.2), 0, 0, true);
  ev.push_back(secondsToNs(0.3), 1, 0, false);
  rec.addEvents(ev, 0, ev.size());
  const cv::Mat img = rec.image(secondsToNs(0.4));
  EXPECT_NEAR(img.at<float>(0, 0), 1.0, 1e-6);
  EXPECT_NEAR(img.at<float>(0, 1), -0.38, 1e-6);
}

// Zeros are filled from the event camera's stated thresholds, else the
// DAVIS240C's; stated options are kept.
TEST(FrontendOptions, SensorThresholdsFillTheUnsetOnes) {
  const FrontendOptions unset;
  const FrontendOptions from_rig =
      resolveSensorParameters(unset, {{"contrast_threshold_pos", 0.3}, {"contrast_threshold_neg", 0.2}});
  EXPECT_DOUBLE_EQ(from_rig.eklt.batch_contrast_threshold, 0.25);
  EXPECT_DOUBLE_EQ(from_rig.reconstruction.contrast_threshold, 0.3);
  EXPECT_DOUBLE_EQ(from_rig.reconstruction.contrast_threshold_neg, 0.2);
  const FrontendOptions davis = resolveSensorParameters(unset, {{"pixel_pitch_um", 18.5}});
  EXPECT_DOUBLE_EQ(davis.eklt.batch_contrast_threshold, 0.44);
  EXPECT_DOUBLE_EQ(davis.reconstruction.contrast_threshold, 0.5);
  EXPECT_DOUBLE_EQ(davis.reconstruction.contrast_threshold_neg, 0.38);
  FrontendOptions stated;
  stated.eklt.batch_contrast_threshold = 0.1;
  stated.reconstruction.contrast_threshold = 0.2;
  const FrontendOptions kept = resolveSensorParameters(stated, {{"contrast_threshold_pos", 0.3}, {"contrast_threshold_neg", 0.2}});
  EXPECT_DOUBLE_EQ(kept.eklt.batch_contrast_threshold, 0.1);
  EXPECT_DOUBLE_EQ(kept.reconstruction.contrast_threshold, 0.2);
  EXPECT_DOUBLE_EQ(kept.reconstruction.contrast_threshold_neg, 0.0);  // 0: as contrast_threshold
}

TEST(ImageReconstructor, FusesUnsaturatedFramesAndKeepsEventsWhereSaturated) {
  ImageReconstructorOptions o;
  o.cutoff_frequency_rad_s = 5.0;
  o.contrast_threshold = 0.2;
  o.output_every_events = 0;
  ImageReconstructor rec(o, 2, 1);
  cv::Mat frame(1, 2, CV_8UC1);
  frame.at<std::uint8_t>(0, 0) = 100;  // usable
  frame.at<std::uint8_t>(0, 1) = 255;  // saturated: not fused
  rec.addFrame(0, frame);
  EventArray ev;
  ev.push_back(secondsToNs(0.1), 0, 0, true);
  ev.push_back(secondsToNs(0.1), 1, 0, true);
  rec.addEvents(ev, 0, ev.size());
  const cv::Mat img = rec.image(secondsToNs(0.3));
  const double lf = std::log(100.0 / 255.0 + 0.01);
  // Pixel 0: the first frame sets the estimate to L_F; +C at 0.1 s, which
  // then relaxes back towards L_F for 0.2 s.
  EXPECT_NEAR(img.at<float>(0, 0), lf + 0.2 * std::exp(-5.0 * 0.2), 1e-5);
  // Pixel 1 keeps L_F = 0 (saturated frame), so it is the high-pass filter.
  EXPECT_NEAR(img.at<float>(0, 1), 0.2 * std::exp(-5.0 * 0.2), 1e-6);
}

TEST(ImageReconstructor, EmitsFramesEveryNEventsAndAtARate) {
  ImageReconstructorOptions o;
  o.output_every_events = 3;
  ImageReconstructor rec(o, 2, 2);
  EventArray ev;
  for (int i = 0; i < 7; ++i) ev.push_back(1000 * i, 0, 0, i % 2 == 0);
  std::vector<TimeNs> due;
  std::size_t begin = 0;
  while (begin < ev.size()) {
    begin = rec.addEvents(ev, begin, ev.size());
    if (rec.frameDue()) {
      due.push_back(rec.dueTime());
      rec.image(rec.dueTime());
    }
  }
  EXPECT_EQ(due, (std::vector<TimeNs>{2000, 5000}));

  ImageReconstructorOptions r;
  r.output_every_events = 0;
  r.output_rate_hz = 1000.0;  // every 1 ms of event time
  ImageReconstructor rate(r, 2, 2);
  EventArray ev2;
  for (int i = 0; i <= 10; ++i) ev2.push_back(secondsToNs(i * 0.4e-3), 1, 1, true);
  due.clear();
  begin = 0;
  while (begin < ev2.size()) {
    begin = rate.addEvents(ev2, begin, ev2.size());
    if (rate.frameDue()) {
      due.push_back(rate.dueTime());
      rate.image(rate.dueTime());
    }
  }
  // First event at 0 starts the clock: frames at the first events ≥ 1 ms, ≥ 2 ms, ≥ 3 ms... up to 4 ms.
  EXPECT_EQ(due, (std::vector<TimeNs>{secondsToNs(1.2e-3), secondsToNs(2.0e-3), secondsToNs(3.2e-3),
                                      secondsToNs(4.0e-3)}));
}

TEST(GyroPredictor, IntegratesConstantRateAndPredictsRotatedProjection) {
  const Camera cam = Camera::create("pinhole", 240, 180, Vec4(200, 200, 120, 90), VecX());
  // Camera looking along body +x: R_B_C maps C's z to B's x.
  Mat3 R_B_C;
  R_B_C << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  const Pose T_B_C(R_B_C, Vec3(0.1, 0.0, 0.05));
  GyroPredictor pred(cam, T_B_C);
  const Vec3 omega_B(0.3, -0.2, 0.5);
  for (int k = 0; k <= 100; ++k) pred.addImu(ImuSample{secondsToNs(0.005 * k), Vec3::Zero(), omega_B});
  const TimeNs t0 = secondsToNs(0.1), t1 = secondsToNs(0.3);
  const Mat3 R = pred.rotation(t0, t1);
  EXPECT_LT((R - so3::exp(omega_B * 0.2)).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT((pred.rotation(t1, t0) - R.transpose()).cwiseAbs().maxCoeff(), 1e-12);
  // A point at infinity seen at uv0 at t0 is seen at t1 along R_C1_C0 f0.
  const Vec2 uv0(60.0, 130.0);
  Vec3 f0;
  ASSERT_TRUE(cam.unproject(uv0, &f0));
  const Mat3 R_C0_C1 = R_B_C.transpose() * so3::exp(omega_B * 0.2) * R_B_C;
  Vec2 expected;
  ASSERT_TRUE(cam.project(R_C0_C1.transpose() * f0, &expected));
  const auto uv1 = pred.predict(uv0, t0, t1);
  ASSERT_TRUE(uv1.has_value());
  EXPECT_LT((*uv1 - expected).norm(), 1e-9);
  EXPECT_GT((*uv1 - uv0).norm(), 10.0);  // it did move
}

// The frontend hands its T_B_C to the KLT tracker when klt.imu_prediction
// asks for the gyro: without one it is an error, with one the tracker takes
// the IMU (and the pipeline must feed it between frames).
TEST(Frontend, KltGyroPredictionTakesTheExtrinsicsAndTheImu) {
  const Camera cam = Camera::create("pinhole", 240, 180, Vec4(200, 200, 120, 90), VecX());
  FrontendOptions options;
  options.tracker = "klt";
  EXPECT_FALSE(Frontend(options, cam).tracker().usesImu());
  EXPECT_FALSE(Frontend(options, cam).usesImu());
  options.klt.imu_prediction = true;
  EXPECT_THROW(Frontend(options, cam), Error);
  EXPECT_TRUE(Frontend(options, cam, Pose()).tracker().usesImu());
  EXPECT_TRUE(Frontend(options, cam, Pose()).usesImu());  // evio track reads the IMU then
}

// Every track point the frontend hands out states the error time constant
// of the tracker that made it (its options section's error_time_s), and
// only that tracker's: the other sections' values are not used.
/// A 240 × 180 frame of 4 × 5 bright 16 px squares on a dark ground,
/// blurred so that each corner has one strongest pixel (FAST's suppression).
cv::Mat squaresImage() {
  cv::Mat image(180, 240, CV_8UC1, cv::Scalar(20));
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 5; ++c) image(cv::Rect(30 + 40 * c, 25 + 35 * r, 16, 16)).setTo(cv::Scalar(220));
  cv::GaussianBlur(image, image, cv::Size(5, 5), 1.5);
  return image;
}

TEST(Frontend, TrackPointsStateTheirTrackersErrorTimeConstant) {
  const Camera cam = Camera::create("pinhole", 240, 180, Vec4(200, 200, 120, 90), VecX());
  const cv::Mat image = squaresImage();
  for (const std::string tracker : {"klt", "eklt"}) {
    FrontendOptions options;
    options.tracker = tracker;
    options.klt.error_time_s = 0.5;
    options.eklt.error_time_s = 0.054;
    options.haste.error_time_s = 0.01;
    Frontend frontend(options, cam);
    frontend.addFrame(secondsToNs(0.1), image);
    frontend.addFrame(secondsToNs(0.15), image);  // EKLT's seeds start on the second frame
    TrackPoints points;
    frontend.drainTrackPoints(points);
    ASSERT_FALSE(points.empty()) << tracker;
    for (const TrackPoint& p : points) EXPECT_EQ(p.error_time_s, tracker == "klt" ? 0.5 : 0.054) << tracker;
  }
}

// EKLT's detections and bootstraps on sensor frames are marked measured on
// a frame (they carry no event lag); on images rebuilt from events they lag
// as the events do, so the frontend leaves them unmarked.
TEST(Frontend, EkltPointsAreMeasuredOnFramesOnlyOnSensorFrames) {
  const Camera cam = Camera::create("pinhole", 240, 180, Vec4(200, 200, 120, 90), VecX());
  const cv::Mat image = squaresImage();
  // Ten events at one corner pixel, away from the squares, from t0 on.
  const auto events = [](double t0) {
    EventArray ev;
    for (int i = 0; i < 10; ++i) ev.push_back(secondsToNs(t0 + 1e-4 * i), 0, 0, i % 2 == 0);
    return ev;
  };
  const auto pointsOf = [&](const std::string& source) {
    FrontendOptions options;
    options.tracker = "eklt";
    options.image_source = source;
    options.reconstruction.output_every_events = 10;  // one image per addEvents below
    Frontend frontend(options, cam);
    frontend.addFrame(secondsToNs(0.1), image);  // reconstructed: fused into the image
    frontend.addEvents(events(0.11));
    if (source == "frames") frontend.addFrame(secondsToNs(0.15), image);
    frontend.addEvents(events(0.15));
    TrackPoints points;
    frontend.drainTrackPoints(points);
    return points;
  };
  const TrackPoints on_frames = pointsOf("frames");
  const TrackPoints rebuilt = pointsOf("reconstructed");
  ASSERT_FALSE(on_frames.empty());
  ASSERT_FALSE(rebuilt.empty());
  for (const TrackPoint& p : on_frames) EXPECT_TRUE(p.measured_on_frame) << "feature " << p.feature_id;
  for (const TrackPoint& p : rebuilt) EXPECT_FALSE(p.measured_on_frame) << "feature " << p.feature_id;
}

// KLT states the σ of its section (position_sigma_px) as each point's
// covariance σ² I; without it a point states none (the backend's σ_img).
// EKLT keeps the covariance of its own fit whatever KLT's section says.
TEST(Frontend, KltPointsStateTheirSectionsPositionSigma) {
  const Camera cam = Camera::create("pinhole", 240, 180, Vec4(200, 200, 120, 90), VecX());
  const cv::Mat image = squaresImage();
  const auto pointsOf = [&](const std::string& tracker, double klt_sigma_px) {
    FrontendOptions options;
    options.tracker = tracker;
    options.klt.position_sigma_px = klt_sigma_px;
    options.haste.position_sigma_px = 7.0;  // another tracker's section: not used
    Frontend frontend(options, cam);
    frontend.addFrame(secondsToNs(0.1), image);
    frontend.addFrame(secondsToNs(0.15), image);
    TrackPoints points;
    frontend.drainTrackPoints(points);
    return points;
  };
  const TrackPoints stated = pointsOf("klt", 3.0);
  ASSERT_FALSE(stated.empty());
  for (const TrackPoint& p : stated) EXPECT_EQ(p.cov_px, Mat2(9.0 * Mat2::Identity()));
  const TrackPoints unstated = pointsOf("klt", 0.0);
  ASSERT_EQ(unstated.size(), stated.size());
  for (std::size_t i = 0; i < unstated.size(); ++i) {
    EXPECT_EQ(unstated[i].cov_px, Mat2::Zero());
    EXPECT_EQ(unstated[i].uv, stated[i].uv);  // the σ changes what is stated, not the track
  }
  const TrackPoints eklt = pointsOf("eklt", 3.0);
  ASSERT_FALSE(eklt.empty());
  for (const TrackPoint& p : eklt) EXPECT_NE(p.cov_px, Mat2(9.0 * Mat2::Identity()));
}

TEST(FrontendOptions, DefaultsRoundTripThroughYamlAndOverridesAreChecked) {
  const FrontendOptions defaults;
  FrontendOptions back;
  config::fill(config::loadString(config::toYaml(defaults), "defaults.yaml"), "", back);
  EXPECT_TRUE(config::equal(defaults, back));
  // The reference values (docs/algorithms.md#eklt) are the defaults.
  EXPECT_EQ(defaults.eklt.patch_size_px, 19);
  EXPECT_EQ(defaults.eklt.max_features, 60);
  EXPECT_EQ(defaults.eklt.min_features, 45);
  EXPECT_DOUBLE_EQ(defaults.eklt.batch_displacement_px, 0.6);
  EXPECT_EQ(defaults.eklt.batch_min_events, 5);
  EXPECT_EQ(defaults.eklt.batch_max_events, 500);
  EXPECT_DOUBLE_EQ(defaults.eklt.min_tracking_quality, 0.6);
  EXPECT_EQ(defaults.eklt.max_iterations, 25);
  EXPECT_EQ(defaults.klt.fast_threshold, 20);
  EXPECT_DOUBLE_EQ(defaults.klt.ransac_threshold_px, 0.6);
  EXPECT_EQ(SynchronizerOptions{}.n_e, 3200);

  auto doc = config::loadString("tracker: klt\n", "t.yaml");
  config::applyOverride(doc, "eklt.patch_size_px=17");
  FrontendOptions o;
  config::fill(doc, "", o);
  EXPECT_EQ(o.tracker, "klt");
  EXPECT_EQ(o.eklt.patch_size_px, 17);
  for (const char* bad : {"eklt:\n  patch_size_px: 18\n", "tracker: orb\n", "eklt:\n  solver: gn\n",
                          "image_source: video\n", "prefilter:\n  random_keep_one_in: 0\n", "eklt:\n  pach: 3\n"}) {
    FrontendOptions x;
    EXPECT_THROW(config::fill(config::loadString(bad, "bad.yaml"), "", x), Error) << bad;
  }
}

}  // namespace
}  // namespace evio::estimator
