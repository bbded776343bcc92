#pragma once
/// @file progress_line.h
/// A one-line progress display on stderr for long work: share done, rate
/// and ETA, refreshed at most every 0.2 s. Silent when stderr is not a
/// terminal or when quiet, so scripts and logs stay clean.

#include <string>

#include "evio/core/stopwatch.h"

namespace evio::apps {

class ProgressLine {
 public:
  /// `label` starts the line; `unit` names what `update`'s amount counts ("ev", "s sim").
  ProgressLine(std::string label, std::string unit, bool quiet = false);
  ~ProgressLine();

  /// `fraction` of the work done (0..1) and the absolute amount processed so far.
  void update(double fraction, double amount);
  /// Replaces the label (e.g. to show a changing position: "simulate t=1.20/10.00 s").
  void setLabel(std::string label) { label_ = std::move(label); }
  /// Clears the line (prints a final newline when something was shown).
  void finish();

 private:
  std::string label_;
  std::string unit_;
  bool enabled_;
  bool shown_ = false;
  Stopwatch watch_;     ///< since construction
  double last_s_ = 0.0;  ///< watch_ time of the last refresh, s
};

}  // namespace evio::apps
