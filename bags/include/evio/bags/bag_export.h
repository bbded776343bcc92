#pragma once
/// @file bag_export.h
/// `evio export <sequence> --format rosbag -o x.bag`: a sequence folder as a
/// ROS 1 bag that rosbag, rpg_dvs_ros tools and `evio import` read:
///
///   /dvs/camera_info    sensor_msgs/CameraInfo  one message: calib.txt (else the
///                                               event camera of sensors.yaml) at the sensor size
///   /evio/sensors_yaml  std_msgs/String         one message: sensors.yaml verbatim (when present)
///   /dvs/events         dvs_msgs/EventArray     consecutive events: a message spans less
///                                               than `event_window_s` from its first event
///                                               and holds at most `max_events_per_message`
///   /dvs/image_raw      sensor_msgs/Image       each frame, mono8
///   /dvs/imu            sensor_msgs/Imu         each sample (no orientation)
///   /groundtruth/pose   geometry_msgs/PoseStamped  each ground-truth pose (T_W_E)
///
/// Events come from events.txt when present (nanoseconds), else events.h5
/// (microseconds). Header stamps are the data's own times; an EventArray is
/// stamped with its last event. The bag records each message at its stamp
/// (ROS 1 cannot record at 0: a stamp of 0 is recorded at 1 ns), and the
/// messages are written in record-time order (a k-way merge of the streamed
/// files, ties in the order of the table above), so players and readers
/// walk the bag forward. The bag is written under a temporary name and
/// renamed when complete. truth/, range.txt and scenario.yaml are not exported.

#include <cstdint>
#include <string>

#include "evio/bags/bag_topics.h"

namespace evio::bags {

struct BagExportOptions {
  /// Chunk compression: "none", "bz2" or "lz4".
  std::string compression = "none";
  /// An EventArray message holds events with t - t_first < event_window_s; s, in [1e-6, 1].
  double event_window_s = 0.001;
  /// Most events in one EventArray message; in [1, 10^7].
  std::uint64_t max_events_per_message = 100'000;
  /// kind → topic name (an empty name leaves the kind out).
  TopicOverrides topics;

  /// Throws evio::Error naming the option.
  void validate() const;
};

struct BagExportSummary {
  std::uint64_t events = 0;
  std::uint64_t event_messages = 0;
  std::uint64_t frames = 0;
  std::uint64_t imu_samples = 0;
  std::uint64_t groundtruth_poses = 0;
  bool camera_info = false;
  bool sensors_yaml = false;
  int width = 0, height = 0;  ///< sensor size written to CameraInfo and EventArray (0: unknown)
};

/// Writes the bag `bag` (replaced atomically) from the sequence folder `sequence`.
BagExportSummary exportBag(const std::string& sequence, const std::string& bag, const BagExportOptions& options = {});

}  // namespace evio::bags
