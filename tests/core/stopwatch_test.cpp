#include "evio/core/stopwatch.h"

#include <gtest/gtest.h>

#include <chrono>
#include <thread>

namespace evio {
namespace {

TEST(Stopwatch, MeasuresASleep) {
  const Stopwatch watch;
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  const double slept = watch.seconds();
  EXPECT_GE(slept, 0.020);
  EXPECT_LT(slept, 5.0);  // generous: the machine may be busy
}

TEST(Stopwatch, RestartMovesTheOrigin) {
  Stopwatch a;
  std::this_thread::sleep_for(std::chrono::milliseconds(5));
  const Stopwatch b;
  a.restart();  // after b started, so a never reads more than b (steady clock)
  const double a_s = a.seconds();
  const double b_s = b.seconds();
  EXPECT_GE(a_s, 0.0);
  EXPECT_LE(a_s, b_s);
}

TEST(Stopwatch, ProcessCpuSecondsGrowsWithWork) {
  const double c0 = Stopwatch::processCpuSeconds();
  volatile double sink = 0.0;
  const Stopwatch watch;
  while (watch.seconds() < 0.05) sink = sink + 1.0;  // busy for 50 ms of wall time
  const double used = Stopwatch::processCpuSeconds() - c0;
  EXPECT_GE(c0, 0.0);
  EXPECT_GT(used, 0.0);
}

}  // namespace
}  // namespace evio
