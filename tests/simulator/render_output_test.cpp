#include "evio/simulator/render_output.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>

#include "evio/core/io/exr_file.h"
#include "evio/core/io/image_file.h"
#include "temp_dir.h"

namespace evio::simulator {
namespace {

TEST(RenderOutput, ToneMapFormulaAndAutoWhite) {
  cv::Mat l(1, 200, CV_32FC1);
  for (int i = 0; i < 200; ++i) l.at<float>(0, i) = static_cast<float>(i);
  // 99.5th percentile of 0..199 is element floor(0.995 · 200) = 199.
  EXPECT_DOUBLE_EQ(autoWhite(l), 199.0);
  const cv::Mat p = toneMap(l, 100.0);
  EXPECT_EQ(p.at<unsigned char>(0, 0), 0);
  EXPECT_EQ(p.at<unsigned char>(0, 25), static_cast<unsigned char>(std::lround(255.0 * std::pow(0.25, 1 / 2.2))));
  EXPECT_EQ(p.at<unsigned char>(0, 150), 255);  // over-exposed
}

TEST(RenderOutput, FilesRoundTrip) {
  test::TempDir dir;
  RenderOutput out;
  out.radiance = cv::Mat(3, 4, CV_32FC1, cv::Scalar(12.5f));
  out.depth = cv::Mat(3, 4, CV_32FC1, cv::Scalar(std::numeric_limits<float>::infinity()));
  out.depth.at<float>(1, 2) = 3.25f;
  out.normal = cv::Mat(3, 4, CV_32FC3, cv::Scalar(0.0f, 0.6f, 0.8f));
  out.flow = cv::Mat(3, 4, CV_32FC2, cv::Scalar(1.5f, -2.0f));
  const auto files = writeRenderOutput((dir.path() / "sub").string(), out, 10.0);
  EXPECT_EQ(files.size(), 5u);
  const cv::Mat r = io::readExrChannel((dir.path() / "sub" / "radiance.exr").string(), "Y");
  const cv::Mat d = io::readExrChannel((dir.path() / "sub" / "depth.exr").string(), "Z");
  EXPECT_EQ(0, std::memcmp(r.data, out.radiance.data, 12 * sizeof(float)));
  EXPECT_EQ(0, std::memcmp(d.data, out.depth.data, 12 * sizeof(float)));
  EXPECT_EQ(io::readExrChannel((dir.path() / "sub" / "normal.exr").string(), "Z").at<float>(2, 3), 0.8f);
  EXPECT_EQ(io::readExrChannel((dir.path() / "sub" / "flow.exr").string(), "V").at<float>(0, 0), -2.0f);
  const cv::Mat png = io::readGrayImage((dir.path() / "sub" / "preview.png").string());
  EXPECT_FLOAT_EQ(png.at<float>(0, 0), 1.0f);  // 12.5 > white 10
}

}  // namespace
}  // namespace evio::simulator
