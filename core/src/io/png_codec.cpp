#include "evio/core/io/png_codec.h"

#include <png.h>
#include <zlib.h>

#include <bit>
#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <vector>

#include "evio/core/error.h"

// libpng reports errors by longjmp to the last setjmp. Every function below
// that calls setjmp holds only trivially destructible locals, so that the jump
// skips no destructor; the images and row tables live in the callers.

namespace evio::io {

namespace {

constexpr std::size_t kSignatureBytes = 8;
constexpr std::uint64_t kMaxPixels = std::uint64_t{1} << 30;  // OpenCV's limit (CV_IO_MAX_IMAGE_PIXELS)
constexpr bool kLittleEndianHost = std::endian::native == std::endian::little;

/// What the callbacks share with the caller: the input (or output) bytes and
/// libpng's last error message.
struct PngIo {
  std::string_view input;
  std::size_t offset = 0;
  std::string* output = nullptr;
  char message[200] = {};
};

void onError(png_structp png, png_const_charp message) {
  auto* io = static_cast<PngIo*>(png_get_error_ptr(png));
  std::snprintf(io->message, sizeof(io->message), "%s", message);
  png_longjmp(png, 1);
}

void onWarning(png_structp, png_const_charp) {}

void readBytes(png_structp png, png_bytep out, png_size_t count) {
  auto* io = static_cast<PngIo*>(png_get_io_ptr(png));
  if (io->input.size() - io->offset < count) png_error(png, "the data ends early (truncated file)");
  std::memcpy(out, io->input.data() + io->offset, count);
  io->offset += count;
}

void writeBytes(png_structp png, png_bytep data, png_size_t count) {
  auto* io = static_cast<PngIo*>(png_get_io_ptr(png));
  bool appended = true;
  try {
    io->output->append(reinterpret_cast<const char*>(data), count);
  } catch (...) {  // no C++ exception may cross libpng's C frames
    appended = false;
  }
  if (!appended) png_error(png, "out of memory");
}

void flushNothing(png_structp) {}

/// The decoded layout after the transforms.
struct Layout {
  png_uint_32 width = 0;
  png_uint_32 height = 0;
  int channels = 0;
  int bit_depth = 0;
};

/// Reads the header and sets the transforms that give imdecode's layout.
bool readHeader(png_structp png, png_infop info, Layout* layout) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_set_sig_bytes(png, 0);
  png_read_info(png, info);
  const int colour = png_get_color_type(png, info);
  const int depth = png_get_bit_depth(png, info);
  const bool transparency = png_get_valid(png, info, PNG_INFO_tRNS) != 0;
  if (colour == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(png);
  if (colour == PNG_COLOR_TYPE_GRAY && depth < 8) png_set_expand_gray_1_2_4_to_8(png);
  // As OpenCV: tRNS becomes alpha for colour and palette images only (grey
  // with tRNS stays one channel), and grey with alpha becomes BGRA (there are
  // no two-channel images).
  if (transparency && (colour & PNG_COLOR_MASK_COLOR) != 0) png_set_tRNS_to_alpha(png);
  if (colour == PNG_COLOR_TYPE_GRAY_ALPHA) png_set_gray_to_rgb(png);
  if (depth == 16 && kLittleEndianHost) png_set_swap(png);
  png_set_bgr(png);
  png_set_interlace_handling(png);
  png_read_update_info(png, info);
  layout->width = png_get_image_width(png, info);
  layout->height = png_get_image_height(png, info);
  layout->channels = png_get_channels(png, info);
  layout->bit_depth = png_get_bit_depth(png, info);
  return true;
}

bool readRows(png_structp png, png_infop info, png_bytepp rows) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_read_image(png, rows);
  png_read_end(png, info);
  return true;
}

bool writeImage(png_structp png, png_infop info, const Layout& layout, int colour, png_bytepp rows) {
  if (setjmp(png_jmpbuf(png))) return false;
  // OpenCV's imencode settings for speed, so that the bytes are those evio
  // wrote before it had its own encoder: the Sub filter, zlib level 1, RLE.
  png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_SUB);
  png_set_compression_level(png, Z_BEST_SPEED);
  png_set_compression_strategy(png, Z_RLE);
  png_set_IHDR(png, info, layout.width, layout.height, layout.bit_depth, colour, PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  if (layout.channels >= 3) png_set_bgr(png);
  if (layout.bit_depth == 16 && kLittleEndianHost) png_set_swap(png);
  png_write_image(png, rows);
  png_write_end(png, info);
  return true;
}

/// libpng's read (kWrite false) or write struct with its info struct,
/// destroyed together.
template <bool kWrite>
class PngStruct {
 public:
  explicit PngStruct(PngIo* io) {
    png_ = kWrite ? png_create_write_struct(PNG_LIBPNG_VER_STRING, io, onError, onWarning)
                  : png_create_read_struct(PNG_LIBPNG_VER_STRING, io, onError, onWarning);
    if (png_) info_ = png_create_info_struct(png_);
  }
  ~PngStruct() {
    if constexpr (kWrite)
      png_destroy_write_struct(&png_, info_ ? &info_ : nullptr);
    else
      png_destroy_read_struct(&png_, info_ ? &info_ : nullptr, nullptr);
  }
  PngStruct(const PngStruct&) = delete;
  PngStruct& operator=(const PngStruct&) = delete;
  bool ok() const { return png_ && info_; }
  png_structp png() const { return png_; }
  png_infop info() const { return info_; }

 private:
  png_structp png_ = nullptr;
  png_infop info_ = nullptr;
};
using ReadStruct = PngStruct<false>;
using WriteStruct = PngStruct<true>;

std::vector<png_bytep> rowPointers(const cv::Mat& image) {
  std::vector<png_bytep> rows(static_cast<std::size_t>(image.rows));
  for (int r = 0; r < image.rows; ++r) rows[static_cast<std::size_t>(r)] = const_cast<png_bytep>(image.ptr(r));
  return rows;
}

}  // namespace

bool isPng(std::string_view bytes) {
  return bytes.size() >= kSignatureBytes &&
         png_sig_cmp(reinterpret_cast<png_const_bytep>(bytes.data()), 0, kSignatureBytes) == 0;
}

cv::Mat decodePng(std::string_view bytes, const std::string& path) {
  if (!isPng(bytes)) throw Error::inFile(path, 0, "not a PNG (no PNG signature)");
  PngIo io;
  io.input = bytes;
  ReadStruct read(&io);
  if (!read.ok()) throw Error::inFile(path, 0, "PNG: libpng could not allocate its decoder");
  png_set_read_fn(read.png(), &io, readBytes);
  Layout layout;
  if (!readHeader(read.png(), read.info(), &layout))
    throw Error::inFile(path, 0, std::string("corrupt PNG header: ") + io.message);
  const std::uint64_t pixels = std::uint64_t{layout.width} * layout.height;
  if (pixels == 0 || pixels > kMaxPixels)
    throw Error::inFile(path, 0, "PNG of " + std::to_string(layout.width) + "x" + std::to_string(layout.height) +
                                     " pixels is empty or too large");
  if ((layout.bit_depth != 8 && layout.bit_depth != 16) ||
      (layout.channels != 1 && layout.channels != 3 && layout.channels != 4))
    throw Error::inFile(path, 0, "unsupported PNG layout (" + std::to_string(layout.channels) + " channels of " +
                                     std::to_string(layout.bit_depth) + " bits)");
  cv::Mat image(static_cast<int>(layout.height), static_cast<int>(layout.width),
                CV_MAKETYPE(layout.bit_depth == 16 ? CV_16U : CV_8U, layout.channels));
  std::vector<png_bytep> rows = rowPointers(image);
  if (!readRows(read.png(), read.info(), rows.data()))
    throw Error::inFile(path, 0, std::string("corrupt PNG data: ") + io.message);
  return image;
}

std::string encodePng(const cv::Mat& image, const std::string& path) {
  const int depth = image.depth();
  const int channels = image.channels();
  if (image.empty() || (depth != CV_8U && depth != CV_16U) || (channels != 1 && channels != 3 && channels != 4))
    throw Error::inFile(path, 0, "PNG: expected a non-empty 8- or 16-bit image with 1, 3 or 4 channels");
  Layout layout;
  layout.width = static_cast<png_uint_32>(image.cols);
  layout.height = static_cast<png_uint_32>(image.rows);
  layout.channels = channels;
  layout.bit_depth = depth == CV_16U ? 16 : 8;
  const int colour = channels == 1 ? PNG_COLOR_TYPE_GRAY : channels == 3 ? PNG_COLOR_TYPE_RGB : PNG_COLOR_TYPE_RGBA;
  std::string out;
  PngIo io;
  io.output = &out;
  WriteStruct write(&io);
  if (!write.ok()) throw Error::inFile(path, 0, "PNG: libpng could not allocate its encoder");
  png_set_write_fn(write.png(), &io, writeBytes, flushNothing);
  std::vector<png_bytep> rows = rowPointers(image);
  if (!writeImage(write.png(), write.info(), layout, colour, rows.data()))
    throw Error::inFile(path, 0, std::string("PNG encoding failed: ") + io.message);
  return out;
}

}  // namespace evio::io
