#pragma once
/// @file source_options.h
/// Geometry sources of a scene file. Each list item of `sources:` is a map
/// with a `type` and the fields of that type (others are rejected):
///
///   plane      a rectangle in its local x-y plane, front face +z_local
///   box        a box, faces outwards
///   terrain    fractal terrain with craters (generators/terrain.h)
///   rocks      scattered rocks on the ground or on another source
///   heightmap  a terrain from an EXR, 16-bit PNG or GeoTIFF raster
///   mesh       a triangle mesh from an OBJ or PLY file
///   tube       a lava tube entered from a collapse pit (lava_tube.h)
///
/// Placement: `position_m` and `rotation_deg` = [roll, pitch, yaw] map local
/// to world coordinates as p_W = R p_local + position_m with
/// R = Rz(yaw) · Ry(pitch) · Rx(roll).
///
/// Surface coordinates uv (m) for uv-based textures: plane u = x + w/2,
/// v = h/2 − y (image top at the local +y edge); box faces alike per face;
/// terrain, heightmap and tube the world (x, y); mesh the file's texture
/// coordinates × uv_size_m.

#include <string>
#include <vector>

#include "evio/core/eigen_types.h"
#include "evio/core/options.h"

namespace evio::scenes {

struct PlaneParams {
  Vec3 position_m = Vec3::Zero();      ///< centre
  Vec3 rotation_deg = Vec3::Zero();    ///< [roll, pitch, yaw]
  Vec2 size_m = Vec2(10.0, 10.0);      ///< extent along local x and y
  double cell_m = 0.0;                 ///< tessellation step (0 = one quad)
  template <class V>
  void fields(V& v) {
    v("position_m", position_m, "centre (m)");
    v("rotation_deg", rotation_deg, "[roll, pitch, yaw] (deg)");
    v("size_m", size_m, "extent along local x and y (m)");
    v("cell_m", cell_m, "tessellation step (m), 0 = one quad");
  }
  void validate() const;
};

struct BoxParams {
  Vec3 position_m = Vec3(0.0, 0.0, 0.5);  ///< centre
  Vec3 rotation_deg = Vec3::Zero();       ///< [roll, pitch, yaw]
  Vec3 size_m = Vec3(1.0, 1.0, 1.0);      ///< edge lengths along local x, y, z
  double cell_m = 0.0;                    ///< tessellation step (0 = one quad per face)
  template <class V>
  void fields(V& v) {
    v("position_m", position_m, "centre (m)");
    v("rotation_deg", rotation_deg, "[roll, pitch, yaw] (deg)");
    v("size_m", size_m, "edge lengths (m)");
    v("cell_m", cell_m, "tessellation step (m), 0 = one quad per face");
  }
  void validate() const;
};

struct TerrainParams {
  Vec3 position_m = Vec3::Zero();           ///< centre of the terrain (m)
  Vec2 size_m = Vec2(40.0, 40.0);           ///< extent in x and y (m)
  double cell_m = 0.1;                      ///< grid step (m)
  double amplitude_m = 1.0;                 ///< fractal relief amplitude (m)
  double wavelength_m = 20.0;               ///< wavelength of the largest relief (m)
  int octaves = 8;                          ///< fractal octaves
  double gain = 0.5;                        ///< amplitude ratio between octaves
  int crater_count = 10;                    ///< number of craters
  Vec2 crater_radius_m = Vec2(0.5, 5.0);    ///< min and max crater radius (m)
  double crater_depth_ratio = 0.12;         ///< depth / diameter
  double crater_rim_ratio = 0.3;            ///< rim height / depth
  template <class V>
  void fields(V& v) {
    v("position_m", position_m, "centre (m)");
    v("size_m", size_m, "extent (m)");
    v("cell_m", cell_m, "grid step (m)");
    v("amplitude_m", amplitude_m, "relief amplitude (m)");
    v("wavelength_m", wavelength_m, "largest relief wavelength (m)");
    v("octaves", octaves, "fractal octaves");
    v("gain", gain, "amplitude ratio between octaves");
    v("crater_count", crater_count, "number of craters");
    v("crater_radius_m", crater_radius_m, "min and max crater radius (m)");
    v("crater_depth_ratio", crater_depth_ratio, "depth / diameter");
    v("crater_rim_ratio", crater_rim_ratio, "rim height / depth");
  }
  void validate() const;
};

struct RocksParams {
  std::string ground;                        ///< source the rocks rest on ("" = z = base_height_m)
  double base_height_m = 0.0;                ///< ground height when `ground` is empty
  Vec2 region_center_m = Vec2::Zero();       ///< centre of the scatter region (x, y)
  Vec2 region_size_m = Vec2(20.0, 20.0);     ///< extent of the scatter region
  int count = 50;                            ///< number of rocks
  Vec2 radius_m = Vec2(0.05, 0.5);           ///< min and max rock radius (m)
  double size_exponent = 2.5;                ///< cumulative size law N(>r) ∝ r^−k
  double embed_fraction = 0.3;               ///< share of a rock's height below ground
  double shape_noise = 0.25;                 ///< relative radius irregularity
  double flatten = 0.6;                      ///< vertical / horizontal radius
  int subdivisions = 2;                      ///< icosphere subdivisions (2: 320 faces)
  template <class V>
  void fields(V& v) {
    v("ground", ground, "source the rocks rest on");
    v("base_height_m", base_height_m, "ground height without `ground` (m)");
    v("region_center_m", region_center_m, "scatter region centre (m)");
    v("region_size_m", region_size_m, "scatter region extent (m)");
    v("count", count, "number of rocks");
    v("radius_m", radius_m, "min and max radius (m)");
    v("size_exponent", size_exponent, "cumulative size-law exponent");
    v("embed_fraction", embed_fraction, "buried share of the height");
    v("shape_noise", shape_noise, "relative radius irregularity");
    v("flatten", flatten, "vertical / horizontal radius");
    v("subdivisions", subdivisions, "icosphere subdivisions");
  }
  void validate() const;
};

struct HeightmapParams {
  std::string path;                    ///< EXR, PNG (16-bit) or GeoTIFF, relative to the scene file
  int band = 1;                        ///< raster band (GeoTIFF)
  double pixel_size_m = 0.0;           ///< grid step; 0 = from the GeoTIFF geotransform
  double height_scale = 1.0;           ///< metres per stored unit
  double height_offset_m = 0.0;        ///< added after scaling
  Vec3 position_m = Vec3::Zero();      ///< where the centre of the map goes
  std::vector<int> crop_px;            ///< [x0, y0, width, height] or empty (whole raster)
  int stride_px = 1;                   ///< keep every n-th sample
  template <class V>
  void fields(V& v) {
    v("path", path, "raster file");
    v("band", band, "raster band");
    v("pixel_size_m", pixel_size_m, "grid step (m), 0 = from the file");
    v("height_scale", height_scale, "metres per stored unit");
    v("height_offset_m", height_offset_m, "offset after scaling (m)");
    v("position_m", position_m, "centre position (m)");
    v("crop_px", crop_px, "[x0, y0, width, height]");
    v("stride_px", stride_px, "decimation");
  }
  void validate() const;
};

struct MeshParams {
  std::string path;                    ///< OBJ or PLY, relative to the scene file
  Vec3 position_m = Vec3::Zero();
  Vec3 rotation_deg = Vec3::Zero();    ///< [roll, pitch, yaw]
  double scale = 1.0;                  ///< uniform scale applied before rotation
  double uv_size_m = 1.0;              ///< uv (m) = file texture coordinates × this
  template <class V>
  void fields(V& v) {
    v("path", path, "mesh file");
    v("position_m", position_m, "position (m)");
    v("rotation_deg", rotation_deg, "[roll, pitch, yaw] (deg)");
    v("scale", scale, "uniform scale");
    v("uv_size_m", uv_size_m, "texture coordinate scale (m)");
  }
  void validate() const;
};

struct TubeParams {
  Vec3 position_m = Vec3::Zero();       ///< floor point on the axis at the mouth
  double yaw_deg = 0.0;                 ///< heading into the tube (0: +x)
  double length_m = 50.0;               ///< tube length from the mouth
  double width_m = 9.0;                 ///< mean width of the elliptic section
  double height_m = 7.0;                ///< mean height of the elliptic section
  double floor_depth_m = 2.0;           ///< floor level below the section's centre
  double roughness = 0.1;               ///< relative wall irregularity
  double roughness_wavelength_m = 2.5;  ///< wavelength of the wall irregularity
  double meander_m = 1.5;               ///< lateral wander of the axis
  double surface_height_m = 10.0;       ///< ground surface above the mouth's floor
  double surface_relief_m = 0.6;        ///< relief amplitude of the surface
  double pit_length_m = 30.0;           ///< collapse pit before the mouth, along the axis
  double pit_width_m = 18.0;            ///< collapse pit width
  double margin_m = 10.0;               ///< surface extent around the pit
  double cell_m = 0.25;                 ///< grid step of the surface extraction
  template <class V>
  void fields(V& v) {
    v("position_m", position_m, "floor point on the axis at the mouth (m)");
    v("yaw_deg", yaw_deg, "heading into the tube (deg)");
    v("length_m", length_m, "tube length (m)");
    v("width_m", width_m, "section width (m)");
    v("height_m", height_m, "section height (m)");
    v("floor_depth_m", floor_depth_m, "floor below the section centre (m)");
    v("roughness", roughness, "relative wall irregularity");
    v("roughness_wavelength_m", roughness_wavelength_m, "irregularity wavelength (m)");
    v("meander_m", meander_m, "lateral wander of the axis (m)");
    v("surface_height_m", surface_height_m, "surface above the mouth floor (m)");
    v("surface_relief_m", surface_relief_m, "surface relief (m)");
    v("pit_length_m", pit_length_m, "collapse pit length (m)");
    v("pit_width_m", pit_width_m, "collapse pit width (m)");
    v("margin_m", margin_m, "surface extent around the pit (m)");
    v("cell_m", cell_m, "grid step (m)");
  }
  void validate() const;
};

struct SourceOptions {
  std::string type;        ///< plane | box | terrain | rocks | heightmap | mesh | tube
  std::string name;        ///< unique; defaults to "<type><index>"
  std::string material;    ///< name of a material of the scene
  bool solid = true;       ///< the back side is inside matter (camera there = error)
  PlaneParams plane;
  BoxParams box;
  TerrainParams terrain;
  RocksParams rocks;
  HeightmapParams heightmap;
  MeshParams mesh;
  TubeParams tube;

  template <class V>
  void fields(V& v) {
    v("type", type, "source type");
    v("name", name, "unique name");
    v("material", material, "material name");
    v("solid", solid, "back side is inside matter");
    if (type == "plane") plane.fields(v);
    else if (type == "box") box.fields(v);
    else if (type == "terrain") terrain.fields(v);
    else if (type == "rocks") rocks.fields(v);
    else if (type == "heightmap") heightmap.fields(v);
    else if (type == "mesh") mesh.fields(v);
    else if (type == "tube") tube.fields(v);
  }
  void validate() const;
  static std::string knownTypes() { return "plane, box, terrain, rocks, heightmap, mesh, tube"; }
};

}  // namespace evio::scenes
