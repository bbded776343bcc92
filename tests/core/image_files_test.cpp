// EXR, PNG and GeoTIFF round trips (core/io/exr_file.h, image_file.h, raster_file.h).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>

#include "evio/core/error.h"
#include "evio/core/io/atomic_file.h"
#include "evio/core/io/exr_file.h"
#include "evio/core/io/image_file.h"
#include "evio/core/io/raster_file.h"
#include "temp_dir.h"

namespace evio {
namespace {

cv::Mat ramp(int w, int h, float scale) {
  cv::Mat m(h, w, CV_32FC1);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) m.at<float>(y, x) = scale * (static_cast<float>(x) + 0.1f * static_cast<float>(y * y)) + 1e-7f;
  return m;
}

bool bitEqual(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() &&
         std::memcmp(a.data, b.data, a.total() * a.elemSize()) == 0;
}

TEST(ExrFile, RoundTripIsBitExactIncludingInfAndNan) {
  test::TempDir dir;
  cv::Mat y = ramp(37, 21, 1.0f / 3.0f), z = ramp(37, 21, 7.5f);
  z.at<float>(3, 4) = std::numeric_limits<float>::infinity();
  z.at<float>(5, 6) = std::numeric_limits<float>::quiet_NaN();
  io::writeExr(dir.file("a.exr"), {{"Y", y}, {"Z", z}});
  const auto channels = io::readExr(dir.file("a.exr"));
  ASSERT_EQ(channels.size(), 2u);
  EXPECT_EQ(channels[0].first, "Y");
  EXPECT_TRUE(bitEqual(channels[0].second, y));
  EXPECT_TRUE(bitEqual(channels[1].second, z));
  EXPECT_TRUE(bitEqual(io::readExrChannel(dir.file("a.exr"), "Z"), z));
  EXPECT_TRUE(bitEqual(io::readExrChannel(dir.file("a.exr")), y));  // Y is preferred
  EXPECT_THROW(io::readExrChannel(dir.file("a.exr"), "Q"), Error);
  EXPECT_THROW(io::writeExr(dir.file("b.exr"), {{"Y", y}, {"Y", z}}), Error);
}

TEST(ExrFile, MissingOrCorruptFileNamesTheFile) {
  test::TempDir dir;
  try {
    io::readExr(dir.file("none.exr"));
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("none.exr"), std::string::npos);
  }
  io::writeFileAtomic(dir.file("bad.exr"), "not an exr");
  EXPECT_THROW(io::readExr(dir.file("bad.exr")), Error);
}

TEST(ImageFile, Png16RawAndNormalized) {
  test::TempDir dir;
  cv::Mat raw(5, 7, CV_16UC1);
  for (int y = 0; y < 5; ++y)
    for (int x = 0; x < 7; ++x) raw.at<std::uint16_t>(y, x) = static_cast<std::uint16_t>(1000 * y + 37 * x + 65000 * (x == 6 && y == 4));
  io::writePng(dir.file("h.png"), raw);
  const cv::Mat r = io::readGrayImage(dir.file("h.png"), io::PixelScale::kRaw);
  const cv::Mat n = io::readGrayImage(dir.file("h.png"));
  for (int y = 0; y < 5; ++y)
    for (int x = 0; x < 7; ++x) {
      EXPECT_EQ(r.at<float>(y, x), static_cast<float>(raw.at<std::uint16_t>(y, x)));
      EXPECT_FLOAT_EQ(n.at<float>(y, x), static_cast<float>(raw.at<std::uint16_t>(y, x)) / 65535.0f);
    }
}

TEST(ImageFile, ColourBecomesRec709Luminance) {
  test::TempDir dir;
  cv::Mat bgr(2, 2, CV_8UC3, cv::Scalar(0, 0, 255));  // pure red
  io::writePng(dir.file("c.png"), bgr);
  const cv::Mat y = io::readGrayImage(dir.file("c.png"));
  EXPECT_NEAR(y.at<float>(0, 0), 0.2126f, 1e-6f);
  EXPECT_THROW(io::readGrayImage(dir.file("none.png")), Error);
}

TEST(RasterFile, GeoTiffRoundTripWithPixelSize) {
  test::TempDir dir;
  const cv::Mat h = ramp(9, 6, 0.25f);
  io::writeGeoTiff(dir.file("dtm.tif"), h, 1.5);
  const io::Raster r = io::readRaster(dir.file("dtm.tif"));
  EXPECT_TRUE(bitEqual(r.values, h));
  EXPECT_DOUBLE_EQ(r.pixel_size_x_m, 1.5);
  EXPECT_DOUBLE_EQ(r.pixel_size_y_m, 1.5);
  EXPECT_FALSE(r.nodata.has_value());
  EXPECT_THROW(io::readRaster(dir.file("dtm.tif"), 2), Error);
  io::writeFileAtomic(dir.file("junk.tif"), "junk");
  EXPECT_THROW(io::readRaster(dir.file("junk.tif")), Error);
}

}  // namespace
}  // namespace evio
