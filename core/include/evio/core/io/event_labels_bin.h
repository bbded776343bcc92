#pragma once
/// @file event_labels_bin.h
/// `truth/event_labels.bin`: one label byte per event of the sequence, in
/// the order of events.h5 / events.txt (the simulator's signal/noise truth).
///
/// Layout (little-endian):
///   bytes 0..7    magic "EVIOLBL1"
///   bytes 8..15   uint64 count: number of labels (= number of events)
///   bytes 16..    count bytes, one label each
/// Label values (simulator/event_camera.h, EventLabel): 0 signal, 1 leak
/// noise, 2 shot noise, 3 hot pixel; other values are rejected on reading.
///
/// Reading it elsewhere, e.g. numpy:
///   raw = open(p, 'rb').read(); n = int.from_bytes(raw[8:16], 'little')
///   labels = numpy.frombuffer(raw, numpy.uint8, n, 16)
///
/// The writer streams (memory flat in the sequence length) and writes the
/// count into the header on close(); the file appears under its name only
/// then (atomic_file.h).

#include <cstdint>
#include <string>
#include <vector>

#include "evio/core/io/atomic_file.h"

namespace evio::io {

/// Largest label value accepted (3: hot pixel).
constexpr std::uint8_t kMaxEventLabel = 3;

class EventLabelWriter {
 public:
  explicit EventLabelWriter(std::string path);
  ~EventLabelWriter();
  EventLabelWriter(const EventLabelWriter&) = delete;
  EventLabelWriter& operator=(const EventLabelWriter&) = delete;

  /// Appends `count` labels; throws Error for a value above kMaxEventLabel.
  void append(const std::uint8_t* labels, std::size_t count);
  /// Writes the header and renames the file onto its path.
  void close();
  std::uint64_t size() const { return count_; }

 private:
  std::string path_;
  std::string tmp_path_;
  std::FILE* file_ = nullptr;
  std::uint64_t count_ = 0;
  bool closed_ = false;
};

/// Reads every label; throws Error naming the file for a wrong magic, a
/// truncated or over-long file, or a label value above kMaxEventLabel.
std::vector<std::uint8_t> readEventLabels(const std::string& path);

/// Writes all labels at once, atomically.
void writeEventLabels(const std::string& path, const std::vector<std::uint8_t>& labels);

}  // namespace evio::io
