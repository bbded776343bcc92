#include "evio/core/io/images_txt.h"

#include <cstdio>
#include <filesystem>
#include <opencv2/imgproc.hpp>

#include "evio/core/error.h"
#include "evio/core/io/media_module.h"
#include "evio/core/io/png_codec.h"
#include "evio/core/io/text_scanner.h"

namespace evio::io {

namespace fs = std::filesystem;

std::vector<ImageStamp> readImageList(const std::string& folder) {
  const std::string path = (fs::path(folder) / "images.txt").string();
  LineReader lines(path);
  std::vector<ImageStamp> out;
  std::string_view line;
  std::string_view f[2];
  while (lines.next(line)) {
    if (isBlankOrComment(line)) continue;
    bool more = false;
    const std::size_t n = splitFields(line, f, 2, &more);
    if (n != 2 || more)
      throw Error::inFile(path, lines.lineNumber(),
                          "images.txt: expected 2 columns 't path', got " + std::to_string(n) +
                              (more ? "+" : ""));
    ImageStamp stamp;
    if (!parseSecondsToNs(f[0], &stamp.t_ns))
      throw Error::inField(path, lines.lineNumber(), "t", "not a finite time in seconds: '" + std::string(f[0]) + "'");
    if (!out.empty() && stamp.t_ns <= out.back().t_ns)
      throw Error::inField(path, lines.lineNumber(), "t", "timestamps must increase strictly");
    stamp.relative_path = std::string(f[1]);
    if (!fs::is_regular_file(fs::path(folder) / stamp.relative_path))
      throw Error::inField(path, lines.lineNumber(), "path", "listed frame '" + stamp.relative_path + "' does not exist");
    out.push_back(std::move(stamp));
  }
  return out;
}

cv::Mat readFrame(const std::string& folder, const ImageStamp& stamp, cv::Size expected) {
  const std::string path = (fs::path(folder) / stamp.relative_path).string();
  cv::Mat image = media::decodeImage(readFile(path), path);  // readFile names the file when missing
  if (image.channels() == 3) cv::cvtColor(image, image, cv::COLOR_BGR2GRAY);
  else if (image.channels() == 4) cv::cvtColor(image, image, cv::COLOR_BGRA2GRAY);
  if (image.depth() == CV_16U) image.convertTo(image, CV_8U, 1.0 / 257.0);
  if (image.type() != CV_8UC1) throw Error::inFile(path, 0, "expected an 8-bit grayscale image");
  if (!expected.empty() && image.size() != expected)
    throw Error::inFile(path, 0, "frame is " + std::to_string(image.cols) + "x" + std::to_string(image.rows) +
                                     ", the sensor is " + std::to_string(expected.width) + "x" +
                                     std::to_string(expected.height));
  return image;
}

ImageFolderWriter::ImageFolderWriter(std::string folder)
    : folder_(std::move(folder)), list_((fs::path(folder_) / "images.txt").string()) {
  fs::create_directories(fs::path(folder_) / "images");
}

void ImageFolderWriter::append(TimeNs t_ns, const cv::Mat& image) {
  if (image.type() != CV_8UC1) throw Error::inFile(list_.path(), 0, "frames must be 8-bit grayscale");
  if (count_ > 0 && t_ns <= last_t_ns_)
    throw Error::inFile(list_.path(), 0, "frames must be appended in increasing time");
  char name[32];
  std::snprintf(name, sizeof(name), "images/frame_%08zu.png", count_);
  writeFileAtomic((fs::path(folder_) / name).string(), encodePng(image, name));
  appendSeconds(buffer_, t_ns);
  buffer_.push_back(' ');
  buffer_ += name;
  buffer_.push_back('\n');
  last_t_ns_ = t_ns;
  ++count_;
}

void ImageFolderWriter::close() {
  list_.write(buffer_);
  list_.commit();
}

}  // namespace evio::io
