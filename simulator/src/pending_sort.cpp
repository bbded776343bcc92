#include "pending_sort.h"

#include <algorithm>
#include <bit>

namespace evio::simulator {

namespace {

bool pendingLess(const EventCamera::Pending& a, const EventCamera::Pending& b) {
  if (a.t_ns != b.t_ns) return a.t_ns < b.t_ns;
  if (a.pixel != b.pixel) return a.pixel < b.pixel;
  if (a.label != b.label) return a.label < b.label;
  return a.positive < b.positive;
}

}  // namespace

void sortPending(std::vector<EventCamera::Pending>::iterator begin, std::vector<EventCamera::Pending>::iterator end,
                 std::size_t pixel_count, std::vector<std::uint64_t>* keys, std::vector<std::uint64_t>* scratch) {
  const auto count = static_cast<std::size_t>(end - begin);
  if (count < 2) return;
  TimeNs t_min = begin->t_ns, t_max = begin->t_ns;
  for (auto it = begin; it != end; ++it) {
    t_min = std::min(t_min, it->t_ns);
    t_max = std::max(t_max, it->t_ns);
  }
  const int pixel_bits = std::bit_width(static_cast<std::uint64_t>(pixel_count - 1));
  const int time_bits = std::bit_width(static_cast<std::uint64_t>(t_max - t_min));
  const int low_bits = pixel_bits + 3;  // pixel, label (2 bits), polarity (1 bit)
  if (count < 64 || time_bits + low_bits > 64) {
    std::sort(begin, end, pendingLess);
    return;
  }
  keys->resize(count);
  scratch->resize(count);
  std::size_t j = 0;
  for (auto it = begin; it != end; ++it, ++j)
    (*keys)[j] = (static_cast<std::uint64_t>(it->t_ns - t_min) << low_bits) |
                 (static_cast<std::uint64_t>(it->pixel) << 3) | (static_cast<std::uint64_t>(it->label) << 1) |
                 static_cast<std::uint64_t>(it->positive);
  const int passes = (time_bits + low_bits + 7) / 8;
  for (int pass = 0; pass < passes; ++pass) {
    const int shift = 8 * pass;
    std::size_t histogram[257] = {};
    for (const std::uint64_t k : *keys) ++histogram[((k >> shift) & 0xFF) + 1];
    for (int d = 0; d < 256; ++d) histogram[d + 1] += histogram[d];
    for (const std::uint64_t k : *keys) (*scratch)[histogram[(k >> shift) & 0xFF]++] = k;
    keys->swap(*scratch);
  }
  const std::uint64_t pixel_mask = (std::uint64_t{1} << pixel_bits) - 1;
  j = 0;
  for (auto it = begin; it != end; ++it, ++j) {
    const std::uint64_t k = (*keys)[j];
    it->t_ns = t_min + static_cast<TimeNs>(k >> low_bits);
    it->pixel = static_cast<std::uint32_t>((k >> 3) & pixel_mask);
    it->label = static_cast<EventLabel>((k >> 1) & 3);
    it->positive = static_cast<std::uint8_t>(k & 1);
  }
}

}  // namespace evio::simulator
