#include "progress_line.h"

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <limits>

namespace evio::apps {

namespace {
std::string human(double v) {
  char buf[32];
  if (v >= 1e9) std::snprintf(buf, sizeof(buf), "%.2f G", v / 1e9);
  else if (v >= 1e6) std::snprintf(buf, sizeof(buf), "%.2f M", v / 1e6);
  else if (v >= 1e3) std::snprintf(buf, sizeof(buf), "%.2f k", v / 1e3);
  else std::snprintf(buf, sizeof(buf), "%.2f ", v);
  return buf;
}
std::string duration(double s) {
  char buf[32];
  if (!std::isfinite(s)) return "?";
  if (s >= 3600) std::snprintf(buf, sizeof(buf), "%dh%02dm", int(s / 3600), int(std::fmod(s, 3600) / 60));
  else if (s >= 60) std::snprintf(buf, sizeof(buf), "%dm%02ds", int(s / 60), int(std::fmod(s, 60)));
  else std::snprintf(buf, sizeof(buf), "%.0fs", s);
  return buf;
}
}  // namespace

ProgressLine::ProgressLine(std::string label, std::string unit, bool quiet)
    : label_(std::move(label)),
      unit_(std::move(unit)),
      enabled_(!quiet && ::isatty(STDERR_FILENO)) {}

ProgressLine::~ProgressLine() { finish(); }

void ProgressLine::update(double fraction, double amount) {
  if (!enabled_) return;
  const double elapsed = watch_.seconds();
  if (shown_ && elapsed - last_s_ < 0.2) return;
  last_s_ = elapsed;
  const double rate = elapsed > 0 ? amount / elapsed : 0.0;
  const double eta =
      fraction > 1e-6 ? elapsed * (1.0 - fraction) / fraction : std::numeric_limits<double>::quiet_NaN();
  std::fprintf(stderr, "\r%s: %5.1f %% | %s%s/s | elapsed %s | ETA %s   ", label_.c_str(), 100.0 * fraction,
               human(rate).c_str(), unit_.c_str(), duration(elapsed).c_str(), duration(eta).c_str());
  std::fflush(stderr);
  shown_ = true;
}

void ProgressLine::finish() {
  if (shown_) std::fprintf(stderr, "\n");
  shown_ = false;
}

}  // namespace evio::apps
