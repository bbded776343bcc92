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
#include "error_of.h"

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

using test::errorOf;

/// libpng writes the layouts OpenCV cannot: palette with transparency, grey
/// with alpha, Adam7 interlacing, 2-bit grey. Returns the file's bytes.
std::string libpngWrite(int width, int height, int bit_depth, int colour, bool interlaced,
                        const std::vector<std::vector<png_byte>>& rows, const std::vector<png_color>& palette = {},
                        const std::vector<png_byte>& palette_alpha = {}, const png_color_16* trans_colour = nullptr,
                        double gamma = 0.0) {
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
  if (trans_colour) png_set_tRNS(png, info, nullptr, 0, const_cast<png_color_16*>(trans_colour));
  if (gamma > 0.0) png_set_gAMA(png, info, gamma);
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
  // tRNS on grey: OpenCV keeps one channel; on colour it adds alpha. And a
  // gAMA chunk, which neither applies.
  png_color_16 grey_key{};
  grey_key.gray = 77;
  std::vector<std::vector<png_byte>> grey8(5, std::vector<png_byte>(9));
  for (int y = 0; y < 5; ++y)
    for (int x = 0; x < 9; ++x) grey8[y][x] = static_cast<png_byte>(x % 3 == 0 ? 77 : 20 * x + y);
  files.push_back(libpngWrite(9, 5, 8, PNG_COLOR_TYPE_GRAY, false, grey8, {}, {}, &grey_key, 0.45455));
  grey_key.gray = 0x1234;
  std::vector<std::vector<png_byte>> grey16(4, std::vector<png_byte>(2 * 7));
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 7; ++x) {
      const int v = x == 2 ? 0x1234 : 9000 * x + 1700 * y + 11;
      grey16[y][2 * x] = static_cast<png_byte>(v >> 8);  // big-endian, as in the file
      grey16[y][2 * x + 1] = static_cast<png_byte>(v & 0xFF);
    }
  files.push_back(libpngWrite(7, 4, 16, PNG_COLOR_TYPE_GRAY, false, grey16, {}, {}, &grey_key));
  grey_key.gray = 2;
  files.push_back(libpngWrite(7, 5, 2, PNG_COLOR_TYPE_GRAY, false, two_bit, {}, {}, &grey_key));
  png_color_16 rgb_key{};
  rgb_key.red = 0x0102;
  rgb_key.green = 0x0304;
  rgb_key.blue = 0x0506;
  std::vector<std::vector<png_byte>> rgb16(3, std::vector<png_byte>(6 * 5));
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 6 * 5; ++x) rgb16[y][x] = static_cast<png_byte>(x < 6 && y == 0 ? x + 1 : 37 * x + 91 * y);
  files.push_back(libpngWrite(5, 3, 16, PNG_COLOR_TYPE_RGB, true, rgb16, {}, {}, &rgb_key));  // the first pixel is the key
  for (std::size_t k = 0; k < files.size(); ++k) {
    SCOPED_TRACE("file " + std::to_string(k));
    const cv::Mat theirs = imdecodeUnchanged(files[k]);
    ASSERT_FALSE(theirs.empty());
    EXPECT_TRUE(samePixels(io::decodePng(files[k], "f.png"), theirs));
  }
}

TEST(PngCodec, EncodesAViewInsideALargerImageAsImgcodecsDoes) {
  const cv::Mat whole = pattern(40, 50, CV_16UC3);
  const cv::Mat view = whole(cv::Rect(7, 5, 31, 22));  // rows not contiguous
  ASSERT_FALSE(view.isContinuous());
  EXPECT_EQ(io::encodePng(view, "v.png"), imencodePng(view));
  EXPECT_TRUE(samePixels(io::decodePng(io::encodePng(view, "v.png"), "v.png"), view));
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
  const std::string broken_jpeg = errorOf([] { io::media::decodeImage("\xFF\xD8\xFF then nothing", "b.jpg"); });
  EXPECT_NE(broken_jpeg.find("b.jpg"), std::string::npos) << broken_jpeg;
  EXPECT_NE(broken_jpeg.find("not a readable image"), std::string::npos) << broken_jpeg;
}

/// Runs `body` in a fresh process (the module is loaded once per process)
/// with EVIO_MEDIA_MODULE set to `module`; the child exits 0 when `body` does.
void expectInFreshProcess(const char* module, bool (*body)()) {
  const std::string style = GTEST_FLAG_GET(death_test_style);
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  EXPECT_EXIT(
      {
        setenv("EVIO_MEDIA_MODULE", module, 1);
        std::exit(body() ? 0 : 1);
      },
      testing::ExitedWithCode(0), "");
  GTEST_FLAG_SET(death_test_style, style);
}

TEST(MediaModule, AMissingModuleIsOneErrorNamingTheFileAndThePathTried) {
  expectInFreshProcess("/nonexistent/libevio_media.so", [] {
    const std::string message = errorOf([] { io::media::decodeImage("\xFF\xD8\xFF a JPEG's start", "g.jpg"); });
    std::fprintf(stderr, "%s\n", message.c_str());
    return message.find("g.jpg") != std::string::npos &&
           message.find("/nonexistent/libevio_media.so (missing)") != std::string::npos &&
           message.find("EVIO_MEDIA_MODULE") != std::string::npos;
  });
}

TEST(MediaModule, ALibraryThatIsNotTheModuleIsRefusedByName) {
  // libpng is a real shared library without the module's entry point.
  expectInFreshProcess(PNG_LIBRARY_FILE, [] {
    const std::string message = errorOf([] { io::media::decodeImage("\xFF\xD8\xFF a JPEG's start", "g.jpg"); });
    std::fprintf(stderr, "%s\n", message.c_str());
    return message.find("not an evio media module") != std::string::npos;
  });
}

TEST(MediaModule, BytesWithoutAnImageSignatureAreRefusedWithoutTheModule) {
  expectInFreshProcess("/nonexistent/libevio_media.so", [] {
    const std::string garbage = errorOf([] { io::media::decodeImage("neither png nor jpeg", "g.bin"); });
    const std::string empty = errorOf([] { io::media::decodeImage("", "e.png"); });
    std::fprintf(stderr, "%s\n%s\n", garbage.c_str(), empty.c_str());
    return garbage.find("no signature") != std::string::npos && empty.find("empty") != std::string::npos &&
           garbage.find("libevio_media") == std::string::npos;
  });
}

}  // namespace
}  // namespace evio
