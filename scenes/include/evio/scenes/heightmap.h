#pragma once
/// @file heightmap.h
/// Terrain from a raster: EXR (channel Y/R/Z/height…), 16-bit PNG (raw
/// values) or anything GDAL reads (GeoTIFF, so a HiRISE DTM can be dropped
/// in; its pixel size comes from the geotransform).
///
/// Sample (column c, row r) of the (cropped, strided) raster of w × h samples
/// goes to world
///   x = position_x + (c − (w − 1)/2) · Δ,   y = position_y − (r − (h − 1)/2) · Δ,
///   z = position_z + height_scale · value + height_offset_m,
/// Δ = pixel size × stride (rows run north to south, i.e. towards −y). The
/// map is centred on `position_m`, which keeps coordinates small for the
/// single-precision ray tracer (a DTM in map coordinates would lose cm).
/// A NaN, infinite or no-data sample is an error naming the file and pixel.

#include <string>

#include <opencv2/core/mat.hpp>

#include "evio/core/triangle_mesh.h"
#include "evio/scenes/source_options.h"

namespace evio::scenes {

class Heightmap {
 public:
  /// Reads the raster (relative paths against base_dir); `field` prefixes
  /// error messages ("scene.yaml:9: sources[0]").
  Heightmap(const HeightmapParams& params, const std::string& base_dir, const std::string& field);

  /// Grid mesh (front up), uv = world (x, y).
  TriangleMesh mesh() const;
  /// Bilinear height at world (x, y) (clamped to the map's extent).
  double height(double x, double y) const;

  int width() const { return heights_.cols; }
  int height() const { return heights_.rows; }
  double spacing_m() const { return spacing_m_; }

 private:
  HeightmapParams p_;
  cv::Mat heights_;   ///< CV_64FC1, final z (m) per sample
  double spacing_m_ = 0.0;
};

}  // namespace evio::scenes
