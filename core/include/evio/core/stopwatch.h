#pragma once
/// @file stopwatch.h
/// Wall-clock timing of work (steady clock, unaffected by clock changes) for
/// the stats and progress lines; never used for simulated or sensor time.

#include <chrono>
#include <ctime>

#include <time.h>

namespace evio {

class Stopwatch {
 public:
  /// Starts timing now.
  Stopwatch() : start_(Clock::now()) {}

  /// Wall time since construction or the last restart(), s.
  double seconds() const { return std::chrono::duration<double>(Clock::now() - start_).count(); }

  /// Starts timing again from now.
  void restart() { start_ = Clock::now(); }

  /// CPU time used by the process so far (all threads), s (std::clock).
  /// Differences of two readings time a piece of work.
  static double processCpuSeconds() { return static_cast<double>(std::clock()) / CLOCKS_PER_SEC; }

  /// CPU time of the process (all threads), s, with ns resolution
  /// (clock_gettime CLOCK_PROCESS_CPUTIME_ID); about 0.3 µs per call.
  static double processCpuSecondsPrecise() { return cpuClockSeconds(CLOCK_PROCESS_CPUTIME_ID); }

  /// CPU time of the calling thread, s (CLOCK_THREAD_CPUTIME_ID).
  static double threadCpuSeconds() { return cpuClockSeconds(CLOCK_THREAD_CPUTIME_ID); }

 private:
  static double cpuClockSeconds(clockid_t id) {
    timespec ts{};
    clock_gettime(id, &ts);
    return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
  }
  using Clock = std::chrono::steady_clock;
  Clock::time_point start_;
};

}  // namespace evio
