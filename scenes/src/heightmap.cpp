#include "evio/scenes/heightmap.h"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "evio/core/error.h"
#include "evio/core/io/exr_file.h"
#include "evio/core/io/image_file.h"
#include "evio/core/io/raster_file.h"
#include "evio/scenes/mesh_ops.h"

namespace evio::scenes {

namespace {
std::string lowerExtension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (auto& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}
}  // namespace

Heightmap::Heightmap(const HeightmapParams& params, const std::string& base_dir, const std::string& field)
    : p_(params) {
  std::filesystem::path path(params.path);
  if (path.is_relative() && !base_dir.empty()) path = std::filesystem::path(base_dir) / path;
  const std::string file = path.string();
  const std::string ext = lowerExtension(file);
  cv::Mat raw;
  double pixel = params.pixel_size_m;
  std::optional<double> nodata;
  try {
    if (ext == ".exr") {
      raw = io::readExrChannel(file);
    } else if (ext == ".png") {
      raw = io::readGrayImage(file, io::PixelScale::kRaw);
    } else {
      io::Raster r = io::readRaster(file, params.band);
      raw = r.values;
      nodata = r.nodata;
      if (pixel == 0.0) pixel = r.pixel_size_x_m;
    }
  } catch (const Error& e) {
    throw Error(field + ".path: " + e.what());
  }
  if (!(pixel > 0.0))
    throw Error(field + ".pixel_size_m: " + file +
                " has no geotransform; set pixel_size_m to the grid step in metres");
  cv::Rect crop(0, 0, raw.cols, raw.rows);
  if (params.crop_px.size() == 4) {
    crop = cv::Rect(params.crop_px[0], params.crop_px[1], params.crop_px[2], params.crop_px[3]);
    if (crop.x + crop.width > raw.cols || crop.y + crop.height > raw.rows)
      throw Error(field + ".crop_px: the crop exceeds the raster (" + std::to_string(raw.cols) + "x" +
                  std::to_string(raw.rows) + " samples in " + file + ")");
  }
  const int s = params.stride_px;
  const int w = (crop.width - 1) / s + 1, h = (crop.height - 1) / s + 1;
  if (w < 2 || h < 2) throw Error(field + ".path: " + file + ": fewer than 2 × 2 samples after crop/stride");
  heights_.create(h, w, CV_64FC1);
  for (int r = 0; r < h; ++r)
    for (int c = 0; c < w; ++c) {
      const int x = crop.x + c * s, y = crop.y + r * s;
      const double v = static_cast<double>(raw.at<float>(y, x));
      if (!std::isfinite(v) || (nodata && v == *nodata))
        throw Error(field + ".path: " + file + ": " + (std::isnan(v) ? "NaN" : !std::isfinite(v) ? "infinite" : "no-data") +
                    " height at pixel (x " + std::to_string(x) + ", y " + std::to_string(y) +
                    "); crop it away with crop_px or fill the hole");
      heights_.at<double>(r, c) = params.position_m.z() + params.height_scale * v + params.height_offset_m;
    }
  spacing_m_ = pixel * s;
}

TriangleMesh Heightmap::mesh() const {
  const int w = heights_.cols, h = heights_.rows;
  const double d = spacing_m_;
  // Grid index j runs south to north (row h−1−j) so that ∂p/∂i × ∂p/∂j = +z.
  const auto xy = [&](int i, int j) {
    return Vec2(p_.position_m.x() + (i - 0.5 * (w - 1)) * d,
                p_.position_m.y() + (j - 0.5 * (h - 1)) * d);
  };
  TriangleMesh m = gridMesh(
      w, h,
      [&](int i, int j) {
        const Vec2 q = xy(i, j);
        return Eigen::Vector3f(static_cast<float>(q.x()), static_cast<float>(q.y()),
                               static_cast<float>(heights_.at<double>(h - 1 - j, i)));
      },
      [&](int i, int j) { return Eigen::Vector2f(xy(i, j).cast<float>()); });
  computeVertexNormals(m);
  return m;
}

double Heightmap::height(double x, double y) const {
  const int w = heights_.cols, h = heights_.rows;
  const double fi = std::clamp((x - p_.position_m.x()) / spacing_m_ + 0.5 * (w - 1), 0.0, w - 1.0);
  const double fj = std::clamp((y - p_.position_m.y()) / spacing_m_ + 0.5 * (h - 1), 0.0, h - 1.0);
  const int i0 = std::min(static_cast<int>(fi), w - 2), j0 = std::min(static_cast<int>(fj), h - 2);
  const double tx = fi - i0, ty = fj - j0;
  const auto at = [&](int i, int j) { return heights_.at<double>(h - 1 - j, i); };
  const double a = at(i0, j0) + tx * (at(i0 + 1, j0) - at(i0, j0));
  const double b = at(i0, j0 + 1) + tx * (at(i0 + 1, j0 + 1) - at(i0, j0 + 1));
  return a + ty * (b - a);
}

}  // namespace evio::scenes
