#pragma once
/// @file event.h
/// Events and the structure-of-arrays container that holds many of them.

#include <cstddef>
#include <cstdint>
#include <vector>

#include "evio/core/time.h"

namespace evio {

/// One event: pixel (x right, y down, origin at the top-left pixel centre),
/// time, polarity (+1 brighter / -1 darker, stored 1 / 0 in files).
struct Event {
  TimeNs t_ns = 0;
  std::uint16_t x = 0;
  std::uint16_t y = 0;
  bool positive = false;

  friend bool operator==(const Event&, const Event&) = default;
};

/// Events stored structure-of-arrays: 8 (t) + 2 (x) + 2 (y) + 1 (p) = 13 bytes
/// per event, so 10^8 events fit in 1.3 GB. Time is non-decreasing by contract
/// of the readers and of the simulator (not enforced on push_back).
class EventArray {
 public:
  std::size_t size() const { return t_ns_.size(); }
  bool empty() const { return t_ns_.empty(); }
  void clear();
  void reserve(std::size_t n);

  void push_back(const Event& e) { push_back(e.t_ns, e.x, e.y, e.positive); }
  void push_back(TimeNs t_ns, std::uint16_t x, std::uint16_t y, bool positive) {
    t_ns_.push_back(t_ns);
    x_.push_back(x);
    y_.push_back(y);
    p_.push_back(positive ? 1 : 0);
  }

  Event operator[](std::size_t i) const { return Event{t_ns_[i], x_[i], y_[i], p_[i] != 0}; }

  /// Appends all events of `other`.
  void append(const EventArray& other);

  /// Keeps only the events with index in [begin, end).
  void keepRange(std::size_t begin, std::size_t end);

  const std::vector<TimeNs>& t() const { return t_ns_; }
  const std::vector<std::uint16_t>& x() const { return x_; }
  const std::vector<std::uint16_t>& y() const { return y_; }
  /// Polarity: 1 positive, 0 negative.
  const std::vector<std::uint8_t>& p() const { return p_; }

  std::vector<TimeNs>& t() { return t_ns_; }
  std::vector<std::uint16_t>& x() { return x_; }
  std::vector<std::uint16_t>& y() { return y_; }
  std::vector<std::uint8_t>& p() { return p_; }

  /// Resizes all four columns.
  void resize(std::size_t n);

  /// Index of the first event with t >= t_ns (binary search; requires sorted time).
  std::size_t lowerBound(TimeNs t_ns) const;

  friend bool operator==(const EventArray&, const EventArray&) = default;

 private:
  std::vector<TimeNs> t_ns_;
  std::vector<std::uint16_t> x_;
  std::vector<std::uint16_t> y_;
  std::vector<std::uint8_t> p_;
};

}  // namespace evio
