#pragma once
/// @file images_txt.h
/// Frames of the Event-Camera Dataset: `images.txt` lists `t images/frame_XXXXXXXX.png`
/// (t in seconds, path relative to the sequence folder); the PNGs are 8-bit
/// grayscale (colour PNGs are converted to gray on reading).

#include <opencv2/core/mat.hpp>
#include <string>
#include <vector>

#include "evio/core/io/atomic_file.h"
#include "evio/core/time.h"

namespace evio::io {

struct ImageStamp {
  TimeNs t_ns = 0;
  std::string relative_path;  ///< as written in images.txt, relative to the folder

  friend bool operator==(const ImageStamp&, const ImageStamp&) = default;
};

/// Reads images.txt in `folder`. Validates two columns per line, strictly
/// increasing time, and that every listed file exists (error: file:line).
std::vector<ImageStamp> readImageList(const std::string& folder);

/// Loads one listed frame as CV_8UC1. Throws naming the file if it is missing
/// or not a readable image, or if its size differs from `expected` (when not empty).
cv::Mat readFrame(const std::string& folder, const ImageStamp& stamp,
                  cv::Size expected = cv::Size());

/// Writes frames as `images/frame_%08d.png` plus `images.txt`. Each PNG is
/// written atomically; images.txt appears on close().
class ImageFolderWriter {
 public:
  explicit ImageFolderWriter(std::string folder);
  /// `image` must be CV_8UC1; frames must come in increasing time.
  void append(TimeNs t_ns, const cv::Mat& image);
  void close();

 private:
  std::string folder_;
  AtomicFile list_;
  std::string buffer_;
  std::size_t count_ = 0;
  TimeNs last_t_ns_ = 0;
};

}  // namespace evio::io
