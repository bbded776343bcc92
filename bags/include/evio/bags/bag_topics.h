#pragma once
/// @file bag_topics.h
/// What a sequence folder holds, as kinds of ROS 1 topics. `evio import`
/// picks each kind's topic by its message type; `--topic kind=/name`
/// names it instead (an empty name skips the kind). `evio export` writes
/// each kind under its default name unless `--topic` renames it.

#include <array>
#include <map>
#include <string>
#include <string_view>
#include <vector>

namespace evio::bags {

/// The kinds of data a bag can carry for a sequence folder.
enum class TopicKind { kEvents, kFrames, kImu, kGroundTruth, kCameraInfo, kSensors };

inline constexpr std::array<TopicKind, 6> kAllTopicKinds = {TopicKind::kEvents,      TopicKind::kFrames,
                                                            TopicKind::kImu,         TopicKind::kGroundTruth,
                                                            TopicKind::kCameraInfo,  TopicKind::kSensors};

/// "events", "frames", "imu", "groundtruth", "camera_info", "sensors".
std::string_view topicKindName(TopicKind kind);

/// The ROS message type of a kind: dvs_msgs/EventArray, sensor_msgs/Image,
/// sensor_msgs/Imu, geometry_msgs/PoseStamped, sensor_msgs/CameraInfo,
/// std_msgs/String (sensors.yaml as text).
std::string_view topicKindType(TopicKind kind);

/// The MD5 sum of that type's definition.
std::string_view topicKindMd5(TopicKind kind);

/// The topic `evio export` writes a kind to (rpg_dvs_ros names for the
/// camera and IMU): /dvs/events, /dvs/image_raw, /dvs/imu, /groundtruth/pose,
/// /dvs/camera_info, /evio/sensors_yaml.
std::string_view defaultTopic(TopicKind kind);

/// Whether import may choose the kind's topic by type alone. Not for
/// `sensors`: std_msgs/String carries any text, so only its default topic
/// (or an override) is read.
bool chosenByType(TopicKind kind);

/// Topic overrides, kind → name ("" = skip the kind).
using TopicOverrides = std::map<TopicKind, std::string>;

/// Parses `--topic` values "kind=/name" (or "kind=" to skip). Throws
/// evio::Error naming the value for an unknown kind, a missing '=', a name
/// that does not start with '/', or a kind given twice.
TopicOverrides parseTopicOverrides(const std::vector<std::string>& values);

}  // namespace evio::bags
