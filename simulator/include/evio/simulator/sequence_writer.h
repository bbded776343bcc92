#pragma once
/// @file sequence_writer.h
/// The streaming half of a sequence folder, fed by the render loop in time
/// order with memory flat in the sequence length:
///   events.h5                 every event (DSEC layout, t_offset = the sequence start)
///   events.txt                the same as text (optional)
///   truth/event_labels.bin    one label per event, same order (core/io/event_labels_bin.h)
///   images.txt, images/       8-bit frames
///   truth/depth.txt, truth/depth/depth_XXXXXXXX.exr
///                             event-camera depth (channel Z, m along the optical
///                             axis, +inf: no surface) at frame stamps, optionally with
///                             the motion field (channels U, V, px/s); index XXXXXXXX
///                             = the frame's index in images/; depth.txt lists
///                             `t depth/depth_XXXXXXXX.exr` like images.txt
/// Each file appears under its name only when complete (close()).

#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "evio/core/event.h"
#include "evio/core/io/event_labels_bin.h"
#include "evio/core/io/events_h5.h"
#include "evio/core/io/events_txt.h"
#include "evio/core/io/images_txt.h"
#include "evio/simulator/event_camera.h"
#include "evio/core/slot_ring_thread.h"

namespace evio::simulator {

struct SequenceWriterOptions {
  int width = 0, height = 0;      ///< event sensor size, px
  TimeNs t_offset_ns = 0;         ///< events.h5 /t_offset (floored to µs)
  bool events_txt = true;
  int events_h5_compression = 0;
  bool frames = true;
  bool depth = true;
};

class SequenceWriter {
 public:
  /// Creates `folder` (and truth/, truth/depth/) when missing.
  SequenceWriter(const std::string& folder, const SequenceWriterOptions& options);

  /// Events (time-sorted, after every earlier one) with one label each.
  void appendEvents(const EventArray& events, const std::vector<EventLabel>& labels);
  /// A frame stamped t_ns (CV_8UC1); returns its index.
  std::size_t appendFrame(TimeNs t_ns, const cv::Mat& image);
  /// Depth (CV_32FC1) at t_ns, named after frame `index`; with a non-empty
  /// `flow` (CV_32FC2, px/s) also its channels U and V.
  void appendDepth(std::size_t index, TimeNs t_ns, const cv::Mat& depth, const cv::Mat& flow = cv::Mat());
  /// Closes every file; returns the paths written.
  std::vector<std::string> close();

  std::uint64_t eventCount() const { return events_; }
  std::uint64_t frameCount() const { return frames_; }
  std::uint64_t depthCount() const { return depths_; }

 private:
  std::string folder_;
  SequenceWriterOptions options_;
  std::unique_ptr<io::EventH5Writer> h5_;
  std::unique_ptr<io::EventTextWriter> txt_;
  std::unique_ptr<io::EventLabelWriter> labels_;
  std::unique_ptr<io::ImageFolderWriter> images_;
  std::string depth_list_;
  std::vector<std::string> files_;
  std::vector<std::uint8_t> label_bytes_;
  std::uint64_t events_ = 0, frames_ = 0, depths_ = 0;
};

/// A SequenceWriter on a thread of its own (core/slot_ring_thread.h): the same calls
/// write the same files, but an append only copies its data into one of
/// `queue_slots` reusable slots (waiting while all are queued) and returns,
/// so the files are written while the caller renders. The arguments are
/// checked at once; an error of the writing itself surfaces at a later
/// append or at close(), and the files are then not completed (as when
/// SequenceWriter throws). Appends may come from several threads; each
/// file's data must come from one thread (events from one, frames from one).
class AsyncSequenceWriter {
 public:
  AsyncSequenceWriter(const std::string& folder, const SequenceWriterOptions& options, std::size_t queue_slots = 16);

  void appendEvents(const EventArray& events, const std::vector<EventLabel>& labels);
  std::size_t appendFrame(TimeNs t_ns, const cv::Mat& image);
  void appendDepth(std::size_t index, TimeNs t_ns, const cv::Mat& depth, const cv::Mat& flow = cv::Mat());
  /// Waits for the queued writes, then closes every file (SequenceWriter::close).
  std::vector<std::string> close();

  std::uint64_t eventCount() const { return events_.load(std::memory_order_relaxed); }
  std::uint64_t frameCount() const { return frames_.load(std::memory_order_relaxed); }
  std::uint64_t depthCount() const { return depths_.load(std::memory_order_relaxed); }

 private:
  /// One queued write; its buffers are reused by later writes.
  struct Job {
    enum class Kind { kEvents, kFrame, kDepth } kind = Kind::kEvents;
    EventArray events;
    std::vector<EventLabel> labels;
    TimeNs t_ns = 0;
    std::size_t index = 0;
    cv::Mat image, depth, flow;  ///< kFrame: image; kDepth: depth, flow (empty: none)
  };
  void write(Job& job);

  SequenceWriterOptions options_;
  SequenceWriter writer_;      // used by the thread only, until close()
  SlotRingThread<Job> thread_;  // declared after writer_: joined before it is destroyed; drops queued jobs
  std::atomic<std::uint64_t> events_{0}, frames_{0}, depths_{0};
};

}  // namespace evio::simulator
