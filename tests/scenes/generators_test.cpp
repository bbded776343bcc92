// Procedural generators and heightmap import: exact geometry where it is known.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>

#include "evio/core/error.h"
#include "evio/core/io/exr_file.h"
#include "evio/core/io/image_file.h"
#include "evio/core/io/raster_file.h"
#include "evio/scenes/heightmap.h"
#include "evio/scenes/isosurface.h"
#include "evio/scenes/lava_tube.h"
#include "evio/scenes/mesh_ops.h"
#include "evio/scenes/primitives.h"
#include "evio/scenes/rocks.h"
#include "evio/scenes/terrain.h"
#include "temp_dir.h"

namespace evio::scenes {
namespace {

Eigen::Vector3d faceNormal(const TriangleMesh& m, const Eigen::Vector3i& t) {
  const Eigen::Vector3d a = m.positions[static_cast<std::size_t>(t[0])].cast<double>();
  const Eigen::Vector3d b = m.positions[static_cast<std::size_t>(t[1])].cast<double>();
  const Eigen::Vector3d c = m.positions[static_cast<std::size_t>(t[2])].cast<double>();
  return (b - a).cross(c - a);
}

Eigen::Vector3d centroid(const TriangleMesh& m, const Eigen::Vector3i& t) {
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (int k = 0; k < 3; ++k) c += m.positions[static_cast<std::size_t>(t[k])].cast<double>();
  return c / 3.0;
}

/// Volume by the divergence theorem: positive for a closed, outward mesh.
double signedVolume(const TriangleMesh& m) {
  double v = 0.0;
  for (const auto& t : m.triangles) {
    const Eigen::Vector3d a = m.positions[static_cast<std::size_t>(t[0])].cast<double>();
    const Eigen::Vector3d b = m.positions[static_cast<std::size_t>(t[1])].cast<double>();
    const Eigen::Vector3d c = m.positions[static_cast<std::size_t>(t[2])].cast<double>();
    v += a.dot(b.cross(c)) / 6.0;
  }
  return v;
}

TEST(Primitives, BoxIsClosedOutwardWithExactVolumeAndArea) {
  BoxParams p;
  p.size_m = Vec3(1.0, 2.0, 0.5);
  p.position_m = Vec3(3, -1, 2);
  p.rotation_deg = Vec3(10, 20, 30);
  p.cell_m = 0.3;
  const TriangleMesh m = boxMesh(p);
  EXPECT_NEAR(signedVolume(m), 1.0, 1e-5);
  EXPECT_NEAR(surfaceArea(m), 2 * (2.0 + 0.5 + 1.0), 1e-5);
  for (const auto& t : m.triangles)
    EXPECT_GT(faceNormal(m, t).dot(centroid(m, t) - p.position_m), 0.0);  // outward
}

TEST(Primitives, PlaneUvAndOrientation) {
  PlaneParams p;
  p.size_m = Vec2(2.0, 1.0);
  p.position_m = Vec3(0, 1, 1);
  p.rotation_deg = Vec3(90, 0, 0);  // vertical, facing -y, local y up
  const TriangleMesh m = planeMesh(p);
  for (const auto& t : m.triangles) EXPECT_LT(faceNormal(m, t).normalized().y(), -0.999999);
  for (std::size_t i = 0; i < m.positions.size(); ++i) {
    // u = x + w/2, v = h/2 - (z - 1): the image top is at the top edge.
    EXPECT_NEAR(m.uvs[i].x(), m.positions[i].x() + 1.0f, 1e-6f);
    EXPECT_NEAR(m.uvs[i].y(), 0.5f - (m.positions[i].z() - 1.0f), 1e-6f);
  }
}

TEST(Rocks, IcosphereIsClosedAndOutward) {
  const TriangleMesh m = icosphere(2);
  EXPECT_EQ(m.positions.size(), 162u);
  EXPECT_EQ(m.triangles.size(), 320u);
  for (const auto& t : m.triangles) EXPECT_GT(faceNormal(m, t).dot(centroid(m, t)), 0.0);
  // An inscribed polyhedron: a little less than the ball's volume.
  EXPECT_LT(signedVolume(m), 4.0 / 3.0 * std::numbers::pi);
  EXPECT_GT(signedVolume(m), 0.95 * 4.0 / 3.0 * std::numbers::pi);
}

TEST(Rocks, RestOnTheGroundAndAreDeterministic) {
  RocksParams p;
  p.count = 20;
  p.embed_fraction = 0.25;
  p.region_size_m = Vec2(10, 10);
  const HeightFunction ground = [](double x, double y) { return 0.1 * x - 0.05 * y; };
  const TriangleMesh a = rocksMesh(p, 5, "rocks", ground);
  const TriangleMesh b = rocksMesh(p, 5, "rocks", ground);
  ASSERT_EQ(a.positions.size(), b.positions.size());
  for (std::size_t i = 0; i < a.positions.size(); ++i) ASSERT_EQ(a.positions[i], b.positions[i]);
  // Each rock (162 vertices) reaches below and above the local ground.
  for (int r = 0; r < p.count; ++r) {
    double below = 1e9, above = -1e9;
    for (int v = 0; v < 162; ++v) {
      const auto& q = a.positions[static_cast<std::size_t>(r * 162 + v)];
      const double d = static_cast<double>(q.z()) - ground(q.x(), q.y());
      below = std::min(below, d);
      above = std::max(above, d);
    }
    EXPECT_LT(below, 0.0);
    EXPECT_GT(above, 0.0);
  }
  const TriangleMesh c = rocksMesh(p, 6, "rocks", ground);
  EXPECT_NE(a.positions[0], c.positions[0]);  // another seed, other rocks
}

TEST(Terrain, CraterProfileIsExact) {
  TerrainParams p;
  p.amplitude_m = 0.0;  // no relief: only the crater
  p.crater_count = 1;
  p.crater_radius_m = Vec2(2.0, 2.0);
  p.position_m = Vec3(0, 0, 1.5);
  const TerrainField f(p, 1, "t");
  ASSERT_EQ(f.craters().size(), 1u);
  const auto& c = f.craters()[0];
  EXPECT_DOUBLE_EQ(c.radius, 2.0);
  EXPECT_NEAR(f.height(c.x, c.y), 1.5 - c.depth, 1e-12);              // floor
  EXPECT_NEAR(f.height(c.x + 2.0, c.y), 1.5 + c.rim, 1e-12);          // rim
  EXPECT_NEAR(f.height(c.x, c.y + 1.0), 1.5 + (c.depth + c.rim) * 0.25 - c.depth, 1e-12);
  EXPECT_NEAR(f.height(c.x + 5.0, c.y), 1.5 + c.rim / (2.5 * 2.5 * 2.5), 1e-12);  // ejecta
  EXPECT_NEAR(f.height(c.x + 8.5, c.y), 1.5, 1e-12);                   // beyond 4 R
  const TriangleMesh m = terrainMesh(p, f);
  for (const auto& t : m.triangles) EXPECT_GT(faceNormal(m, t).z(), 0.0);
  for (const auto& q : m.positions) EXPECT_NEAR(q.z(), f.height(q.x(), q.y()), 1e-5);
}

TEST(Heightmap, ExrPngAndGeoTiffGiveExactVertices) {
  test::TempDir dir;
  cv::Mat h(4, 5, CV_32FC1);
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 5; ++c) h.at<float>(r, c) = static_cast<float>(10 * r + c);
  io::writeExr(dir.file("h.exr"), {{"Y", h}});
  cv::Mat h16;
  h.convertTo(h16, CV_16UC1);
  io::writePng(dir.file("h.png"), h16);
  io::writeGeoTiff(dir.file("h.tif"), h, 0.5);
  for (const std::string file : {"h.exr", "h.png", "h.tif"}) {
    SCOPED_TRACE(file);
    HeightmapParams p;
    p.path = file;
    p.pixel_size_m = file == "h.tif" ? 0.0 : 0.5;  // GeoTIFF: from the geotransform
    p.height_scale = 0.1;
    p.position_m = Vec3(1, 2, 3);
    const Heightmap map(p, dir.path().string(), "scene.yaml:3: sources[0]");
    EXPECT_DOUBLE_EQ(map.spacing_m(), 0.5);
    const TriangleMesh m = map.mesh();
    ASSERT_EQ(m.positions.size(), 20u);
    // Sample (c, r) → x = 1 + (c − 2)·0.5, y = 2 − (r − 1.5)·0.5, z = 3 + 0.1 h.
    for (const auto& q : m.positions) {
      const double c = (static_cast<double>(q.x()) - 1.0) / 0.5 + 2.0;
      const double r = 1.5 - (static_cast<double>(q.y()) - 2.0) / 0.5;
      EXPECT_NEAR(c, std::round(c), 1e-6);
      EXPECT_NEAR(q.z(), 3.0 + 0.1 * (10 * std::round(r) + std::round(c)), 1e-5);
    }
    for (const auto& t : m.triangles) EXPECT_GT(faceNormal(m, t).z(), 0.0);
    EXPECT_NEAR(map.height(1.0 - 1.0, 2.0 + 0.75), 3.0 + 0.1 * (10 * 0 + 0), 1e-9);  // corner (c 0, r 0)
  }
}

TEST(Heightmap, NanOrNoDataIsAnErrorNamingFileFieldAndPixel) {
  test::TempDir dir;
  cv::Mat h(3, 3, CV_32FC1, cv::Scalar(1.0f));
  h.at<float>(1, 2) = std::numeric_limits<float>::quiet_NaN();
  io::writeExr(dir.file("nan.exr"), {{"Y", h}});
  HeightmapParams p;
  p.path = "nan.exr";
  p.pixel_size_m = 1.0;
  try {
    Heightmap map(p, dir.path().string(), "scene.yaml:9: sources[2]");
    FAIL();
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("scene.yaml:9: sources[2].path"), std::string::npos) << msg;
    EXPECT_NE(msg.find("nan.exr"), std::string::npos) << msg;
    EXPECT_NE(msg.find("NaN height at pixel (x 2, y 1)"), std::string::npos) << msg;
  }
  p.crop_px = {0, 0, 2, 3};  // crop the hole away
  EXPECT_NO_THROW(Heightmap(p, dir.path().string(), "f"));
  p.crop_px = {0, 0, 4, 3};
  EXPECT_THROW(Heightmap(p, dir.path().string(), "f"), Error);
  p.crop_px.clear();
  p.path = "missing.tif";
  try {
    Heightmap map(p, dir.path().string(), "scene.yaml:9: sources[2]");
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("sources[2].path"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("missing.tif"), std::string::npos) << e.what();
  }
}

TEST(Isosurface, SphereIsClosedOutwardAndOnTheSurface) {
  IsoGrid g;
  g.origin = Vec3(-1.5, -1.5, -1.5);
  g.cell_m = 0.1;
  g.nx = g.ny = g.nz = 31;
  const TriangleMesh m = extractIsosurface(g, [](const Vec3& p) { return 1.0 - p.norm(); });
  EXPECT_NEAR(signedVolume(m), 4.0 / 3.0 * std::numbers::pi, 0.08);
  for (const auto& q : m.positions) EXPECT_NEAR(q.cast<double>().norm(), 1.0, 0.05);
  for (const auto& t : m.triangles) EXPECT_GT(faceNormal(m, t).dot(centroid(m, t)), 0.0);
}

TEST(LavaTube, FacesPointIntoFreeSpaceAndTheMouthIsOpen) {
  TubeParams p;
  p.length_m = 12;
  p.pit_length_m = 10;
  p.pit_width_m = 10;
  p.margin_m = 2;
  p.cell_m = 0.5;
  const LavaTube tube(p, 3, "tube");
  const TriangleMesh m = tube.mesh();
  ASSERT_GT(m.triangles.size(), 1000u);
  int wrong = 0;
  for (const auto& t : m.triangles) {
    const Vec3 c = centroid(m, t), n = faceNormal(m, t).normalized();
    if (tube.freeSpace(c + 0.3 * n) <= tube.freeSpace(c - 0.3 * n)) ++wrong;
  }
  EXPECT_LT(wrong, static_cast<int>(m.triangles.size() / 200));  // < 0.5 % (noisy corners)
  // Free: inside the tube, in the pit, above the surface; rock: above the tube's roof.
  EXPECT_GT(tube.freeSpace(Vec3(6, 0, 2)), 0.0);
  EXPECT_GT(tube.freeSpace(Vec3(-5, 0, 5)), 0.0);
  EXPECT_GT(tube.freeSpace(Vec3(6, 0, 12)), 0.0);
  EXPECT_LT(tube.freeSpace(Vec3(6, 0, 8)), 0.0);
  EXPECT_NEAR(tube.floorHeight(6, 0), 0.0, 0.05);
}

}  // namespace
}  // namespace evio::scenes
