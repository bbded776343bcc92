#include "evio/core/io/raster_file.h"

#include <cstdio>

#include "evio/core/error.h"
#include "evio/core/io/atomic_file.h"
#include "evio/core/io/media_module.h"

// GDAL itself lives in the media module (media_module.h); here the files are
// checked, named in errors and written atomically.

namespace evio::io {

Raster readRaster(const std::string& path, int band) {
  {
    std::FILE* f = std::fopen(path.c_str(), "rb");
    if (!f) throw Error::inFile(path, 0, "cannot open file (missing or unreadable)");
    std::fclose(f);
  }
  Raster raster;
  std::string error;
  if (!media::api(path).read_raster(path, band, &raster, &error)) throw Error::inFile(path, 0, error);
  return raster;
}

void writeGeoTiff(const std::string& path, const cv::Mat& values, double pixel_size_m) {
  if (values.empty() || values.type() != CV_32FC1)
    throw Error::inFile(path, 0, "GeoTIFF: expected a non-empty CV_32FC1 image");
  if (!(pixel_size_m > 0.0)) throw Error::inFile(path, 0, "GeoTIFF: pixel size must be > 0");
  const media::Api& gdal = media::api(path);
  const std::string tmp = temporaryPathFor(path);
  std::string error;
  if (!gdal.write_geotiff(tmp, values, pixel_size_m, &error)) {
    std::remove(tmp.c_str());
    throw Error::inFile(path, 0, error);
  }
  renameFile(tmp, path);
}

}  // namespace evio::io
