#include "evio/core/io/image_file.h"

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <vector>

#include "evio/core/error.h"
#include "evio/core/io/atomic_file.h"
#include "evio/core/io/exr_file.h"

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
  std::vector<unsigned char> bytes;
  {
    const std::string data = readFile(path);  // names the file when missing
    bytes.assign(data.begin(), data.end());
  }
  cv::Mat image;
  try {
    image = cv::imdecode(bytes, cv::IMREAD_UNCHANGED);
  } catch (const cv::Exception& e) {
    throw Error::inFile(path, 0, std::string("cannot decode image: ") + e.what());
  }
  if (image.empty()) throw Error::inFile(path, 0, "cannot decode image (unknown or corrupt format)");
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

void writePng(const std::string& path, const cv::Mat& image) {
  if (image.empty() || (image.depth() != CV_8U && image.depth() != CV_16U) ||
      (image.channels() != 1 && image.channels() != 3 && image.channels() != 4))
    throw Error::inFile(path, 0, "PNG: expected a non-empty 8- or 16-bit image with 1, 3 or 4 channels");
  std::vector<unsigned char> png;
  if (!cv::imencode(".png", image, png)) throw Error::inFile(path, 0, "PNG encoding failed");
  writeFileAtomic(path, std::string_view(reinterpret_cast<const char*>(png.data()), png.size()));
}

}  // namespace evio::io
