#include "evio/core/io/raster_file.h"

#include <gdal_priv.h>

#include <cmath>
#include <cstdio>
#include <memory>

#include "evio/core/error.h"
#include "evio/core/io/atomic_file.h"

namespace evio::io {

namespace {
struct DatasetCloser {
  void operator()(GDALDataset* d) const { GDALClose(d); }
};
using DatasetPtr = std::unique_ptr<GDALDataset, DatasetCloser>;
}  // namespace

Raster readRaster(const std::string& path, int band) {
  {
    std::FILE* f = std::fopen(path.c_str(), "rb");
    if (!f) throw Error::inFile(path, 0, "cannot open file (missing or unreadable)");
    std::fclose(f);
  }
  GDALAllRegister();  // idempotent
  CPLPushErrorHandler(CPLQuietErrorHandler);
  DatasetPtr ds(static_cast<GDALDataset*>(GDALOpen(path.c_str(), GA_ReadOnly)));
  CPLPopErrorHandler();
  if (!ds) throw Error::inFile(path, 0, "not a raster GDAL can read");
  if (band < 1 || band > ds->GetRasterCount())
    throw Error::inFile(path, 0, "raster has no band " + std::to_string(band) + " (it has " +
                                     std::to_string(ds->GetRasterCount()) + ")");
  GDALRasterBand* b = ds->GetRasterBand(band);
  const int w = ds->GetRasterXSize(), h = ds->GetRasterYSize();
  Raster r;
  r.values.create(h, w, CV_32FC1);
  if (b->RasterIO(GF_Read, 0, 0, w, h, r.values.ptr<float>(), w, h, GDT_Float32, 0, 0) != CE_None)
    throw Error::inFile(path, 0, "reading the raster band failed");
  double gt[6];
  if (ds->GetGeoTransform(gt) == CE_None) {
    r.pixel_size_x_m = std::abs(gt[1]);
    r.pixel_size_y_m = std::abs(gt[5]);
  }
  int has_nodata = 0;
  const double nodata = b->GetNoDataValue(&has_nodata);
  if (has_nodata) r.nodata = nodata;
  return r;
}

void writeGeoTiff(const std::string& path, const cv::Mat& values, double pixel_size_m) {
  if (values.empty() || values.type() != CV_32FC1)
    throw Error::inFile(path, 0, "GeoTIFF: expected a non-empty CV_32FC1 image");
  if (!(pixel_size_m > 0.0)) throw Error::inFile(path, 0, "GeoTIFF: pixel size must be > 0");
  GDALAllRegister();
  GDALDriver* driver = GetGDALDriverManager()->GetDriverByName("GTiff");
  if (!driver) throw Error::inFile(path, 0, "GDAL has no GTiff driver");
  const std::string tmp = temporaryPathFor(path);
  {
    CPLPushErrorHandler(CPLQuietErrorHandler);
    DatasetPtr ds(driver->Create(tmp.c_str(), values.cols, values.rows, 1, GDT_Float32, nullptr));
    CPLPopErrorHandler();
    if (!ds) throw Error::inFile(path, 0, "cannot create GeoTIFF");
    double gt[6] = {0.0, pixel_size_m, 0.0, 0.0, 0.0, -pixel_size_m};
    ds->SetGeoTransform(gt);
    cv::Mat c = values.isContinuous() ? values : values.clone();
    if (ds->GetRasterBand(1)->RasterIO(GF_Write, 0, 0, c.cols, c.rows, c.ptr<float>(), c.cols, c.rows,
                                       GDT_Float32, 0, 0) != CE_None) {
      ds.reset();
      std::remove(tmp.c_str());
      throw Error::inFile(path, 0, "writing GeoTIFF failed");
    }
  }
  renameFile(tmp, path);
}

}  // namespace evio::io
