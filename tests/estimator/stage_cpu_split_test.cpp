// The pipeline's per-stage CPU split (estimator/pipeline/src/stage_cpu_split.h):
// the thread's CPU clock read once per window, shared among the laps by their
// wall time.
#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include "evio/core/stopwatch.h"
#include "stage_cpu_split.h"

namespace evio::estimator {
namespace {

/// Spins until the calling thread has used `cpu_s` more CPU seconds.
void burnCpu(double cpu_s) {
  const double until = Stopwatch::threadCpuSeconds() + cpu_s;
  volatile double sink = 0.0;
  while (Stopwatch::threadCpuSeconds() < until)
    for (int i = 0; i < 1000; ++i) sink = sink + 1.0;
}

TEST(StageCpuSplit, SharesTheThreadsCpuAmongTheLapsAndNothingToWaiting) {
  double a = 0.0, b = 0.0;
  StageCpuSplit split;
  const double cpu0 = Stopwatch::threadCpuSeconds();
  split.begin();
  for (int k = 0; k < 12; ++k) {  // 12 × (3 + 6) ms of CPU: several 20 ms windows
    split.begin();
    burnCpu(0.003);
    split.lap(&a);
    burnCpu(0.006);
    split.lap(&b);
    std::this_thread::sleep_for(std::chrono::milliseconds(4));  // waiting between items
  }
  split.flush();
  const double cpu = Stopwatch::threadCpuSeconds() - cpu0;
  // Every CPU second of the thread goes to a stage, the sleeps add none
  // (the laps' clock reads and the loop are a few µs).
  EXPECT_NEAR(a + b, cpu, 1e-3);
  EXPECT_GE(a + b, 12 * 0.009);
  // The split follows the laps' wall time: 1 : 2 on an idle core. The wide
  // band leaves room for the thread being descheduled inside a lap on a
  // loaded machine.
  EXPECT_GT(a / (a + b), 0.2);
  EXPECT_LT(a / (a + b), 0.5);
}

TEST(StageCpuSplit, AWindowLeftOpenCountsItsLapsByWallTimeFromAnotherThread) {
  double a = 0.0;
  StageCpuSplit split;
  double wall = 0.0;
  std::thread owner([&] {
    const Stopwatch watch;
    split.begin();
    burnCpu(0.002);  // well inside one window
    split.lap(&a);
    wall = watch.seconds();
  });
  owner.join();
  EXPECT_EQ(a, 0.0);  // nothing settled before the window closes
  split.flushByWall();
  EXPECT_GE(a, 0.002);
  EXPECT_LE(a, wall);
  split.flushByWall();  // a second close adds nothing
  EXPECT_LE(a, wall);
}

TEST(StageCpuSplit, MoreStagesThanSlotsAreSettledByWallTime) {
  double stages[10] = {};
  StageCpuSplit split;
  split.begin();
  for (double& s : stages) {
    burnCpu(0.0002);
    split.lap(&s);
  }
  split.flush();
  for (double s : stages) EXPECT_GT(s, 0.0);
}

}  // namespace
}  // namespace evio::estimator
