#include "evio/bags/bag_topics.h"

#include <ros/message_traits.h>

#include "evio/bags/ros/dvs_msgs.h"
#include "evio/bags/ros/ros_messages.h"
#include "evio/core/error.h"

namespace evio::bags {

namespace {

struct KindInfo {
  TopicKind kind;
  const char* name;
  const char* topic;
};

constexpr std::array<KindInfo, 6> kKinds = {{
    {TopicKind::kEvents, "events", "/dvs/events"},
    {TopicKind::kFrames, "frames", "/dvs/image_raw"},
    {TopicKind::kImu, "imu", "/dvs/imu"},
    {TopicKind::kGroundTruth, "groundtruth", "/groundtruth/pose"},
    {TopicKind::kCameraInfo, "camera_info", "/dvs/camera_info"},
    {TopicKind::kSensors, "sensors", "/evio/sensors_yaml"},
}};

const KindInfo& info(TopicKind kind) { return kKinds[static_cast<std::size_t>(kind)]; }

template <class M>
std::string_view typeOf() {
  return ros::message_traits::DataType<M>::value();
}
template <class M>
std::string_view md5Of() {
  return ros::message_traits::MD5Sum<M>::value();
}

std::string kindList() {
  std::string out;
  for (const auto& k : kKinds) out += (out.empty() ? "" : ", ") + std::string(k.name);
  return out;
}

}  // namespace

std::string_view topicKindName(TopicKind kind) { return info(kind).name; }

std::string_view topicKindType(TopicKind kind) {
  switch (kind) {
    case TopicKind::kEvents: return typeOf<dvs_msgs::EventArray_<RosAllocator<void>>>();
    case TopicKind::kFrames: return typeOf<RosImage>();
    case TopicKind::kImu: return typeOf<RosImu>();
    case TopicKind::kGroundTruth: return typeOf<RosPoseStamped>();
    case TopicKind::kCameraInfo: return typeOf<RosCameraInfo>();
    case TopicKind::kSensors: return typeOf<RosString>();
  }
  return {};
}

std::string_view topicKindMd5(TopicKind kind) {
  switch (kind) {
    case TopicKind::kEvents: return md5Of<dvs_msgs::EventArray_<RosAllocator<void>>>();
    case TopicKind::kFrames: return md5Of<RosImage>();
    case TopicKind::kImu: return md5Of<RosImu>();
    case TopicKind::kGroundTruth: return md5Of<RosPoseStamped>();
    case TopicKind::kCameraInfo: return md5Of<RosCameraInfo>();
    case TopicKind::kSensors: return md5Of<RosString>();
  }
  return {};
}

std::string_view defaultTopic(TopicKind kind) { return info(kind).topic; }

bool chosenByType(TopicKind kind) { return kind != TopicKind::kSensors; }

TopicOverrides parseTopicOverrides(const std::vector<std::string>& values) {
  TopicOverrides out;
  for (const std::string& value : values) {
    const auto eq = value.find('=');
    if (eq == std::string::npos)
      throw Error("--topic " + value + ": expected kind=/name (kinds: " + kindList() + ")");
    const std::string kind_name = value.substr(0, eq);
    const std::string topic = value.substr(eq + 1);
    const KindInfo* found = nullptr;
    for (const auto& k : kKinds)
      if (kind_name == k.name) found = &k;
    if (!found) throw Error("--topic " + value + ": unknown kind '" + kind_name + "' (kinds: " + kindList() + ")");
    if (!topic.empty() && topic.front() != '/')
      throw Error("--topic " + value + ": a topic name starts with '/'");
    if (!out.emplace(found->kind, topic).second) throw Error("--topic " + value + ": " + kind_name + " given twice");
  }
  return out;
}

}  // namespace evio::bags
