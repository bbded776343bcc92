#pragma once
/// @file stage_cpu_split.h
/// CPU seconds of one thread split among the pipeline's stages
/// (summary.yaml `stage_cpu_s`), without a system call per stage.
///
/// Reading a thread's CPU clock (CLOCK_THREAD_CPUTIME_ID) is a system call;
/// read at every stage of every input item (about 220 000 reads in a 12 s
/// EKLT-VIO run) it cost about 8 % of the run's CPU. Here each lap reads the
/// steady clock instead (vDSO, no system call), and the thread's CPU clock
/// is read once per window of at least `kWindowS` of wall time: the thread's
/// CPU seconds in the window are split among the window's laps in
/// proportion to their wall seconds. Waiting between laps (for the next
/// item) uses no CPU and so adds nothing; the little CPU used between laps
/// (bookkeeping that belongs to no stage) is shared among the stages.
///
/// Each stage's share is exact when the thread ran without waiting inside
/// the window's laps (one thread on an idle core) and otherwise follows the
/// stages' wall time. One instance per thread: two on one thread would each
/// count the thread's whole CPU. A window still open when the owner stops is
/// closed by `flushByWall` from another thread: its laps count their wall
/// seconds.

#include <array>
#include <chrono>
#include <cstddef>

#include "evio/core/stopwatch.h"

namespace evio::estimator {

class StageCpuSplit {
 public:
  /// Minimum wall time between two reads of the thread's CPU clock, s.
  static constexpr double kWindowS = 0.02;

  /// Marks now as the start of the next lap; the time since the previous
  /// lap goes to no stage. The first call opens the window (on the thread
  /// whose CPU is measured, as every call but flushByWall).
  void begin() {
    last_ = Clock::now();
    if (!window_open_) openWindow(last_);
  }

  /// Ends a lap: its wall time goes to *stage (the window's CPU is added to
  /// the stages when the window closes).
  void lap(double* stage) {
    const Clock::time_point now = Clock::now();
    add(stage, seconds(now - last_));
    last_ = now;
    if (seconds(now - window_start_) >= kWindowS) closeWindow(now, Stopwatch::threadCpuSeconds());
  }

  /// Closes the open window on the owning thread.
  void flush() {
    if (window_open_) closeWindow(Clock::now(), Stopwatch::threadCpuSeconds());
  }

  /// Closes the open window from another thread once the owner has stopped:
  /// the laps count their wall seconds as CPU seconds.
  void flushByWall() {
    for (std::size_t k = 0; k < n_shares_; ++k) *shares_[k].stage += shares_[k].wall_s;
    n_shares_ = 0;
    window_open_ = false;
  }

 private:
  using Clock = std::chrono::steady_clock;
  struct Share {
    double* stage = nullptr;
    double wall_s = 0.0;
  };

  static double seconds(Clock::duration d) { return std::chrono::duration<double>(d).count(); }

  void openWindow(Clock::time_point now) {
    window_start_ = now;
    window_cpu0_s_ = Stopwatch::threadCpuSeconds();
    window_open_ = true;
  }

  void add(double* stage, double wall_s) {
    for (std::size_t k = 0; k < n_shares_; ++k)
      if (shares_[k].stage == stage) {
        shares_[k].wall_s += wall_s;
        return;
      }
    if (n_shares_ == shares_.size()) {  // more stages than slots: settle by wall time
      *stage += wall_s;
      return;
    }
    shares_[n_shares_++] = Share{stage, wall_s};
  }

  /// Splits the window's CPU seconds among its laps by their wall seconds.
  void closeWindow(Clock::time_point now, double cpu_now_s) {
    const double cpu_s = cpu_now_s - window_cpu0_s_;
    double wall_s = 0.0;
    for (std::size_t k = 0; k < n_shares_; ++k) wall_s += shares_[k].wall_s;
    for (std::size_t k = 0; k < n_shares_; ++k)
      *shares_[k].stage += wall_s > 0.0 ? cpu_s * (shares_[k].wall_s / wall_s) : 0.0;
    n_shares_ = 0;
    window_start_ = now;
    window_cpu0_s_ = cpu_now_s;
  }

  std::array<Share, 8> shares_{};
  std::size_t n_shares_ = 0;
  bool window_open_ = false;
  Clock::time_point window_start_{};
  Clock::time_point last_{};
  double window_cpu0_s_ = 0.0;
};

}  // namespace evio::estimator
