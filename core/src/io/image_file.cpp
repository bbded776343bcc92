#include "evio/core/io/image_file.h"

#include <opencv2/core.hpp>
#include <vector>

#include "evio/core/error.h"
#include "evio/core/io/atomic_file.h"
#include "evio/core/io/exr_file.h"
#include "evio/core/io/media_module.h"
#include "evio/core/io/png_codec.h"

namespace evio::io {

namespace {
bool endsWithExr(const std::string& path) {
  if (path.size() < 4) return false;
  std::string ext = path.substr(path.size() - 4);
  for (auto& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".exr";
}
}  // namespace

cv::Mat readGrayImage(const std::string& path, PixelScale scale) {
  if (endsWithExr(path)) {
    const auto channels = readExr(path);
    const cv::Mat* r = nullptr;
    const cv::Mat* g = nullptr;
    const cv::Mat* b = nullptr;
    for (const auto& [name, image] : channels) {
      if (name == "R") r = &image;
      if (name == "G") g = &image;
      if (name == "B") b = &image;
    }
    if (r && g && b) {
      cv::Mat y = 0.2126 * *r + 0.7152 * *g + 0.0722 * *b;
      return y;
    }
    return readExrChannel(path);
  }
  const cv::Mat image = media::decodeImage(readFile(path), path);  // readFile names the file when missing
  double max_value = 1.0;
  switch (image.depth()) {
    case CV_8U: max_value = 255.0; break;
    case CV_16U: max_value = 65535.0; break;
    case CV_32F: break;
    default: throw Error::inFile(path, 0, "unsupported pixel depth (expected 8 or 16 bit)");
  }
  cv::Mat f;
  image.convertTo(f, CV_32F, scale == PixelScale::kNormalized ? 1.0 / max_value : 1.0);
  if (f.channels() == 1) return f;
  if (f.channels() != 3 && f.channels() != 4)
    throw Error::inFile(path, 0, "unsupported channel count " + std::to_string(f.channels()));
  // OpenCV orders colour channels B, G, R(, A).
  std::vector<cv::Mat> bgr;
  cv::split(f, bgr);
  cv::Mat y = 0.0722 * bgr[0] + 0.7152 * bgr[1] + 0.2126 * bgr[2];
  return y;
}

void writePng(const std::string& path, const cv::Mat& image) { writeFileAtomic(path, encodePng(image, path)); }

}  // namespace evio::io
