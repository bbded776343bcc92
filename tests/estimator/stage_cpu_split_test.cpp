// The pipeline's per-stage CPU split (estimator/pipeline/src/stage_cpu_split.h):
// the thread's CPU clock read once per window, shared among the laps by
// their busy wall time. Exact arithmetic on scripted clocks, and one check
// on the real ones.
#include <gtest/gtest.h>

#include <thread>

#include "evio/core/stopwatch.h"
#include "stage_cpu_split.h"

namespace evio::estimator {
namespace {

/// Clocks the test advances by hand: wall and thread CPU seconds.
struct ScriptedClocks {
  static inline double wall_s = 0.0;
  static inline double cpu_s = 0.0;
  static inline int cpu_reads = 0;
  static double wallSeconds() { return wall_s; }
  static double threadCpuSeconds() {
    ++cpu_reads;
    return cpu_s;
  }
  static void reset() { wall_s = cpu_s = 0.0, cpu_reads = 0; }
  /// The thread works for `s` seconds (wall and CPU).
  static void work(double s) { wall_s += s, cpu_s += s; }
  /// The thread waits for `s` seconds (wall only).
  static void wait(double s) { wall_s += s; }
};
using Split = BasicStageCpuSplit<ScriptedClocks>;

TEST(StageCpuSplit, OnAnIdleCoreEachStageGetsItsOwnCpuWithOneClockReadPerWindow) {
  ScriptedClocks::reset();
  Split split;
  double a = 0.0, b = 0.0;
  for (int item = 0; item < 100; ++item) {  // 100 items of 1 ms + 2 ms, waiting 1 ms between them
    split.begin();
    ScriptedClocks::work(0.001);
    split.lap(&a);
    ScriptedClocks::work(0.002);
    split.lap(&b);
    ScriptedClocks::wait(0.001);
  }
  split.flush();
  EXPECT_NEAR(a, 0.1, 1e-12);
  EXPECT_NEAR(b, 0.2, 1e-12);
  // 0.4 s of wall time in windows of at least 20 ms: at most 21 CPU reads, not 200.
  EXPECT_LE(ScriptedClocks::cpu_reads, 21);
}

TEST(StageCpuSplit, AWaitReportedInsideALapTakesNoShare) {
  ScriptedClocks::reset();
  Split split;
  double tracking = 0.0, sync = 0.0;
  split.begin();
  ScriptedClocks::work(0.004);
  ScriptedClocks::wait(0.006);  // the tracker waits for its workers
  split.lap(&tracking, 0.006);
  ScriptedClocks::work(0.002);
  split.lap(&sync);
  split.flush();
  EXPECT_NEAR(tracking, 0.004, 1e-12);
  EXPECT_NEAR(sync, 0.002, 1e-12);
}

TEST(StageCpuSplit, CpuUsedBetweenLapsIsSharedAndAnUnreportedWaitFollowsWallTime) {
  ScriptedClocks::reset();
  Split split;
  double a = 0.0, b = 0.0;
  split.begin();
  ScriptedClocks::work(0.010);
  split.lap(&a);
  ScriptedClocks::work(0.004);  // bookkeeping between the laps
  split.begin();
  ScriptedClocks::work(0.010);
  ScriptedClocks::wait(0.010);  // not reported: counted as busy
  split.lap(&b);
  split.flush();
  // 0.024 s of CPU in the window; the laps' busy wall times 0.010 and 0.020.
  EXPECT_NEAR(a + b, 0.024, 1e-12);
  EXPECT_NEAR(a, 0.024 / 3.0, 1e-12);
}

TEST(StageCpuSplit, MoreStagesThanSlotsTakeTheirWallTimeAndTheRestTheRest) {
  ScriptedClocks::reset();
  Split split;
  double stages[Split::kMaxStages + 2] = {};
  split.begin();
  for (double& s : stages) {
    ScriptedClocks::work(0.001);
    split.lap(&s);
  }
  split.flush();
  double total = 0.0;
  for (double s : stages) {
    EXPECT_NEAR(s, 0.001, 1e-12);
    total += s;
  }
  EXPECT_NEAR(total, ScriptedClocks::cpu_s, 1e-12);  // nothing counted twice
}

TEST(StageCpuSplit, AWindowLeftOpenIsClosedByWallTime) {
  ScriptedClocks::reset();
  Split split;
  double a = 0.0;
  split.begin();
  ScriptedClocks::work(0.005);  // inside one window
  split.lap(&a);
  EXPECT_EQ(a, 0.0);  // nothing settled before the window closes
  split.flushByWall();
  EXPECT_NEAR(a, 0.005, 1e-12);
  split.flushByWall();  // a second close adds nothing
  EXPECT_NEAR(a, 0.005, 1e-12);
}

/// Spins until the calling thread has used `cpu_s` more CPU seconds.
void burnCpu(double cpu_s) {
  const double until = Stopwatch::threadCpuSeconds() + cpu_s;
  volatile double sink = 0.0;
  while (Stopwatch::threadCpuSeconds() < until)
    for (int i = 0; i < 1000; ++i) sink = sink + 1.0;
}

TEST(StageCpuSplit, OnTheRealClocksEveryCpuSecondGoesToAStageAndSleepingToNone) {
  double a = 0.0, b = 0.0;
  StageCpuSplit split;
  const double cpu0 = Stopwatch::threadCpuSeconds();
  for (int k = 0; k < 12; ++k) {
    split.begin();
    burnCpu(0.003);
    split.lap(&a);
    burnCpu(0.006);
    split.lap(&b);
    std::this_thread::sleep_for(std::chrono::milliseconds(4));  // waiting between items
  }
  split.flush();
  const double cpu = Stopwatch::threadCpuSeconds() - cpu0;
  // Whatever the scheduler did, the total is the thread's CPU (the clock
  // reads and the loop between the window's opening and the first begin are
  // a few µs); the sleeps add nothing.
  EXPECT_NEAR(a + b, cpu, 1e-3);
  EXPECT_GE(a + b, 12 * 0.009);
}

}  // namespace
}  // namespace evio::estimator
