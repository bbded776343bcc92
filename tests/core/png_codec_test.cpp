// PNG through libpng (core/io/png_codec.h) against OpenCV's imgcodecs, the
// decoder and encoder evio used before, and the media module that now carries
// imgcodecs (core/io/media_module.h).
#include <gtest/gtest.h>
#include <png.h>

#include <cstdlib>
#include <cstring>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "evio/core/error.h"
#include "evio/core/io/media_module.h"
#include "evio/core/io/png_codec.h"

namespace evio {
namespace {

/// A deterministic image of every value range: a ramp plus a checker term.
cv::Mat pattern(int rows, int cols, int type) {
  cv::Mat m(rows, cols, type);
  const int channels = m.channels();
  const double top = m.depth() == CV_16U ? 65535.0 : 255.0;
  for (int y = 0; y < rows; ++y)
    for (int x = 0; x < cols; ++x)
      for (int c = 0; c < channels; ++c) {
        const double v = std::fmod(top * (0.37 * x + 0.11 * y * y + 0.29 * c) / 17.0 + ((x ^ y) & 4) * 13.0, top + 1.0);
        if (m.depth() == CV_16U)
          m.ptr<std::uint16_t>(y)[x * channels + c] = static_cast<std::uint16_t>(v);
        else
          m.ptr<std::uint8_t>(y)[x * channels + c] = static_cast<std::uint8_t>(v);
      }
  return m;
}

std::string imencodePng(const cv::Mat& image, const std::vector<int>& params = {}) {
  std::vector<unsigned char> bytes;
  EXPECT_TRUE(cv::imencode(".png", image, bytes, params));
  return std::string(bytes.begin(), bytes.end());
}

cv::Mat imdecodeUnchanged(const std::string& bytes) {
  return cv::imdecode(std::vector<unsigned char>(bytes.begin(), bytes.end()), cv::IMREAD_UNCHANGED);
}

bool samePixels(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() && cv::norm(a, b, cv::NORM_INF) == 0.0;
}

std::string errorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "(no error)";
}

/// libpng writes the layouts OpenCV cannot: palette with transparency, grey
/// with alpha, Adam7 interlacing, 2-bit grey. Returns the file's bytes.
std::string libpngWrite(int width, int height, int bit_depth, int colour, bool interlaced,
                        const std::vector<std::vector<png_byte>>& rows, const std::vector<png_color>& palette = {},
                        const std::vector<png_byte>& palette_alpha = {}) {
  std::string out;
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png_create_info_struct(png);
  png_set_write_fn(
      png, &out,
      [](png_structp p, png_bytep data, png_size_t n) {
        static_cast<std::string*>(png_get_io_ptr(p))->append(reinterpret_cast<const char*>(data), n);
      },
      [](png_structp) {});
  png_set_IHDR(png, info, static_cast<png_uint_32>(width), static_cast<png_uint_32>(height), bit_depth, colour,
               interlaced ? PNG_INTERLACE_ADAM7 : PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
               PNG_FILTER_TYPE_DEFAULT);
  if (!palette.empty()) png_set_PLTE(png, info, palette.data(), static_cast<int>(palette.size()));
  if (!palette_alpha.empty())
    png_set_tRNS(png, info, palette_alpha.data(), static_cast<int>(palette_alpha.size()), nullptr);
  png_write_info(png, info);
  std::vector<png_bytep> pointers;
  for (const auto& r : rows) pointers.push_back(const_cast<png_bytep>(r.data()));
  png_write_image(png, pointers.data());
  png_write_end(png, info);
  png_destroy_write_struct(&png, &info);
  return out;
}

TEST(PngCodec, DecodesAndEncodesEveryOpenCvLayoutAsImgcodecsDoes) {
  for (const int type : {CV_8UC1, CV_16UC1, CV_8UC3, CV_16UC3, CV_8UC4, CV_16UC4}) {
    SCOPED_TRACE("type " + std::to_string(type));
    const cv::Mat image = pattern(23, 37, type);
    const std::string theirs = imencodePng(image);
    const std::string ours = io::encodePng(image, "p.png");
    EXPECT_EQ(ours, theirs);  // same settings, same libpng and zlib: the same bytes
    const cv::Mat decoded = io::decodePng(theirs, "p.png");
    EXPECT_TRUE(samePixels(decoded, image));
    EXPECT_TRUE(samePixels(decoded, imdecodeUnchanged(theirs)));
  }
}

TEST(PngCodec, ExpandsBilevelPaletteAlphaAndInterlacedFilesAsImgcodecsDoes) {
  std::vector<std::string> files;
  const cv::Mat grey = pattern(19, 29, CV_8UC1);
  files.push_back(imencodePng(grey > 100, {cv::IMWRITE_PNG_BILEVEL, 1}));  // 1-bit grey
  std::vector<std::vector<png_byte>> two_bit(5, std::vector<png_byte>(2));
  for (int y = 0; y < 5; ++y) two_bit[y] = {static_cast<png_byte>(0x1B * (y + 1)), static_cast<png_byte>(0xE4 >> y)};
  files.push_back(libpngWrite(7, 5, 2, PNG_COLOR_TYPE_GRAY, false, two_bit));
  std::vector<std::vector<png_byte>> indices(6, std::vector<png_byte>(9));
  for (int y = 0; y < 6; ++y)
    for (int x = 0; x < 9; ++x) indices[y][x] = static_cast<png_byte>((x + 2 * y) % 4);
  const std::vector<png_color> palette{{10, 20, 30}, {200, 100, 0}, {0, 255, 128}, {77, 77, 77}};
  files.push_back(libpngWrite(9, 6, 8, PNG_COLOR_TYPE_PALETTE, false, indices, palette));
  files.push_back(libpngWrite(9, 6, 8, PNG_COLOR_TYPE_PALETTE, false, indices, palette, {255, 0, 128}));
  std::vector<std::vector<png_byte>> grey_alpha(6, std::vector<png_byte>(18));
  for (int y = 0; y < 6; ++y)
    for (int x = 0; x < 18; ++x) grey_alpha[y][x] = static_cast<png_byte>(13 * x + 31 * y);
  files.push_back(libpngWrite(9, 6, 8, PNG_COLOR_TYPE_GRAY_ALPHA, false, grey_alpha));
  std::vector<std::vector<png_byte>> rgb(11, std::vector<png_byte>(3 * 13));
  for (int y = 0; y < 11; ++y)
    for (int x = 0; x < 3 * 13; ++x) rgb[y][x] = static_cast<png_byte>(7 * x + 19 * y);
  files.push_back(libpngWrite(13, 11, 8, PNG_COLOR_TYPE_RGB, true, rgb));  // Adam7
  for (std::size_t k = 0; k < files.size(); ++k) {
    SCOPED_TRACE("file " + std::to_string(k));
    const cv::Mat theirs = imdecodeUnchanged(files[k]);
    ASSERT_FALSE(theirs.empty());
    EXPECT_TRUE(samePixels(io::decodePng(files[k], "f.png"), theirs));
  }
}

TEST(PngCodec, BrokenDataIsOneErrorNamingTheFile) {
  const std::string good = imencodePng(pattern(40, 60, CV_8UC1));
  EXPECT_TRUE(io::isPng(good));
  EXPECT_FALSE(io::isPng("not a png"));
  const std::string not_png = errorOf([] { io::decodePng("not a png at all", "a.png"); });
  EXPECT_NE(not_png.find("a.png"), std::string::npos) << not_png;
  EXPECT_NE(not_png.find("signature"), std::string::npos) << not_png;
  for (const std::size_t keep : {std::size_t{8}, std::size_t{20}, good.size() / 2, good.size() - 5}) {
    const std::string truncated = errorOf([&] { io::decodePng(good.substr(0, keep), "t.png"); });
    EXPECT_NE(truncated.find("t.png"), std::string::npos) << keep << ": " << truncated;
    EXPECT_NE(truncated.find("corrupt PNG"), std::string::npos) << keep << ": " << truncated;
  }
  std::string flipped = good;
  const std::size_t idat = flipped.find("IDAT");
  ASSERT_NE(idat, std::string::npos);
  flipped[idat + 10] = static_cast<char>(flipped[idat + 10] ^ 0x5A);  // inside the data: the CRC no longer matches
  const std::string crc = errorOf([&] { io::decodePng(flipped, "c.png"); });
  EXPECT_NE(crc.find("c.png"), std::string::npos) << crc;
  EXPECT_NE(crc.find("corrupt PNG"), std::string::npos) << crc;
  const std::string two_channels = errorOf([] { io::encodePng(cv::Mat(4, 4, CV_8UC2, cv::Scalar(1, 2)), "e.png"); });
  EXPECT_NE(two_channels.find("e.png"), std::string::npos) << two_channels;
}

TEST(MediaModule, DecodesOtherFormatsThroughTheModuleAsImgcodecsDoes) {
  const cv::Mat image = pattern(30, 40, CV_8UC3);
  std::vector<unsigned char> jpeg;
  ASSERT_TRUE(cv::imencode(".jpg", image, jpeg));
  const std::string bytes(jpeg.begin(), jpeg.end());
  EXPECT_TRUE(samePixels(io::media::decodeImage(bytes, "a.jpg"), imdecodeUnchanged(bytes)));
  const std::string garbage = errorOf([] { io::media::decodeImage("neither png nor jpeg", "g.bin"); });
  EXPECT_NE(garbage.find("g.bin"), std::string::npos) << garbage;
  EXPECT_NE(garbage.find("not a readable image"), std::string::npos) << garbage;
}

TEST(MediaModule, AMissingModuleIsOneErrorNamingTheFileAndThePathTried) {
  // In a fresh process (the module is loaded once per process).
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  EXPECT_EXIT(
      {
        setenv("EVIO_MEDIA_MODULE", "/nonexistent/libevio_media.so", 1);
        const std::string message = errorOf([] { io::media::decodeImage("neither png nor jpeg", "g.jpg"); });
        const bool names_both = message.find("g.jpg") != std::string::npos &&
                                message.find("/nonexistent/libevio_media.so (missing)") != std::string::npos;
        std::fprintf(stderr, "%s\n", message.c_str());
        std::exit(names_both ? 0 : 1);
      },
      testing::ExitedWithCode(0), "EVIO_MEDIA_MODULE");
}

}  // namespace
}  // namespace evio
