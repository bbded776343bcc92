#include "evio/estimator/pipeline/sequence_reader.h"

#include <algorithm>
#include <filesystem>
#include <utility>

#include "evio/core/error.h"
#include "evio/core/io/events_h5.h"
#include "evio/core/io/events_txt.h"
#include "evio/core/io/imu_txt.h"

namespace evio::estimator {

namespace fs = std::filesystem;

namespace {

std::string sizeText(int w, int h) { return std::to_string(w) + "x" + std::to_string(h); }

}  // namespace

/// Events from events.h5 or events.txt, handed out in chunks up to a time.
class SequenceReader::EventStream {
 public:
  EventStream(const fs::path& folder, const SequenceReaderOptions& o) {
    const fs::path h5 = folder / "events.h5";
    const fs::path txt = folder / "events.txt";
    if (fs::exists(h5)) {
      name_ = "events.h5";
      h5_ = std::make_unique<io::EventH5Reader>(h5.string());
      if (o.event_width > 0 && h5_->width() > 0 &&
          (h5_->width() != o.event_width || h5_->height() != o.event_height))
        throw Error(h5.string() + ": sensor size " + sizeText(h5_->width(), h5_->height()) + " differs from " +
                    o.calibration + " (" + sizeText(o.event_width, o.event_height) + ")");
      if (o.event_width > 0 && h5_->width() == 0)
        h5_ = std::make_unique<io::EventH5Reader>(h5.string(), o.event_width, o.event_height);
      total_ = h5_->size();
      if (total_ > 0) t_last_ = h5_->tLastNs();
    } else if (fs::exists(txt)) {
      name_ = "events.txt";
      std::optional<io::SensorSize> sensor;
      if (o.event_width > 0) sensor = io::SensorSize{o.event_width, o.event_height};
      txt_ = std::make_unique<io::EventTextReader>(txt.string(), sensor);
      total_ = static_cast<std::uint64_t>(fs::file_size(txt) / 24);  // about 24 bytes per line: progress only
    } else {
      throw Error(folder.string() + ": no events.h5 or events.txt");
    }
    block_ = o.max_events_per_chunk;
  }

  /// Replaces `out` with the next events with t < t_end (all when nullopt),
  /// at most block_; false when none are left before t_end.
  bool next(EventArray& out, std::optional<TimeNs> t_end) {
    if (pos_ >= buffer_.size()) {
      if (done_) return false;
      buffer_.clear();
      pos_ = 0;
      const bool more = h5_ ? h5_->next(buffer_, std::size_t{1} << 16) : txt_->next(buffer_, std::size_t{1} << 16);
      if (!more || buffer_.empty()) {
        done_ = true;
        return false;
      }
      read_ += buffer_.size();
    }
    std::size_t end = std::min(buffer_.size(), pos_ + block_);
    if (t_end) {
      const std::size_t bound = buffer_.lowerBound(*t_end);
      end = std::min(end, std::max(pos_, bound));
    }
    if (end == pos_) return false;
    const auto b = static_cast<std::ptrdiff_t>(pos_), e = static_cast<std::ptrdiff_t>(end);
    out.t().assign(buffer_.t().begin() + b, buffer_.t().begin() + e);
    out.x().assign(buffer_.x().begin() + b, buffer_.x().begin() + e);
    out.y().assign(buffer_.y().begin() + b, buffer_.y().begin() + e);
    out.p().assign(buffer_.p().begin() + b, buffer_.p().begin() + e);
    pos_ = end;
    return true;
  }

  bool exhausted() const { return done_ && pos_ >= buffer_.size(); }
  std::uint64_t read() const { return read_; }
  std::uint64_t total() const { return total_; }
  std::optional<TimeNs> tLast() const { return t_last_; }
  const std::string& name() const { return name_; }

 private:
  std::unique_ptr<io::EventH5Reader> h5_;
  std::unique_ptr<io::EventTextReader> txt_;
  std::string name_;
  EventArray buffer_;
  std::size_t pos_ = 0;
  std::size_t block_ = 1;
  bool done_ = false;
  std::uint64_t read_ = 0;
  std::uint64_t total_ = 0;
  std::optional<TimeNs> t_last_;
};

/// imu.txt, one sample looked ahead.
struct SequenceReader::ImuStream {
  explicit ImuStream(const std::string& path) : reader(path) { have = reader.next(sample); }
  void advance() { have = reader.next(sample); }
  io::ImuTextReader reader;
  ImuSample sample;
  bool have = false;
};

/// range.txt, one reading looked ahead.
struct SequenceReader::RangeStream {
  explicit RangeStream(const std::string& path) : reader(path) { have = reader.next(sample); }
  void advance() { have = reader.next(sample); }
  io::RangeReader reader;
  io::RangeSample sample;
  bool have = false;
};

SequenceReader::SequenceReader(std::string folder, const SequenceReaderOptions& options)
    : folder_(std::move(folder)), options_(options) {
  if (!fs::is_directory(folder_)) throw Error(folder_ + ": not a folder");
  require(options_.max_events_per_chunk > 0, "SequenceReader: max_events_per_chunk must be > 0");
  if (options_.read_events) {
    events_ = std::make_unique<EventStream>(fs::path(folder_), options_);
    events_file_ = events_->name();
    if (events_->tLast()) t_end_ = *events_->tLast();
  }
  if (options_.read_frames && fs::exists(fs::path(folder_) / "images.txt")) {
    frames_ = io::readImageList(folder_);
    if (!frames_.empty()) t_end_ = std::max(t_end_.value_or(frames_.back().t_ns), frames_.back().t_ns);
  }
  if (options_.read_imu) {
    const fs::path imu = fs::path(folder_) / "imu.txt";
    if (!fs::exists(imu)) throw Error(folder_ + ": no imu.txt");
    imu_ = std::make_unique<ImuStream>(imu.string());
  }
  if (options_.read_range) {
    const fs::path range = fs::path(folder_) / "range.txt";
    if (!fs::exists(range)) throw Error(folder_ + ": no range.txt");
    range_ = std::make_unique<RangeStream>(range.string());
  }
}

SequenceReader::~SequenceReader() = default;

bool SequenceReader::hasEvents() const { return events_ != nullptr; }

bool SequenceReader::nextEvents(SequenceItem& item, std::optional<TimeNs> t_end) {
  if (!events_ || !events_->next(item.events, t_end)) return false;
  item.kind = SequenceItem::Kind::kEvents;
  item.t_ns = item.events.t().back();
  events_read_ += item.events.size();
  return true;
}

bool SequenceReader::next(SequenceItem& item) {
  const bool have_imu = imu_ && imu_->have;
  const bool have_frame = next_frame_ < frames_.size();
  const bool have_range = range_ && range_->have;
  const TimeNs t_imu = have_imu ? imu_->sample.t_ns - options_.time_offset_cam_imu_ns : 0;
  const TimeNs t_frame = have_frame ? frames_[next_frame_].t_ns : 0;
  const TimeNs t_range = have_range ? range_->sample.t_ns : 0;
  std::optional<TimeNs> t_stop;
  for (const auto& [have, t] : {std::pair{have_imu, t_imu}, {have_frame, t_frame}, {have_range, t_range}})
    if (have) t_stop = std::min(t_stop.value_or(t), t);
  bool got = false;
  if (nextEvents(item, t_stop)) {
    got = true;
  } else if (have_imu && t_imu == *t_stop) {
    item.kind = SequenceItem::Kind::kImu;
    item.imu = imu_->sample;
    item.t_ns = t_imu;
    imu_->advance();
    if (imu_->have && imu_->sample.t_ns <= item.imu.t_ns)  // the reader checks too; be explicit
      throw Error(folder_ + "/imu.txt: time does not increase after " + std::to_string(nsToSeconds(item.imu.t_ns)) + " s");
    got = true;
  } else if (have_frame && t_frame == *t_stop) {
    item.kind = SequenceItem::Kind::kFrame;
    item.frame_index = next_frame_;
    item.t_ns = t_frame;
    ++next_frame_;
    got = true;
  } else if (have_range) {
    item.kind = SequenceItem::Kind::kRange;
    item.range = range_->sample;
    item.t_ns = t_range;
    range_->advance();
    got = true;
  }
  if (!got) return false;
  if (!have_first_) {
    t_first_ = item.kind == SequenceItem::Kind::kEvents ? item.events.t().front() : item.t_ns;
    have_first_ = true;
  }
  t_now_ = std::max(t_now_, item.t_ns);
  return true;
}

cv::Mat SequenceReader::loadFrame(std::size_t index, cv::Size expected, const std::string& expected_from) const {
  require(index < frames_.size(), "SequenceReader::loadFrame: index out of range");
  const cv::Mat image = io::readFrame(folder_, frames_[index]);
  if (!expected.empty() && image.size() != expected)
    throw Error((fs::path(folder_) / frames_[index].relative_path).string() + ": frame size " +
                sizeText(image.cols, image.rows) + " differs from " + expected_from + " (" +
                sizeText(expected.width, expected.height) + ")");
  return image;
}

double SequenceReader::fraction() const {
  if (t_end_ && have_first_ && *t_end_ > t_first_)
    return std::clamp(static_cast<double>(t_now_ - t_first_) / static_cast<double>(*t_end_ - t_first_), 0.0, 1.0);
  if (events_ && events_->total() > 0)
    return std::min(1.0, static_cast<double>(events_->read()) / static_cast<double>(events_->total()));
  return 0.0;
}

}  // namespace evio::estimator
