#include "evio/simulator/render_output.h"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include <opencv2/core.hpp>

#include "evio/core/error.h"
#include "evio/core/io/exr_file.h"
#include "evio/core/io/image_file.h"

namespace evio::simulator {

double autoWhite(const cv::Mat& radiance) {
  std::vector<float> v;
  v.reserve(radiance.total());
  for (int y = 0; y < radiance.rows; ++y)
    for (int x = 0; x < radiance.cols; ++x) {
      const float l = radiance.at<float>(y, x);
      if (std::isfinite(l)) v.push_back(l);
    }
  if (v.empty()) return 1.0;
  const std::size_t k = std::min(v.size() - 1, static_cast<std::size_t>(0.995 * static_cast<double>(v.size())));
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  const double white = static_cast<double>(v[k]);
  return white > 0.0 ? white : 1.0;
}

cv::Mat toneMap(const cv::Mat& radiance, double white_w_m2_sr) {
  require(radiance.type() == CV_32FC1, "toneMap: radiance must be CV_32FC1");
  const double white = white_w_m2_sr > 0.0 ? white_w_m2_sr : autoWhite(radiance);
  cv::Mat out(radiance.size(), CV_8UC1);
  for (int y = 0; y < radiance.rows; ++y)
    for (int x = 0; x < radiance.cols; ++x) {
      const double l = static_cast<double>(radiance.at<float>(y, x));
      const double t = std::isfinite(l) ? std::clamp(l / white, 0.0, 1.0) : 0.0;
      out.at<unsigned char>(y, x) = static_cast<unsigned char>(std::lround(255.0 * std::pow(t, 1.0 / 2.2)));
    }
  return out;
}

std::vector<std::string> writeRenderOutput(const std::string& dir, const RenderOutput& out, double white_w_m2_sr) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw Error::inFile(dir, 0, "cannot create the output folder: " + ec.message());
  const auto path = [&](const char* name) { return (std::filesystem::path(dir) / name).string(); };
  std::vector<std::string> written;
  io::writeExr(path("radiance.exr"), {{"Y", out.radiance}});
  written.push_back(path("radiance.exr"));
  io::writeExr(path("depth.exr"), {{"Z", out.depth}});
  written.push_back(path("depth.exr"));
  std::vector<cv::Mat> n;
  cv::split(out.normal, n);
  io::writeExr(path("normal.exr"), {{"X", n[0]}, {"Y", n[1]}, {"Z", n[2]}});
  written.push_back(path("normal.exr"));
  if (!out.flow.empty()) {
    std::vector<cv::Mat> f;
    cv::split(out.flow, f);
    io::writeExr(path("flow.exr"), {{"U", f[0]}, {"V", f[1]}});
    written.push_back(path("flow.exr"));
  }
  io::writePng(path("preview.png"), toneMap(out.radiance, white_w_m2_sr));
  written.push_back(path("preview.png"));
  return written;
}

}  // namespace evio::simulator
