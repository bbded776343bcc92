#pragma once
/// @file bag_import.h
/// `evio import <bag> -o <folder>`: a ROS 1 bag (uncompressed, bz2 or lz4)
/// into a sequence folder (docs/architecture.md#the-sequence-folder):
///
///   dvs_msgs/EventArray      → events.txt (t in s with 9 decimals: the
///                              bag's nanoseconds exactly) and/or events.h5
///                              (µs, with the sensor size; `events_format`)
///   sensor_msgs/Image        → images.txt, images/frame_XXXXXXXX.png (8-bit grey)
///   sensor_msgs/Imu          → imu.txt (specific force, angular rate; frame of the message)
///   geometry_msgs/PoseStamped→ groundtruth.txt (TUM; taken as T_W_E)
///   sensor_msgs/CameraInfo   → calib.txt (plumb_bob; the first message)
///   std_msgs/String on /evio/sensors_yaml → sensors.yaml (as written by `evio export`)
///
/// Each kind's topic is the bag's only topic of that type (bag_topics.h),
/// or the one named by an override. Every stamp is the message's own
/// (header stamp, event ts), never the time the bag recorded the message.
/// Messages are read one at a time in the bag's order (librosbag keeps the
/// bag's index, tens of bytes per message, in memory; nothing else grows
/// with the bag).
///
/// Errors (evio::Error "<bag>: <topic> message <i>: ..."): a bag that is
/// not one, truncated, or with a corrupt compressed chunk; a topic override
/// that names a missing topic or a topic of another type; a type whose MD5
/// differs from the published definition; two topics of one type without an
/// override; times going back within a topic; events outside the sensor;
/// image encodings other than 8-bit; frames changing size; camera info that
/// calib.txt cannot hold.

#include <cstdint>
#include <string>
#include <vector>

#include "evio/bags/bag_topics.h"

namespace evio::bags {

struct BagImportOptions {
  TopicOverrides topics;  ///< kind → topic name ("" skips the kind)
  /// Events file(s) to write: "txt" (events.txt, exact ns), "h5" (events.h5,
  /// µs floored, with the sensor size as attributes; read faster and
  /// preferred by the readers) or "both".
  std::string events_format = "txt";

  /// Throws evio::Error naming the option.
  void validate() const;
};

/// What was imported.
struct BagImportSummary {
  std::map<TopicKind, std::string> topics;  ///< the topic read for each kind found
  std::uint64_t events = 0;
  std::uint64_t event_messages = 0;
  std::uint64_t frames = 0;
  std::uint64_t imu_samples = 0;
  std::uint64_t groundtruth_poses = 0;
  std::uint64_t camera_infos = 0;
  int width = 0, height = 0;  ///< sensor size from EventArray or CameraInfo; 0 unknown
  std::vector<std::string> files;  ///< files written, relative to the folder
};

/// Imports `bag` into `folder` (which must exist; the caller stages it,
/// core/io/staged_folder.h).
BagImportSummary importBag(const std::string& bag, const std::string& folder, const BagImportOptions& options = {});

}  // namespace evio::bags
