#include "evio/estimator/frontend/event_prefilter.h"

#include <limits>
#include <string>

#include "evio/core/error.h"

namespace evio::estimator {

EventPrefilter::EventPrefilter(const EventPrefilterOptions& options, int width, int height)
    : options_(options),
      width_(width),
      height_(height),
      refractory_ns_(secondsToNs(options.refractory_period_s)),
      random_(options.random_seed, "event_prefilter") {
  options_.validate();
  require(width > 0 && height > 0, "EventPrefilter: sensor size must be > 0");
  if (refractory_ns_ > 0)
    last_kept_ns_.assign(static_cast<std::size_t>(width) * static_cast<std::size_t>(height),
                         std::numeric_limits<TimeNs>::min() / 2);
}

void EventPrefilter::filter(const EventArray& in, std::size_t begin, std::size_t end, EventArray* out) {
  out->clear();
  const auto& t = in.t();
  const auto& x = in.x();
  const auto& y = in.y();
  const auto& p = in.p();
  const bool rf = options_.random_keep_one_in > 1;
  const double keep_probability = 1.0 / options_.random_keep_one_in;
  for (std::size_t i = begin; i < end; ++i) {
    ++seen_;
    if (x[i] >= width_ || y[i] >= height_)
      throw Error("EventPrefilter: event at (" + std::to_string(x[i]) + ", " + std::to_string(y[i]) +
                  ") outside the " + std::to_string(width_) + "x" + std::to_string(height_) + " sensor");
    if (rf && !random_.bernoulli(keep_probability)) continue;
    if (refractory_ns_ > 0) {
      TimeNs& last = last_kept_ns_[static_cast<std::size_t>(y[i]) * static_cast<std::size_t>(width_) + x[i]];
      if (t[i] - last < refractory_ns_) continue;
      last = t[i];
    }
    out->push_back(t[i], x[i], y[i], p[i] != 0);
    ++kept_;
  }
}

}  // namespace evio::estimator
