#pragma once
/// @file export_sources.h
/// The streams of a sequence folder, each turned into ROS messages one at a
/// time, for bag_export.cpp's merge by record time. Each source holds one
/// pending message (an EventArray holds at most one window of events).

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <rosbag/bag.h>

#include "evio/core/event.h"
#include "evio/core/io/events_h5.h"
#include "evio/core/io/events_txt.h"
#include "evio/core/io/images_txt.h"
#include "evio/core/io/imu_txt.h"
#include "evio/core/io/tum.h"
#include "message_conversion.h"

namespace evio::bags::detail {

/// One stream: `empty()`, else the pending message's stamp `time()`; `write()`
/// writes it to the bag (recorded at its stamp, at least 1 ns) and loads the next.
class ExportSource {
 public:
  explicit ExportSource(std::string topic) : topic_(std::move(topic)) {}
  virtual ~ExportSource() = default;
  virtual bool empty() const = 0;
  virtual TimeNs time() const = 0;
  virtual void write(rosbag::Bag& bag) = 0;
  const std::string& topic() const { return topic_; }
  std::uint64_t written() const { return written_; }

 protected:
  /// ROS 1 cannot record a message at time 0 (ros::TIME_MIN is 1 ns).
  static ros::Time recordTime(TimeNs t_ns) { return rosTimeFromNs(std::max<TimeNs>(t_ns, 1)); }
  std::string topic_;
  std::uint64_t written_ = 0;
};

/// Events of events.txt or events.h5, cut into EventArray messages.
class EventSource : public ExportSource {
 public:
  EventSource(std::string topic, const std::string& folder, int width, int height, TimeNs window_ns,
              std::uint64_t max_per_message, std::string frame_id);
  bool empty() const override { return pending_.events.empty(); }
  TimeNs time() const override { return pending_time_; }
  void write(rosbag::Bag& bag) override;
  std::uint64_t events() const { return events_; }

 private:
  bool refill();
  void load();

  std::unique_ptr<io::EventTextReader> txt_;
  std::unique_ptr<io::EventH5Reader> h5_;
  EventArray chunk_;
  std::size_t next_ = 0;
  TimeNs window_ns_;
  std::uint64_t max_per_message_;
  RosEventArray pending_;
  TimeNs pending_time_ = 0;
  std::uint64_t events_ = 0;
};

/// Frames of images.txt, loaded one at a time.
class FrameSource : public ExportSource {
 public:
  FrameSource(std::string topic, std::string folder, std::string frame_id);
  bool empty() const override { return next_ >= stamps_.size(); }
  TimeNs time() const override { return stamps_[next_].t_ns; }
  void write(rosbag::Bag& bag) override;

 private:
  std::string folder_, frame_id_;
  std::vector<io::ImageStamp> stamps_;  ///< the list only (tens of bytes per frame)
  std::size_t next_ = 0;
  cv::Size size_;
};

class ImuSource : public ExportSource {
 public:
  ImuSource(std::string topic, const std::string& path, std::string frame_id);
  bool empty() const override { return !has_; }
  TimeNs time() const override { return sample_.t_ns; }
  void write(rosbag::Bag& bag) override;

 private:
  io::ImuTextReader reader_;
  ImuSample sample_;
  bool has_ = false;
  std::string frame_id_;
};

class PoseSource : public ExportSource {
 public:
  PoseSource(std::string topic, const std::string& path, std::string frame_id);
  bool empty() const override { return !has_; }
  TimeNs time() const override { return pose_.t_ns; }
  void write(rosbag::Bag& bag) override;

 private:
  io::TumReader reader_;
  StampedPose pose_;
  bool has_ = false;
  std::string frame_id_;
};

}  // namespace evio::bags::detail
