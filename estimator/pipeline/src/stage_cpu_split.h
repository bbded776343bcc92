#pragma once
/// @file stage_cpu_split.h
/// CPU seconds of one thread split among the pipeline's stages
/// (summary.yaml `stage_cpu_s`), without a system call per stage.
///
/// Reading a thread's CPU clock (CLOCK_THREAD_CPUTIME_ID) is a system call;
/// read at every stage of every input item (about 220 000 reads in a 12 s
/// EKLT-VIO run on poster_6dof) it cost about 6 % of the run's CPU. Here each
/// lap reads the steady clock instead (vDSO, no system call), and the
/// thread's CPU clock is read once per window of at least `kWindowS` of wall
/// time: the thread's CPU seconds in the window are split among the window's
/// laps in proportion to their busy wall seconds (a lap's wall time less
/// what the caller says it spent waiting inside it, e.g. for worker threads).
/// Waiting between laps (for the next item) uses no CPU and so adds nothing;
/// the little CPU used between laps (bookkeeping that belongs to no stage)
/// is shared among the stages.
///
/// Each stage's share is exact when the thread ran on an idle core and every
/// wait inside a lap was reported; otherwise it follows the stages' wall
/// time. One instance per thread: two on one thread would each count the
/// thread's whole CPU. A window still open when the owner stops is closed by
/// `flushByWall` from another thread: its laps count their busy wall seconds
/// (at most kWindowS of CPU is estimated that way).

#include <array>
#include <chrono>
#include <cstddef>

#include "evio/core/stopwatch.h"

namespace evio::estimator {

/// The clocks of StageCpuSplit: wall seconds (steady) and the calling
/// thread's CPU seconds. Tests substitute their own.
struct SystemStageClocks {
  static double wallSeconds() {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
  }
  static double threadCpuSeconds() { return Stopwatch::threadCpuSeconds(); }
};

template <class Clocks>
class BasicStageCpuSplit {
 public:
  /// Minimum wall time between two reads of the thread's CPU clock, s.
  static constexpr double kWindowS = 0.02;
  /// Stages one window tracks; laps of further stages count their wall time.
  static constexpr std::size_t kMaxStages = 8;

  /// Marks now as the start of the next lap; the time since the previous
  /// lap goes to no stage. The first call opens the window (on the thread
  /// whose CPU is measured, as every call but flushByWall).
  void begin() {
    last_s_ = Clocks::wallSeconds();
    if (!window_open_) openWindow(last_s_);
  }

  /// Ends a lap: its wall time less `waited_s` (time the caller knows the
  /// thread spent waiting inside the lap) goes to *stage; the window's CPU
  /// is added to the stages when the window closes.
  void lap(double* stage, double waited_s = 0.0) {
    const double now = Clocks::wallSeconds();
    double busy = now - last_s_ - waited_s;
    if (busy < 0.0) busy = 0.0;
    add(stage, busy);
    last_s_ = now;
    if (now - window_start_s_ >= kWindowS) closeWindow(now, Clocks::threadCpuSeconds());
  }

  /// Closes the open window on the owning thread.
  void flush() {
    if (window_open_) closeWindow(Clocks::wallSeconds(), Clocks::threadCpuSeconds());
  }

  /// Closes the open window from another thread once the owner has stopped:
  /// the laps count their busy wall seconds as CPU seconds.
  void flushByWall() {
    for (std::size_t k = 0; k < n_shares_; ++k) *shares_[k].stage += shares_[k].wall_s;
    n_shares_ = 0;
    overflow_wall_s_ = 0.0;
    window_open_ = false;
  }

 private:
  struct Share {
    double* stage = nullptr;
    double wall_s = 0.0;
  };

  void openWindow(double now_s) {
    window_start_s_ = now_s;
    window_cpu0_s_ = Clocks::threadCpuSeconds();
    window_open_ = true;
  }

  void add(double* stage, double wall_s) {
    for (std::size_t k = 0; k < n_shares_; ++k)
      if (shares_[k].stage == stage) {
        shares_[k].wall_s += wall_s;
        return;
      }
    if (n_shares_ == shares_.size()) {  // no slot left: this lap's wall time as its CPU
      *stage += wall_s;
      overflow_wall_s_ += wall_s;
      return;
    }
    shares_[n_shares_++] = Share{stage, wall_s};
  }

  /// Splits the window's CPU seconds (less what overflowing laps took by
  /// wall time) among its laps by their busy wall seconds.
  void closeWindow(double now_s, double cpu_now_s) {
    double cpu_s = cpu_now_s - window_cpu0_s_ - overflow_wall_s_;
    if (cpu_s < 0.0) cpu_s = 0.0;
    double wall_s = 0.0;
    for (std::size_t k = 0; k < n_shares_; ++k) wall_s += shares_[k].wall_s;
    for (std::size_t k = 0; k < n_shares_; ++k)
      *shares_[k].stage += wall_s > 0.0 ? cpu_s * (shares_[k].wall_s / wall_s) : 0.0;
    n_shares_ = 0;
    overflow_wall_s_ = 0.0;
    window_start_s_ = now_s;
    window_cpu0_s_ = cpu_now_s;
  }

  std::array<Share, kMaxStages> shares_{};
  std::size_t n_shares_ = 0;
  double overflow_wall_s_ = 0.0;
  bool window_open_ = false;
  double window_start_s_ = 0.0;
  double last_s_ = 0.0;
  double window_cpu0_s_ = 0.0;
};

using StageCpuSplit = BasicStageCpuSplit<SystemStageClocks>;

}  // namespace evio::estimator
