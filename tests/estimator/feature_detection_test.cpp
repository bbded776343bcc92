// Harris detection (EKLT's corners): the quality level is relative to the
// frame's strongest response, which is what limits how many corners EKLT
// starts over a scene with one high-contrast feature (issue 18, session 55).
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "evio/estimator/frontend/feature_detection.h"

namespace evio::estimator {
namespace {

constexpr int kWidth = 240;
constexpr int kHeight = 180;
constexpr int kBackground = 100;
constexpr int kSide = 24;  // px, every square

struct Square {
  int x0, y0, grey;
};

/// One bright square (contrast 120 grey levels) and four faint ones
/// (contrast 56). Harris' response is quartic in the contrast (its structure
/// tensor is quadratic in the gradient and the response is det − k tr²), so
/// the faint corners respond (56/120)⁴ = 0.047 of the bright ones: below a
/// level of 0.3, above 0.01.
std::vector<Square> squares() {
  return {{30, 30, kBackground + 120},
          {130, 30, kBackground + 56},
          {30, 110, kBackground + 56},
          {130, 110, kBackground + 56},
          {190, 70, kBackground + 56}};
}

cv::Mat image(const std::vector<Square>& sq) {
  cv::Mat img(kHeight, kWidth, CV_8UC1, cv::Scalar(kBackground));
  for (const Square& s : sq) img(cv::Rect(s.x0, s.y0, kSide, kSide)).setTo(s.grey);
  return img;
}

/// The square's outer corners, in the pixel-centre convention (a pixel's
/// centre at its integer coordinates): the edge lies half a pixel outside
/// the last lit pixel.
std::vector<Vec2> cornersOf(const Square& s) {
  const double a = s.x0 - 0.5, b = s.x0 + kSide - 0.5;
  const double c = s.y0 - 0.5, d = s.y0 + kSide - 0.5;
  return {Vec2(a, c), Vec2(b, c), Vec2(a, d), Vec2(b, d)};
}

/// The distance from p to the nearest of `corners`.
double distanceToNearest(const Vec2& p, const std::vector<Vec2>& corners) {
  double best = 1e9;
  for (const Vec2& c : corners) best = std::min(best, (p - c).norm());
  return best;
}

HarrisSettings settingsAt(double quality_level) {
  HarrisSettings s;
  s.max_corners = 100;
  s.quality_level = quality_level;
  return s;
}

TEST(FeatureDetection, HarrisLevelIsRelativeToTheStrongestCorner) {
  const std::vector<Square> sq = squares();
  const cv::Mat img = image(sq);
  std::vector<Vec2> all_corners;
  for (const Square& s : sq)
    for (const Vec2& c : cornersOf(s)) all_corners.push_back(c);
  const std::vector<Vec2> bright = cornersOf(sq[0]);

  // At 0.3 only the bright square's four corners pass.
  const std::vector<Vec2> strong = detectHarris(img, {}, settingsAt(0.3));
  ASSERT_EQ(strong.size(), 4u);
  for (const Vec2& p : strong) EXPECT_LT(distanceToNearest(p, bright), 2.0) << p.transpose();

  // At 0.01 every square's four corners pass, and nothing else.
  const std::vector<Vec2> weak = detectHarris(img, {}, settingsAt(0.01));
  ASSERT_EQ(weak.size(), all_corners.size());
  for (const Vec2& p : weak) EXPECT_LT(distanceToNearest(p, all_corners), 2.0) << p.transpose();

  // Without the bright square the faint ones are the strongest: all pass at 0.3.
  const std::vector<Square> faint(sq.begin() + 1, sq.end());
  EXPECT_EQ(detectHarris(image(faint), {}, settingsAt(0.3)).size(), 4u * faint.size());
}

TEST(FeatureDetection, HarrisKeepsAwayFromLiveFeatures) {
  const std::vector<Square> sq = squares();
  const cv::Mat img = image(sq);
  // A live feature on the bright square's top-left corner blocks that corner
  // (a box of ±min_distance_px) and none of the others.
  const Vec2 live = cornersOf(sq[0])[0];
  const std::vector<Vec2> found = detectHarris(img, {live}, settingsAt(0.01));
  EXPECT_EQ(found.size(), 4u * sq.size() - 1u);
  for (const Vec2& p : found) EXPECT_GT((p - live).norm(), settingsAt(0.01).min_distance_px) << p.transpose();
}

}  // namespace
}  // namespace evio::estimator
