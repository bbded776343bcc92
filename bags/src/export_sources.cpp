#include "export_sources.h"

#include <filesystem>

#include "evio/core/error.h"

namespace evio::bags::detail {

namespace fs = std::filesystem;

namespace {
/// Events read from the file at once.
constexpr std::size_t kReadChunk = 1u << 16;
}  // namespace

EventSource::EventSource(std::string topic, const std::string& folder, int width, int height, TimeNs window_ns,
                         std::uint64_t max_per_message, std::string frame_id)
    : ExportSource(std::move(topic)), window_ns_(window_ns), max_per_message_(max_per_message) {
  const fs::path txt = fs::path(folder) / "events.txt";
  if (fs::exists(txt)) {
    std::optional<io::SensorSize> sensor;
    if (width > 0) sensor = io::SensorSize{width, height};
    txt_ = std::make_unique<io::EventTextReader>(txt.string(), sensor);
  } else {
    h5_ = std::make_unique<io::EventH5Reader>((fs::path(folder) / "events.h5").string());
  }
  pending_.width = static_cast<std::uint32_t>(width);
  pending_.height = static_cast<std::uint32_t>(height);
  pending_.header.frame_id = std::move(frame_id);
  load();
}

bool EventSource::refill() {
  chunk_.clear();
  next_ = 0;
  if (txt_) return txt_->next(chunk_, kReadChunk);
  return h5_->next(chunk_, kReadChunk);
}

void EventSource::load() {
  pending_.events.clear();
  TimeNs t_first = 0;
  while (pending_.events.size() < max_per_message_) {
    if (next_ >= chunk_.size() && !refill()) break;
    const TimeNs t = chunk_.t()[next_];
    if (pending_.events.empty()) t_first = t;
    else if (t - t_first >= window_ns_) break;
    RosEvent e;
    e.x = chunk_.x()[next_];
    e.y = chunk_.y()[next_];
    e.ts = rosTimeFromNs(t);
    e.polarity = chunk_.p()[next_];
    pending_.events.push_back(e);
    pending_time_ = t;
    ++next_;
  }
}

void EventSource::write(rosbag::Bag& bag) {
  pending_.header.seq = static_cast<std::uint32_t>(written_);
  pending_.header.stamp = rosTimeFromNs(pending_time_);
  bag.write(topic_, recordTime(pending_time_), pending_);
  events_ += pending_.events.size();
  ++written_;
  load();
}

FrameSource::FrameSource(std::string topic, std::string folder, std::string frame_id)
    : ExportSource(std::move(topic)), folder_(std::move(folder)), frame_id_(std::move(frame_id)),
      stamps_(io::readImageList(folder_)) {}

void FrameSource::write(rosbag::Bag& bag) {
  const io::ImageStamp& stamp = stamps_[next_];
  const cv::Mat grey = io::readFrame(folder_, stamp, size_);
  size_ = grey.size();  // every frame the size of the first
  RosImage msg = imageFromGrey(grey, stamp.t_ns, frame_id_);
  msg.header.seq = static_cast<std::uint32_t>(written_);
  bag.write(topic_, recordTime(stamp.t_ns), msg);
  ++written_;
  ++next_;
}

ImuSource::ImuSource(std::string topic, const std::string& path, std::string frame_id)
    : ExportSource(std::move(topic)), reader_(path), frame_id_(std::move(frame_id)) {
  has_ = reader_.next(sample_);
}

void ImuSource::write(rosbag::Bag& bag) {
  RosImu msg = rosFromImu(sample_, frame_id_);
  msg.header.seq = static_cast<std::uint32_t>(written_);
  bag.write(topic_, recordTime(sample_.t_ns), msg);
  ++written_;
  has_ = reader_.next(sample_);
}

PoseSource::PoseSource(std::string topic, const std::string& path, std::string frame_id)
    : ExportSource(std::move(topic)), reader_(path), frame_id_(std::move(frame_id)) {
  has_ = reader_.next(pose_);
}

void PoseSource::write(rosbag::Bag& bag) {
  RosPoseStamped msg = rosFromPose(pose_, frame_id_);
  msg.header.seq = static_cast<std::uint32_t>(written_);
  bag.write(topic_, recordTime(pose_.t_ns), msg);
  ++written_;
  has_ = reader_.next(pose_);
}

}  // namespace evio::bags::detail
