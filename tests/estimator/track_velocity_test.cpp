#include "evio/estimator/frontend/track_velocity.h"

#include <gtest/gtest.h>

#include "evio/core/error.h"

namespace evio::estimator {
namespace {

TimeNs ms(double t) { return secondsToNs(t * 1e-3); }

// On a line every window gives the line's velocity exactly.
TEST(TrackVelocity, ALineGivesItsVelocityForAnyWindow) {
  const Vec2 uv0(10, -4), v(250, 125);  // px, px/s
  for (const double window : {0.0, 0.005, 0.02, 0.5}) {
    TrackVelocity track(window);
    EXPECT_FALSE(track.velocity().has_value());
    for (int k = 0; k < 30; ++k) track.add(ms(1.7 * k), uv0 + v * (1.7e-3 * k));
    ASSERT_TRUE(track.velocity().has_value());
    EXPECT_LT((*track.velocity() - v).norm(), 1e-6) << "window " << window;
  }
}

// The window holds the points of its span and the newest two at least:
// memory stays bounded as the track grows.
TEST(TrackVelocity, KeepsTheWindowsPointsAndTheNewestTwo) {
  TrackVelocity two(0.0), twenty(0.02);
  for (int k = 0; k < 1000; ++k) {
    two.add(ms(2.0 * k), Vec2(k, 0));
    twenty.add(ms(2.0 * k), Vec2(k, 0));
  }
  EXPECT_EQ(two.size(), 2u);
  EXPECT_EQ(twenty.size(), 11u);  // t_n − 20 ms … t_n, 2 ms apart
  TrackVelocity sparse(0.02);     // points farther apart than the window: still two
  sparse.add(ms(0), Vec2(0, 0));
  sparse.add(ms(100), Vec2(5, 0));
  EXPECT_EQ(sparse.size(), 2u);
  EXPECT_NEAR(sparse.velocity()->x(), 50.0, 1e-9);
}

// The slope of the newest two points when a window is 0: the last step alone.
TEST(TrackVelocity, WindowZeroIsTheLastStep) {
  TrackVelocity track(0.0);
  track.add(ms(0), Vec2(0, 0));
  track.add(ms(10), Vec2(1, 0));
  track.add(ms(20), Vec2(1, 3));
  EXPECT_LT((*track.velocity() - Vec2(0, 300)).norm(), 1e-9);
}

// A point at the newest time replaces it; an older one is ignored.
TEST(TrackVelocity, SameTimeReplacesOlderIsIgnored) {
  TrackVelocity track(0.0);
  track.add(ms(0), Vec2(0, 0));
  track.add(ms(10), Vec2(9, 9));
  track.add(ms(10), Vec2(1, 0));
  track.add(ms(5), Vec2(100, 100));
  EXPECT_EQ(track.size(), 2u);
  EXPECT_LT((*track.velocity() - Vec2(100, 0)).norm(), 1e-9);
}

TEST(TrackVelocity, RejectsAWindowOutsideZeroToOneSecond) {
  EXPECT_THROW(TrackVelocity(-0.001), Error);
  EXPECT_THROW(TrackVelocity(1.5), Error);
}

}  // namespace
}  // namespace evio::estimator
