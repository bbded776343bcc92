// libevio_media.so: the codecs that pull in large dependency trees (OpenCV's
// imgcodecs and videoio, GDAL), loaded by evio only when a file needs them
// (evio/core/io/media_module.h). It links no evio library: errors come back
// as messages, and the caller names its file.

#include <gdal_priv.h>

#include <cmath>
#include <memory>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>
#include <vector>

#include "evio/core/io/media_module.h"

#ifndef EVIO_MEDIA_BUILD_ID
#error "EVIO_MEDIA_BUILD_ID (the build identifier both sides share) is not defined"
#endif

namespace {

using evio::io::Raster;
using evio::io::media::Api;
using evio::io::media::VideoEncoder;

struct DatasetCloser {
  void operator()(GDALDataset* d) const { GDALClose(d); }
};
using DatasetPtr = std::unique_ptr<GDALDataset, DatasetCloser>;

/// Silences GDAL's own printing while a file is opened or created.
class QuietGdal {
 public:
  QuietGdal() { CPLPushErrorHandler(CPLQuietErrorHandler); }
  ~QuietGdal() { CPLPopErrorHandler(); }
  QuietGdal(const QuietGdal&) = delete;
  QuietGdal& operator=(const QuietGdal&) = delete;
};

bool decodeImage(const unsigned char* bytes, std::size_t size, cv::Mat* image, std::string* error) {
  try {
    const cv::Mat buffer(1, static_cast<int>(size), CV_8UC1, const_cast<unsigned char*>(bytes));
    *image = cv::imdecode(buffer, cv::IMREAD_UNCHANGED);
  } catch (const cv::Exception& e) {
    *error = std::string("not a readable image: ") + e.what();
    return false;
  }
  if (image->empty()) {
    *error = "not a readable image (unknown or corrupt format)";
    return false;
  }
  return true;
}

bool readRaster(const std::string& path, int band, Raster* raster, std::string* error) {
  GDALAllRegister();  // idempotent
  DatasetPtr ds;
  {
    const QuietGdal quiet;
    ds.reset(static_cast<GDALDataset*>(GDALOpen(path.c_str(), GA_ReadOnly)));
  }
  if (!ds) {
    *error = "not a raster GDAL can read";
    return false;
  }
  if (band < 1 || band > ds->GetRasterCount()) {
    *error = "raster has no band " + std::to_string(band) + " (it has " + std::to_string(ds->GetRasterCount()) + ")";
    return false;
  }
  GDALRasterBand* b = ds->GetRasterBand(band);
  const int w = ds->GetRasterXSize(), h = ds->GetRasterYSize();
  Raster r;
  r.values.create(h, w, CV_32FC1);
  if (b->RasterIO(GF_Read, 0, 0, w, h, r.values.ptr<float>(), w, h, GDT_Float32, 0, 0) != CE_None) {
    *error = "reading the raster band failed";
    return false;
  }
  double gt[6];
  if (ds->GetGeoTransform(gt) == CE_None) {
    r.pixel_size_x_m = std::abs(gt[1]);
    r.pixel_size_y_m = std::abs(gt[5]);
  }
  int has_nodata = 0;
  const double nodata = b->GetNoDataValue(&has_nodata);
  if (has_nodata) r.nodata = nodata;
  *raster = std::move(r);
  return true;
}

bool writeGeoTiff(const std::string& path, const cv::Mat& values, double pixel_size_m, std::string* error) {
  GDALAllRegister();
  GDALDriver* driver = GetGDALDriverManager()->GetDriverByName("GTiff");
  if (!driver) {
    *error = "GDAL has no GTiff driver";
    return false;
  }
  DatasetPtr ds;
  {
    const QuietGdal quiet;
    ds.reset(driver->Create(path.c_str(), values.cols, values.rows, 1, GDT_Float32, nullptr));
  }
  if (!ds) {
    *error = "cannot create GeoTIFF";
    return false;
  }
  double gt[6] = {0.0, pixel_size_m, 0.0, 0.0, 0.0, -pixel_size_m};
  ds->SetGeoTransform(gt);
  const cv::Mat c = values.isContinuous() ? values : values.clone();
  if (ds->GetRasterBand(1)->RasterIO(GF_Write, 0, 0, c.cols, c.rows, const_cast<float*>(c.ptr<float>()), c.cols,
                                     c.rows, GDT_Float32, 0, 0) != CE_None) {
    *error = "writing GeoTIFF failed";
    return false;
  }
  return true;
}

class OpenCvVideo final : public VideoEncoder {
 public:
  explicit OpenCvVideo(cv::VideoWriter writer) : writer_(std::move(writer)) {}
  void write(const cv::Mat& bgr) override { writer_.write(bgr); }
  void release() override { writer_.release(); }

 private:
  cv::VideoWriter writer_;
};

VideoEncoder* openVideo(const std::string& path, const char* fourcc, double fps, int width, int height) {
  cv::VideoWriter writer;
  if (!writer.open(path, cv::CAP_FFMPEG, cv::VideoWriter::fourcc(fourcc[0], fourcc[1], fourcc[2], fourcc[3]), fps,
                   cv::Size(width, height), true))
    return nullptr;
  return new OpenCvVideo(std::move(writer));
}

const Api kApi{EVIO_MEDIA_BUILD_ID, sizeof(Api),        sizeof(Raster), sizeof(cv::Mat),
               decodeImage,                readRaster,         writeGeoTiff,   openVideo};

}  // namespace

extern "C" __attribute__((visibility("default"))) const Api* evio_media_api() { return &kApi; }
