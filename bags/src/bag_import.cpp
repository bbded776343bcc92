#include "evio/bags/bag_import.h"

#include <filesystem>
#include <memory>
#include <optional>
#include <rosbag/view.h>

#include "bag_file.h"
#include "evio/core/error.h"
#include "evio/core/io/atomic_file.h"
#include "evio/core/io/calib_txt.h"
#include "evio/core/io/events_h5.h"
#include "evio/core/io/events_txt.h"
#include "evio/core/io/images_txt.h"
#include "evio/core/io/imu_txt.h"
#include "evio/core/io/sensors_yaml.h"
#include "evio/core/io/tum.h"
#include "message_conversion.h"

namespace evio::bags {

namespace {

namespace fs = std::filesystem;
using detail::RosEventArray;

/// The header line groundtruth.txt carries wherever evio writes it.
const char* const kGroundTruthHeader = "pose of the event camera E in the world W (T_W_E); t px py pz qx qy qz qw";

struct TopicType {
  std::string type;
  std::string md5;
};

/// Every topic of the bag with its message type.
std::map<std::string, TopicType> topicsOf(const rosbag::Bag& bag) {
  std::map<std::string, TopicType> out;
  rosbag::View all(bag);
  for (const rosbag::ConnectionInfo* c : all.getConnections()) {
    const auto [it, fresh] = out.try_emplace(c->topic, TopicType{c->datatype, c->md5sum});
    if (!fresh && (it->second.type != c->datatype || it->second.md5 != c->md5sum))
      throw Error(c->topic + ": carries two message types (" + it->second.type + " " + it->second.md5 + " and " +
                  c->datatype + " " + c->md5sum + ")");
  }
  return out;
}

std::string topicsOfType(const std::map<std::string, TopicType>& topics, std::string_view type) {
  std::string list;
  for (const auto& [name, t] : topics)
    if (t.type == type) list += (list.empty() ? "" : ", ") + name;
  return list;
}

/// The topic of each kind: the override, or the bag's only topic of the kind's type.
std::map<TopicKind, std::string> chooseTopics(const std::map<std::string, TopicType>& topics,
                                              const TopicOverrides& overrides) {
  std::map<TopicKind, std::string> chosen;
  for (TopicKind kind : kAllTopicKinds) {
    const std::string_view type = topicKindType(kind);
    const std::string kind_name(topicKindName(kind));
    std::string name;
    if (const auto o = overrides.find(kind); o != overrides.end()) {
      if (o->second.empty()) continue;  // skipped on request
      name = o->second;
      const auto t = topics.find(name);
      if (t == topics.end()) throw Error("--topic " + kind_name + "=" + name + ": no such topic in the bag");
      if (t->second.type != type)
        throw Error("--topic " + kind_name + "=" + name + ": the topic is " + t->second.type + ", " + kind_name +
                    " need " + std::string(type));
    } else if (!chosenByType(kind)) {
      const auto t = topics.find(std::string(defaultTopic(kind)));
      if (t == topics.end() || t->second.type != type) continue;
      name = t->first;
    } else {
      for (const auto& [topic, t] : topics) {
        if (t.type != type) continue;
        if (!name.empty())
          throw Error("several " + std::string(type) + " topics (" + topicsOfType(topics, type) +
                      "): choose one with --topic " + kind_name + "=/name, or skip them with --topic " + kind_name + "=");
        name = topic;
      }
      if (name.empty()) continue;
    }
    const std::string& md5 = topics.at(name).md5;
    if (md5 != topicKindMd5(kind))
      throw Error(name + ": " + std::string(type) + " with MD5 " + md5 + ", not the published definition's " +
                  std::string(topicKindMd5(kind)) + " (a different message layout)");
    chosen[kind] = name;
  }
  return chosen;
}

/// Writes the files of the sequence folder as the messages come; each file
/// is created with its first message.
class SequenceSink {
 public:
  SequenceSink(std::string folder, std::string events_format, BagImportSummary& summary)
      : folder_(std::move(folder)), events_format_(std::move(events_format)), summary_(summary) {}

  void events(const RosEventArray& msg) {
    checkSensorSize(msg.width, msg.height, "EventArray");
    if (!events_ && !events_h5_) openEventWriters();
    chunk_.clear();
    detail::appendEvents(msg, chunk_, last_event_t_ns_);
    if (events_) events_->append(chunk_);
    if (events_h5_) events_h5_->append(chunk_);
    summary_.events += chunk_.size();
    ++summary_.event_messages;
  }

  void frame(const RosImage& msg) {
    const TimeNs t_ns = detail::nsFromRosTime(msg.header.stamp);
    requireIncreasing(t_ns, last_frame_t_ns_, summary_.frames, "frame");
    const cv::Mat grey = detail::greyFromImage(msg);
    if (!frames_) {
      frames_ = std::make_unique<io::ImageFolderWriter>(folder_);
      frame_size_ = grey.size();
      summary_.files.emplace_back("images.txt");
      summary_.files.emplace_back("images/");
    }
    if (grey.size() != frame_size_)
      throw Error("frame of " + std::to_string(grey.cols) + " x " + std::to_string(grey.rows) + " after frames of " +
                  std::to_string(frame_size_.width) + " x " + std::to_string(frame_size_.height));
    frames_->append(t_ns, grey);
    ++summary_.frames;
  }

  void imu(const RosImu& msg) {
    const ImuSample s = detail::imuFromRos(msg);
    requireIncreasing(s.t_ns, last_imu_t_ns_, summary_.imu_samples, "IMU sample");
    if (!imu_) imu_ = std::make_unique<io::ImuTextWriter>(file("imu.txt"));
    imu_->append(s);
    ++summary_.imu_samples;
  }

  void pose(const RosPoseStamped& msg) {
    const StampedPose p = detail::poseFromRos(msg);
    requireIncreasing(p.t_ns, last_pose_t_ns_, summary_.groundtruth_poses, "pose");
    if (!poses_) poses_ = std::make_unique<io::TumWriter>(file("groundtruth.txt"), std::vector<std::string>{kGroundTruthHeader});
    poses_->append(p);
    ++summary_.groundtruth_poses;
  }

  /// The first CameraInfo becomes calib.txt; later ones only count.
  void cameraInfo(const RosCameraInfo& msg) {
    if (summary_.camera_infos++ > 0) return;
    checkSensorSize(msg.width, msg.height, "CameraInfo");
    io::writeCalibTxt(file("calib.txt"), detail::calibFromCameraInfo(msg));
  }

  /// The first message becomes sensors.yaml, after it parses as one.
  void sensors(const RosString& msg, const std::string& name) {
    if (sensors_written_) return;
    io::parseSensorsYaml(msg.data, name);
    io::writeFileAtomic(file("sensors.yaml"), msg.data);
    sensors_written_ = true;
  }

  void close() {
    if (events_) events_->close();
    if (events_h5_) events_h5_->close();
    if (frames_) frames_->close();
    if (imu_) imu_->close();
    if (poses_) poses_->close();
  }

 private:
  std::string file(const char* name) {
    summary_.files.emplace_back(name);
    return (fs::path(folder_) / name).string();
  }

  /// events.txt and/or events.h5; the latter with the sensor size known so far
  /// (from the first EventArray, or a CameraInfo before it) as attributes.
  void openEventWriters() {
    if (events_format_ != "h5") events_ = std::make_unique<io::EventTextWriter>(file("events.txt"));
    if (events_format_ != "txt") {
      io::EventH5Options h5;
      h5.width = summary_.width;
      h5.height = summary_.height;
      events_h5_ = std::make_unique<io::EventH5Writer>(file("events.h5"), h5);
    }
  }

  /// Sensor sizes of EventArray and CameraInfo must agree (0 = not given).
  void checkSensorSize(std::uint32_t width, std::uint32_t height, const char* source) {
    if (width == 0 && height == 0) return;
    if (summary_.width == 0) {
      summary_.width = static_cast<int>(width);
      summary_.height = static_cast<int>(height);
      size_source_ = source;
    } else if (static_cast<int>(width) != summary_.width || static_cast<int>(height) != summary_.height) {
      throw Error(std::string(source) + " sensor size " + std::to_string(width) + " x " + std::to_string(height) +
                  " differs from " + size_source_ + "'s " + std::to_string(summary_.width) + " x " +
                  std::to_string(summary_.height));
    }
  }

  static void requireIncreasing(TimeNs t_ns, TimeNs& last_t_ns, std::uint64_t count, const char* what) {
    if (count > 0 && t_ns <= last_t_ns)
      throw Error(std::string(what) + " time " + secondsText(t_ns, 9) + " is not after the previous one, " +
                  secondsText(last_t_ns, 9) + " (unsorted)");
    last_t_ns = t_ns;
  }

  std::string folder_;
  std::string events_format_;
  BagImportSummary& summary_;
  std::unique_ptr<io::EventTextWriter> events_;
  std::unique_ptr<io::EventH5Writer> events_h5_;
  std::unique_ptr<io::ImageFolderWriter> frames_;
  std::unique_ptr<io::ImuTextWriter> imu_;
  std::unique_ptr<io::TumWriter> poses_;
  bool sensors_written_ = false;
  EventArray chunk_;
  TimeNs last_event_t_ns_ = 0;
  TimeNs last_frame_t_ns_ = 0, last_imu_t_ns_ = 0, last_pose_t_ns_ = 0;
  cv::Size frame_size_;
  std::string size_source_;
};

/// An instance as message type M; throws when it does not deserialise.
template <class M>
boost::shared_ptr<M> instantiate(const rosbag::MessageInstance& m) {
  auto msg = m.instantiate<M>();
  if (!msg) throw Error("the message is not a " + std::string(ros::message_traits::DataType<M>::value()));
  return msg;
}

void dispatch(TopicKind kind, const rosbag::MessageInstance& m, SequenceSink& sink, const std::string& name) {
  switch (kind) {
    case TopicKind::kEvents: sink.events(*instantiate<RosEventArray>(m)); break;
    case TopicKind::kFrames: sink.frame(*instantiate<RosImage>(m)); break;
    case TopicKind::kImu: sink.imu(*instantiate<RosImu>(m)); break;
    case TopicKind::kGroundTruth: sink.pose(*instantiate<RosPoseStamped>(m)); break;
    case TopicKind::kCameraInfo: sink.cameraInfo(*instantiate<RosCameraInfo>(m)); break;
    case TopicKind::kSensors: sink.sensors(*instantiate<RosString>(m), name); break;
  }
}

}  // namespace

void BagImportOptions::validate() const {
  if (events_format != "txt" && events_format != "h5" && events_format != "both")
    throw Error("events_format (--events): '" + events_format + "' is not txt, h5 or both");
}

BagImportSummary importBag(const std::string& bag_path, const std::string& folder, const BagImportOptions& options) {
  options.validate();
  rosbag::Bag bag;
  detail::openForReading(bag, bag_path);
  BagImportSummary summary;
  std::string where = "listing the topics";
  try {
    summary.topics = chooseTopics(topicsOf(bag), options.topics);
    if (summary.topics.empty())
      throw Error("no topic of a type evio reads (dvs_msgs/EventArray, sensor_msgs/Image, sensor_msgs/Imu, "
                  "geometry_msgs/PoseStamped, sensor_msgs/CameraInfo)");
    std::map<std::string, TopicKind> kind_of;
    std::vector<std::string> names;
    for (const auto& [kind, name] : summary.topics) {
      kind_of[name] = kind;
      names.push_back(name);
    }
    SequenceSink sink(folder, options.events_format, summary);
    std::map<std::string, std::uint64_t> index;
    where = "reading the first message";
    rosbag::View view(bag, rosbag::TopicQuery(names));
    for (const rosbag::MessageInstance& m : view) {
      const std::string& topic = m.getTopic();
      where = topic + " message " + std::to_string(index[topic]++);
      dispatch(kind_of.at(topic), m, sink, bag_path + ":" + where);
      where = "the message after " + where;
    }
    where = "closing the output";
    sink.close();
  } catch (...) {
    detail::rethrowAsError(bag_path, where);
  }
  return summary;
}

}  // namespace evio::bags
