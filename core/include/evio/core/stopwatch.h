#pragma once
/// @file stopwatch.h
/// Wall-clock timing of work (steady clock, unaffected by clock changes) for
/// the stats and progress lines; never used for simulated or sensor time.

#include <chrono>
#include <ctime>

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

 private:
  using Clock = std::chrono::steady_clock;
  Clock::time_point start_;
};

}  // namespace evio
