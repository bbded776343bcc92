#include "evio/scenes/source_options.h"

#include <algorithm>
#include <cmath>

namespace evio::scenes {

namespace {
void requireFinite(std::string_view field, const Eigen::MatrixXd& m) {
  requireField(m.allFinite(), field, "must be finite");
}
void requirePair(std::string_view field, const Vec2& range) {
  requirePositive(std::string(field) + "[0]", range.x());
  requireField(range.y() >= range.x() && std::isfinite(range.y()), field, "max must be >= min");
}
}  // namespace

void PlaneParams::validate() const {
  requireFinite("position_m", position_m);
  requireFinite("rotation_deg", rotation_deg);
  requirePositive("size_m[0]", size_m.x());
  requirePositive("size_m[1]", size_m.y());
  requireNonNegative("cell_m", cell_m);
  if (cell_m > 0.0)
    requireField(size_m.x() / cell_m * size_m.y() / cell_m < 5e7, "cell_m", "too many cells");
}

void BoxParams::validate() const {
  requireFinite("position_m", position_m);
  requireFinite("rotation_deg", rotation_deg);
  for (int i = 0; i < 3; ++i) requirePositive("size_m[" + std::to_string(i) + "]", size_m[i]);
  requireNonNegative("cell_m", cell_m);
  if (cell_m > 0.0) requireField(size_m.maxCoeff() / cell_m < 5000, "cell_m", "too many cells");
}

void TerrainParams::validate() const {
  requireFinite("position_m", position_m);
  requirePositive("size_m[0]", size_m.x());
  requirePositive("size_m[1]", size_m.y());
  requirePositive("cell_m", cell_m);
  requireField(size_m.x() / cell_m * size_m.y() / cell_m < 5e7, "cell_m",
               "too many grid cells (more than 5e7)");
  requireNonNegative("amplitude_m", amplitude_m);
  requirePositive("wavelength_m", wavelength_m);
  requireInRange("octaves", octaves, 1, 20);
  requireInRange("gain", gain, 0.0, 1.0);
  requireInRange("crater_count", crater_count, 0, 100000);
  requirePair("crater_radius_m", crater_radius_m);
  requireInRange("crater_depth_ratio", crater_depth_ratio, 0.0, 0.5);
  requireInRange("crater_rim_ratio", crater_rim_ratio, 0.0, 2.0);
}

void RocksParams::validate() const {
  requireField(std::isfinite(base_height_m), "base_height_m", "must be finite");
  requireFinite("region_center_m", region_center_m);
  requirePositive("region_size_m[0]", region_size_m.x());
  requirePositive("region_size_m[1]", region_size_m.y());
  requireInRange("count", count, 0, 1000000);
  requirePair("radius_m", radius_m);
  requirePositive("size_exponent", size_exponent);
  requireInRange("embed_fraction", embed_fraction, 0.0, 0.9);
  requireInRange("shape_noise", shape_noise, 0.0, 0.6);
  requireInRange("flatten", flatten, 0.1, 2.0);
  requireInRange("subdivisions", subdivisions, 0, 5);
}

void HeightmapParams::validate() const {
  requireField(!path.empty(), "path", "a raster file is required");
  requireInRange("band", band, 1, 1000);
  requireNonNegative("pixel_size_m", pixel_size_m);
  requireField(std::isfinite(height_scale) && height_scale != 0.0, "height_scale",
               "must be finite and non-zero");
  requireField(std::isfinite(height_offset_m), "height_offset_m", "must be finite");
  requireFinite("position_m", position_m);
  requireField(crop_px.empty() || crop_px.size() == 4, "crop_px",
               "expected [x0, y0, width, height] or nothing");
  if (crop_px.size() == 4)
    requireField(crop_px[0] >= 0 && crop_px[1] >= 0 && crop_px[2] >= 2 && crop_px[3] >= 2, "crop_px",
                 "x0, y0 must be >= 0 and width, height >= 2");
  requireInRange("stride_px", stride_px, 1, 10000);
}

void MeshParams::validate() const {
  requireField(!path.empty(), "path", "a mesh file is required");
  requireFinite("position_m", position_m);
  requireFinite("rotation_deg", rotation_deg);
  requirePositive("scale", scale);
  requirePositive("uv_size_m", uv_size_m);
}

void TubeParams::validate() const {
  requireFinite("position_m", position_m);
  requireField(std::isfinite(yaw_deg), "yaw_deg", "must be finite");
  requirePositive("length_m", length_m);
  requirePositive("width_m", width_m);
  requirePositive("height_m", height_m);
  requireInRange("floor_depth_m", floor_depth_m, 0.0, 0.45 * height_m);
  requireInRange("roughness", roughness, 0.0, 0.3);
  requirePositive("roughness_wavelength_m", roughness_wavelength_m);
  requireNonNegative("meander_m", meander_m);
  requireField(surface_height_m > floor_depth_m + 0.5 * height_m + 1.0, "surface_height_m",
               "must leave at least 1 m of rock above the tube");
  requireNonNegative("surface_relief_m", surface_relief_m);
  requirePositive("pit_length_m", pit_length_m);
  requirePositive("pit_width_m", pit_width_m);
  requireNonNegative("margin_m", margin_m);
  requirePositive("cell_m", cell_m);
  const double cells = (length_m + pit_length_m + margin_m) / cell_m *
                       (std::max(pit_width_m, width_m) + 2.0 * margin_m) / cell_m *
                       (surface_height_m + 2.0) / cell_m;
  requireField(cells < 1.5e8, "cell_m", "too many grid cells (more than 1.5e8)");
}

void SourceOptions::validate() const {
  requireField(!material.empty(), "material", "every source needs a material");
  if (type == "plane") plane.validate();
  else if (type == "box") box.validate();
  else if (type == "terrain") terrain.validate();
  else if (type == "rocks") rocks.validate();
  else if (type == "heightmap") heightmap.validate();
  else if (type == "mesh") mesh.validate();
  else if (type == "tube") tube.validate();
  else
    requireField(false, "type", "unknown source type '" + type + "' (known: " + knownTypes() + ")");
}

}  // namespace evio::scenes
