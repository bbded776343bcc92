#pragma once
/// @file sequence_reader.h
/// Streams a sequence folder (docs/architecture.md#the-sequence-folder) in time order: event chunks
/// (events.h5 when present, else events.txt), frames (images.txt, loaded on
/// demand), IMU samples (imu.txt) and, when asked for, laser range-finder
/// readings (range.txt, camera clock), merged on the camera clock. Memory
/// stays flat: events come in chunks of at most max_events_per_chunk, the IMU
/// and the range finder one sample at a time, frames as stamps until loaded.
///
/// Order: an IMU sample stamped t_imu is placed at camera time
/// t = t_imu − time_offset_cam_imu (sensors.yaml: t_imu = t_cam + offset).
/// Before the IMU sample, frame or range reading at time T come all events
/// with t < T; at
/// equal times the IMU sample comes before the frame, and the frame before the
/// range reading.
///
/// Bad input is evio::Error: decreasing event times (from the readers, naming
/// the file and index or line), events outside the sensor size given, a
/// sensor size stored in events.h5 that differs from the calibration (naming
/// both), a frame whose size differs from the calibration (naming both).

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "evio/core/event.h"
#include "evio/core/imu_sample.h"
#include "evio/core/io/images_txt.h"
#include "evio/core/io/range_txt.h"
#include "evio/core/time.h"

namespace evio::estimator {

struct SequenceReaderOptions {
  bool read_events = true;
  bool read_frames = true;
  bool read_imu = true;
  bool read_range = false;  ///< range.txt (an error when missing)
  std::size_t max_events_per_chunk = std::size_t{1} << 14;
  /// Event sensor size to check events against (0: unchecked); `calibration`
  /// names where it came from in messages ("sensors.yaml camera cam0").
  int event_width = 0;
  int event_height = 0;
  std::string calibration = "the calibration";
  /// Camera–IMU time offset: t_imu = t_cam + offset.
  TimeNs time_offset_cam_imu_ns = 0;
};

struct SequenceItem {
  enum class Kind { kEvents, kFrame, kImu, kRange };
  Kind kind = Kind::kEvents;
  TimeNs t_ns = 0;            ///< camera clock: last event of the chunk, frame time, IMU time − offset
  EventArray events;          ///< kEvents: the chunk (non-empty, time-ordered)
  std::size_t frame_index = 0;  ///< kFrame: index into frames()
  cv::Mat image;              ///< kFrame: the frame, once the pipeline loaded it (loadFrame)
  ImuSample imu;              ///< kImu: the sample as read (IMU clock)
  io::RangeSample range;      ///< kRange: the reading as read (camera clock)
};

class SequenceReader {
 public:
  /// Opens the streams that are asked for and exist. Throws evio::Error when
  /// the folder does not exist, events are asked for and neither events.h5
  /// nor events.txt exists, or imu.txt or range.txt is asked for and missing. A missing
  /// images.txt gives no frames (hasFrames() false).
  SequenceReader(std::string folder, const SequenceReaderOptions& options);
  ~SequenceReader();
  SequenceReader(const SequenceReader&) = delete;
  SequenceReader& operator=(const SequenceReader&) = delete;

  /// The next item in time order; false at the end of all streams.
  bool next(SequenceItem& item);

  const std::string& folder() const { return folder_; }
  bool hasEvents() const;
  bool hasFrames() const { return !frames_.empty(); }
  const std::vector<io::ImageStamp>& frames() const { return frames_; }
  /// Loads frame `index` as CV_8UC1; throws naming the file and
  /// `expected_from` when its size is not `expected` (when not empty).
  cv::Mat loadFrame(std::size_t index, cv::Size expected = cv::Size(),
                    const std::string& expected_from = "the calibration") const;

  std::uint64_t eventsRead() const { return events_read_; }
  /// Share of the data read (0..1) by data time when the end is known
  /// (events.h5, frames), else by the size of events.txt.
  double fraction() const;
  /// Events file used ("events.h5" or "events.txt"; empty when none).
  const std::string& eventsFile() const { return events_file_; }

 private:
  class EventStream;
  bool nextEvents(SequenceItem& item, std::optional<TimeNs> t_end);

  std::string folder_;
  SequenceReaderOptions options_;
  std::unique_ptr<EventStream> events_;
  std::string events_file_;
  std::vector<io::ImageStamp> frames_;
  std::size_t next_frame_ = 0;
  struct ImuStream;
  std::unique_ptr<ImuStream> imu_;
  struct RangeStream;
  std::unique_ptr<RangeStream> range_;
  std::uint64_t events_read_ = 0;
  TimeNs t_first_ = 0;
  bool have_first_ = false;
  TimeNs t_now_ = 0;
  std::optional<TimeNs> t_end_;
};

}  // namespace evio::estimator
