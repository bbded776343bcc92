#include "evio/simulator/sequence_writer.h"

#include <cstdio>
#include <filesystem>
#include <opencv2/core.hpp>

#include "evio/core/error.h"
#include "evio/core/io/atomic_file.h"
#include "evio/core/io/exr_file.h"
#include "evio/core/io/text_scanner.h"

namespace evio::simulator {

namespace fs = std::filesystem;

SequenceWriter::SequenceWriter(const std::string& folder, const SequenceWriterOptions& options)
    : folder_(folder), options_(options) {
  std::error_code ec;
  fs::create_directories(fs::path(folder_) / "truth", ec);
  if (!ec && options_.depth) fs::create_directories(fs::path(folder_) / "truth" / "depth", ec);
  if (ec) throw Error(folder_ + ": cannot create the output folder: " + ec.message());
  io::EventH5Options h5;
  h5.width = options_.width;
  h5.height = options_.height;
  h5.compression_level = options_.events_h5_compression;
  h5_ = std::make_unique<io::EventH5Writer>((fs::path(folder_) / "events.h5").string(), h5, options_.t_offset_ns);
  if (options_.events_txt) txt_ = std::make_unique<io::EventTextWriter>((fs::path(folder_) / "events.txt").string());
  labels_ = std::make_unique<io::EventLabelWriter>((fs::path(folder_) / "truth" / "event_labels.bin").string());
  if (options_.frames) images_ = std::make_unique<io::ImageFolderWriter>(folder_);
}

void SequenceWriter::appendEvents(const EventArray& events, const std::vector<EventLabel>& labels) {
  require(labels.size() == events.size(), "SequenceWriter: one label per event");
  if (events.empty()) return;
  h5_->append(events);
  if (txt_) txt_->append(events);
  label_bytes_.resize(labels.size());
  for (std::size_t i = 0; i < labels.size(); ++i) label_bytes_[i] = static_cast<std::uint8_t>(labels[i]);
  labels_->append(label_bytes_.data(), label_bytes_.size());
  events_ += events.size();
}

std::size_t SequenceWriter::appendFrame(TimeNs t_ns, const cv::Mat& image) {
  require(images_ != nullptr, "SequenceWriter: frames are off");
  images_->append(t_ns, image);
  return static_cast<std::size_t>(frames_++);
}

void SequenceWriter::appendDepth(std::size_t index, TimeNs t_ns, const cv::Mat& depth, const cv::Mat& flow) {
  char name[40];
  std::snprintf(name, sizeof(name), "depth/depth_%08zu.exr", index);
  std::vector<io::ExrChannel> channels = {{"Z", depth}};
  if (!flow.empty()) {
    cv::Mat uv[2];
    cv::split(flow, uv);
    channels.emplace_back("U", uv[0]);
    channels.emplace_back("V", uv[1]);
  }
  io::writeExr((fs::path(folder_) / "truth" / name).string(), channels);
  io::appendSeconds(depth_list_, t_ns);
  depth_list_ += ' ';
  depth_list_ += name;
  depth_list_ += '\n';
  ++depths_;
}

std::vector<std::string> SequenceWriter::close() {
  h5_->close();
  files_.push_back(h5_->path());
  if (txt_) {
    txt_->close();
    files_.push_back((fs::path(folder_) / "events.txt").string());
  }
  labels_->close();
  files_.push_back((fs::path(folder_) / "truth" / "event_labels.bin").string());
  if (images_) {
    images_->close();
    files_.push_back((fs::path(folder_) / "images.txt").string());
  }
  if (options_.depth) {
    const std::string list = (fs::path(folder_) / "truth" / "depth.txt").string();
    io::writeFileAtomic(list, "# t depth/depth_XXXXXXXX.exr: event-camera depth (channel Z, m; U, V: motion field, px/s, when written) "
                                  "at frame stamps\n" +
                                  depth_list_);
    files_.push_back(list);
  }
  return files_;
}

AsyncSequenceWriter::AsyncSequenceWriter(const std::string& folder, const SequenceWriterOptions& options,
                                         std::size_t queue_slots)
    : options_(options), writer_(folder, options), thread_(queue_slots, [this](Job& job) { write(job); }, SlotRingThread<Job>::OnDestroy::kDropQueued) {}

void AsyncSequenceWriter::write(Job& job) {
  switch (job.kind) {
    case Job::Kind::kEvents:
      writer_.appendEvents(job.events, job.labels);
      return;
    case Job::Kind::kFrame:
      writer_.appendFrame(job.t_ns, job.image);
      return;
    case Job::Kind::kDepth:
      writer_.appendDepth(job.index, job.t_ns, job.depth, job.flow);
      return;
  }
}

void AsyncSequenceWriter::appendEvents(const EventArray& events, const std::vector<EventLabel>& labels) {
  require(labels.size() == events.size(), "SequenceWriter: one label per event");
  if (events.empty()) return;
  thread_.push([&](Job& job) {
    job.kind = Job::Kind::kEvents;
    job.events = events;  // copy assignment: reuses the slot's capacity
    job.labels = labels;
  });
  events_.fetch_add(events.size(), std::memory_order_relaxed);
}

std::size_t AsyncSequenceWriter::appendFrame(TimeNs t_ns, const cv::Mat& image) {
  require(options_.frames, "SequenceWriter: frames are off");
  thread_.push([&](Job& job) {
    job.kind = Job::Kind::kFrame;
    job.t_ns = t_ns;
    image.copyTo(job.image);  // reuses the slot's buffer when the size and type match
  });
  return static_cast<std::size_t>(frames_.fetch_add(1, std::memory_order_relaxed));
}

void AsyncSequenceWriter::appendDepth(std::size_t index, TimeNs t_ns, const cv::Mat& depth, const cv::Mat& flow) {
  thread_.push([&](Job& job) {
    job.kind = Job::Kind::kDepth;
    job.index = index;
    job.t_ns = t_ns;
    depth.copyTo(job.depth);
    if (flow.empty()) {
      job.flow.release();
    } else {
      flow.copyTo(job.flow);
    }
  });
  depths_.fetch_add(1, std::memory_order_relaxed);
}

std::vector<std::string> AsyncSequenceWriter::close() {
  thread_.finish();
  return writer_.close();
}

}  // namespace evio::simulator
