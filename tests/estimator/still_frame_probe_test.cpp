// The still probe (frontend/still_frame_probe.h) on synthetic frames with
// exact truth: a texture of Gaussian blobs rendered at a known sub-pixel
// shift. Still frames give the first frame's corners back; shifted frames
// give them moved by the shift; the probe stops after its span and says
// nothing without corners.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <opencv2/core.hpp>

#include "evio/estimator/frontend/still_frame_probe.h"

namespace evio::estimator {
namespace {

/// 240 × 180, 8 bit: 60 blobs (σ 3 px) of random brightness, all moved by
/// (dx, dy) px; the same blobs for every call with the same seed.
cv::Mat blobs(double dx, double dy, unsigned seed = 11) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> ux(0.0, 240.0), uy(0.0, 180.0), ua(40.0, 120.0);
  struct Blob {
    double x, y, a;
  };
  std::vector<Blob> b;
  for (int k = 0; k < 60; ++k) b.push_back({ux(rng), uy(rng), ua(rng)});
  cv::Mat image(180, 240, CV_8UC1);
  for (int y = 0; y < 180; ++y)
    for (int x = 0; x < 240; ++x) {
      double v = 40.0;
      for (const Blob& k : b) {
        const double ex = x - k.x - dx, ey = y - k.y - dy;
        v += k.a * std::exp(-(ex * ex + ey * ey) / (2.0 * 9.0));
      }
      image.at<std::uint8_t>(y, x) = cv::saturate_cast<std::uint8_t>(v);
    }
  return image;
}

TEST(StillFrameProbe, StillFramesGiveTheFirstCornersBackAndShiftedOnesMoveByTheShift) {
  StillFrameProbe probe(1.0);
  const auto first = probe.addFrame(0, blobs(0.0, 0.0));
  ASSERT_TRUE(first.has_value());
  ASSERT_GE(first->corners_px.size(), 10u);
  // The same image again: every corner found where it was (KLT converges in
  // place: hundredths of a pixel at most).
  const auto still = probe.addFrame(secondsToNs(0.05), blobs(0.0, 0.0));
  ASSERT_TRUE(still.has_value());
  ASSERT_EQ(still->corners_px.size(), first->corners_px.size());
  for (std::size_t i = 0; i < still->corners_px.size(); ++i) {
    EXPECT_EQ(still->corners_px[i].first, first->corners_px[i].first);
    EXPECT_LT((still->corners_px[i].second - first->corners_px[i].second).norm(), 0.01);
  }
  // Moved by (1.5, −0.7) px: found moved by it, to 0.1 px (8-bit rounding of
  // the rendered texture), against the first frame, not the one before.
  const Vec2 shift(1.5, -0.7);
  const auto moved = probe.addFrame(secondsToNs(0.1), blobs(shift.x(), shift.y()));
  ASSERT_TRUE(moved.has_value());
  ASSERT_GE(moved->corners_px.size(), first->corners_px.size() - 2);
  for (const auto& [id, uv] : moved->corners_px) {
    const Vec2& uv0 = first->corners_px[static_cast<std::size_t>(id)].second;
    EXPECT_LT((uv - uv0 - shift).norm(), 0.1) << "corner " << id;
  }
  // Past its span (1 s after the first frame) the probe is done.
  EXPECT_TRUE(probe.addFrame(secondsToNs(1.0), blobs(0.0, 0.0)).has_value());
  EXPECT_FALSE(probe.addFrame(secondsToNs(1.05), blobs(0.0, 0.0)).has_value());
}

TEST(StillFrameProbe, CornersThatDoNotTrackBackAreDropped) {
  // A later frame of other blobs: Lucas–Kanade converges somewhere for many
  // corners (status OK), but tracked back they do not return to within
  // 0.5 px of their start: fewer than the five the window's test needs.
  StillFrameProbe probe(1.0);
  const auto first = probe.addFrame(0, blobs(0.0, 0.0));
  ASSERT_TRUE(first.has_value());
  ASSERT_GE(first->corners_px.size(), 10u);
  const auto other = probe.addFrame(secondsToNs(0.05), blobs(0.0, 0.0, 12));
  ASSERT_TRUE(other.has_value());
  EXPECT_LT(other->corners_px.size(), 5u);
}

TEST(StillFrameProbe, OffOrWithoutCornersItSaysNothing) {
  StillFrameProbe off(0.0);
  EXPECT_FALSE(off.addFrame(0, blobs(0.0, 0.0)).has_value());
  StillFrameProbe flat(1.0);
  const cv::Mat grey(180, 240, CV_8UC1, cv::Scalar(90));
  EXPECT_FALSE(flat.addFrame(0, grey).has_value());
  EXPECT_FALSE(flat.addFrame(secondsToNs(0.05), blobs(0.0, 0.0)).has_value());
}

}  // namespace
}  // namespace evio::estimator
