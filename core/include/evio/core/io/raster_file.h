#pragma once
/// @file raster_file.h
/// Georeferenced rasters through GDAL: GeoTIFF digital terrain models (e.g.
/// HiRISE DTMs) and any other single-band format GDAL reads.

#include <opencv2/core/mat.hpp>
#include <optional>
#include <string>

namespace evio::io {

struct Raster {
  cv::Mat values;                 ///< CV_32FC1, row 0 = first (northern) row of the file
  double pixel_size_x_m = 0.0;    ///< |geotransform[1]|, 0 when the file has no geotransform
  double pixel_size_y_m = 0.0;    ///< |geotransform[5]|, 0 when the file has no geotransform
  std::optional<double> nodata;   ///< the band's no-data value, when declared
};

/// Reads band `band` (1-based) of a raster as float. Throws Error naming the
/// file when it is missing, not a raster GDAL can open, or lacks the band.
Raster readRaster(const std::string& path, int band = 1);

/// Writes a single-band Float32 GeoTIFF with a north-up geotransform of the
/// given pixel size (origin 0, 0; no projection), atomically.
void writeGeoTiff(const std::string& path, const cv::Mat& values, double pixel_size_m);

}  // namespace evio::io
