#include "evio/core/event.h"

#include <algorithm>

namespace evio {

void EventArray::clear() {
  t_ns_.clear();
  x_.clear();
  y_.clear();
  p_.clear();
}

void EventArray::reserve(std::size_t n) {
  t_ns_.reserve(n);
  x_.reserve(n);
  y_.reserve(n);
  p_.reserve(n);
}

void EventArray::resize(std::size_t n) {
  t_ns_.resize(n);
  x_.resize(n);
  y_.resize(n);
  p_.resize(n);
}

void EventArray::append(const EventArray& other) {
  t_ns_.insert(t_ns_.end(), other.t_ns_.begin(), other.t_ns_.end());
  x_.insert(x_.end(), other.x_.begin(), other.x_.end());
  y_.insert(y_.end(), other.y_.begin(), other.y_.end());
  p_.insert(p_.end(), other.p_.begin(), other.p_.end());
}

void EventArray::keepRange(std::size_t begin, std::size_t end) {
  end = std::min(end, size());
  begin = std::min(begin, end);
  auto keep = [&](auto& v) {
    v.erase(v.begin() + static_cast<std::ptrdiff_t>(end), v.end());
    v.erase(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(begin));
  };
  keep(t_ns_);
  keep(x_);
  keep(y_);
  keep(p_);
}

std::size_t EventArray::lowerBound(TimeNs t_ns) const {
  return static_cast<std::size_t>(std::lower_bound(t_ns_.begin(), t_ns_.end(), t_ns) - t_ns_.begin());
}

}  // namespace evio
