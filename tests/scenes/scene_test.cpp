// The built scene: import errors, the camera-inside check, shading
// ingredients and the deterministic indirect-light cache.
#include "evio/scenes/scene.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <numbers>

#include "evio/core/error.h"
#include "evio/core/io/atomic_file.h"
#include "evio/core/io/mesh_file.h"
#include "evio/scenes/embree_util.h"
#include "temp_dir.h"

namespace evio::scenes {
namespace {

std::string errorOf(const std::string& yaml, const std::string& base_dir = "") {
  try {
    Scene scene(loadSceneString(yaml, "scene.yaml", base_dir));
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

const char* kHeader =
    "materials:\n"                                          // 1
    "  - {name: m, albedo: {type: constant, value: 0.5}}\n"  // 2
    "lights:\n"                                             // 3
    "  - {type: sun, azimuth_deg: 0, elevation_deg: 90, irradiance_w_m2: 590}\n"  // 4
    "sources:\n";                                           // 5

TEST(Scene, MissingMeshFileNamesFileAndField) {
  test::TempDir dir;
  const std::string msg = errorOf(std::string(kHeader) + "  - {type: mesh, material: m, path: rock.obj}\n",
                                  dir.path().string());
  EXPECT_NE(msg.find("scene.yaml:6: sources[0].path"), std::string::npos) << msg;
  EXPECT_NE(msg.find("rock.obj"), std::string::npos) << msg;
}

TEST(Scene, MissingTextureFileNamesFileAndField) {
  test::TempDir dir;
  const std::string msg = errorOf(
      "materials:\n  - name: m\n    albedo: {type: image, path: poster.png}\n"
      "lights:\n  - {type: sky, radiance_w_m2_sr: 1}\nsources:\n  - {type: plane, material: m}\n",
      dir.path().string());
  EXPECT_NE(msg.find("scene.yaml:2: materials[0].albedo.path"), std::string::npos) << msg;
  EXPECT_NE(msg.find("poster.png"), std::string::npos) << msg;
}

TEST(Scene, MeshImportIsPlacedAndUvScaled) {
  test::TempDir dir;
  TriangleMesh tri;
  tri.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  tri.uvs = {{0, 0}, {1, 0}, {0, 1}};
  tri.triangles = {{0, 1, 2}};
  io::writePly(dir.file("tri.ply"), tri);
  const Scene scene(loadSceneString(std::string(kHeader) +
                                        "  - {type: mesh, material: m, path: tri.ply, scale: 2, "
                                        "position_m: [1, 2, 3], rotation_deg: [0, 0, 90], uv_size_m: 0.5}\n",
                                    "scene.yaml", dir.path().string()));
  const TriangleMesh& m = scene.meshes()[0].mesh;
  EXPECT_NEAR((m.positions[1] - Eigen::Vector3f(1, 4, 3)).norm(), 0.0f, 1e-6f);  // (2,0,0) turned by 90°
  EXPECT_EQ(m.uvs[1], Eigen::Vector2f(0.5f, 0.0f));
  EXPECT_NEAR((m.normals[0] - Eigen::Vector3f::UnitZ()).norm(), 0.0f, 1e-6f);
}

TEST(Scene, CameraInsideSolidGeometryIsAnError) {
  const Scene scene(loadSceneString(std::string(kHeader) +
                                        "  - {type: plane, material: m, size_m: [20, 20]}\n"
                                        "  - {type: box, name: crate, material: m, position_m: [0, 0, 1], size_m: [1, 1, 1]}\n",
                                    "scene.yaml"));
  EXPECT_NO_THROW(scene.checkViewpoint(Vec3(3, 0, 1)));
  try {
    scene.checkViewpoint(Vec3(0.1, 0.2, 1.1));
    FAIL();
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("scene.yaml:7: sources[1]"), std::string::npos) << msg;
    EXPECT_NE(msg.find("inside solid source 'crate'"), std::string::npos) << msg;
  }
  EXPECT_THROW(scene.checkViewpoint(Vec3(3, 0, -1)), Error);  // below the ground plane
}

TEST(Scene, NonSolidSheetMayBeSeenFromBehind) {
  const Scene scene(loadSceneString(std::string(kHeader) + "  - {type: plane, material: m, solid: false}\n",
                                    "scene.yaml"));
  EXPECT_NO_THROW(scene.checkViewpoint(Vec3(0, 0, -1)));
}

/// A small plate 1 m above a large sunlit floor sees, on its lower face,
/// the floor's radiance L_f over almost the whole hemisphere:
///   E = π L_f · F,  F = view factor of the square floor from the plate,
/// F = 4 · (1/2π)(A/√(1+A²) atan(B/√(1+A²)) + B/√(1+B²) atan(A/√(1+B²))),
/// A = B = half size / height (the corner formula applied to four quadrants).
TEST(IrradianceCache, OneBounceUnderAPlateMatchesTheViewFactor) {
  const double half = 10.0, h = 1.0, rho_f = 0.4, e_sun = 590.0, elev = 60.0;
  const std::string yaml =
      "indirect: {bounces: 1, directions: 1024}\n"
      "materials:\n"
      "  - {name: floor, albedo: {type: constant, value: 0.4}}\n"
      "  - {name: plate, albedo: {type: constant, value: 0.3}}\n"
      "lights:\n"
      "  - {type: sun, azimuth_deg: 30, elevation_deg: 60, irradiance_w_m2: 590}\n"
      "sources:\n"
      "  - {type: plane, material: floor, size_m: [20, 20]}\n"
      "  - {type: box, material: plate, position_m: [0, 0, 1.005], size_m: [0.1, 0.1, 0.01]}\n";
  SceneBuildOptions one_thread;
  one_thread.threads = 1;
  const Scene scene(loadSceneString(yaml, "scene.yaml"), one_thread);
  ASSERT_TRUE(scene.hasIndirect());
  const double A = half / h;
  const double corner = (A / std::sqrt(1 + A * A) * std::atan(A / std::sqrt(1 + A * A))) * 2.0 / (2.0 * std::numbers::pi);
  const double F = 4.0 * corner;
  const double l_floor = rho_f * e_sun * std::sin(elev * std::numbers::pi / 180.0) / std::numbers::pi;
  const double expected = std::numbers::pi * l_floor * F;
  // The plate's bottom face: vertices with normal -z.
  const auto& plate = scene.meshes()[1].mesh;
  int checked = 0;
  for (std::size_t v = 0; v < plate.positions.size(); ++v) {
    if (plate.normals[v].z() > -0.99f) continue;
    // 1024 cosine-distributed directions; the plate's own shadow on the floor
    // (0.01 m² of 400 m²) and the quadrature error stay below 1.5 %.
    EXPECT_NEAR(scene.indirect()[1][v], expected, 0.015 * expected);
    ++checked;
  }
  EXPECT_EQ(checked, 4);

  // Same cache with two threads, bit for bit.
  SceneBuildOptions two;
  two.threads = 2;
  const Scene again(loadSceneString(yaml, "scene.yaml"), two);
  for (std::size_t m = 0; m < scene.indirect().size(); ++m)
    EXPECT_EQ(0, std::memcmp(scene.indirect()[m].data(), again.indirect()[m].data(),
                             scene.indirect()[m].size() * sizeof(float)));
}

TEST(Scene, SurfaceHitFromEmbree) {
  const Scene scene(loadSceneString(std::string(kHeader) + "  - {type: plane, material: m, position_m: [0, 0, 0.5]}\n",
                                    "scene.yaml"));
  RTCIntersectContext ctx = intersectContext(false);
  RTCRayHit rh;
  const Eigen::Vector3f dir = Eigen::Vector3f(0.3f, -0.2f, -1.0f).normalized();
  setRayHit(rh, Eigen::Vector3f(0.1f, 0.2f, 2.5f), dir);
  rtcIntersect1(scene.embree(), &ctx, &rh);
  ASSERT_NE(rh.hit.geomID, RTC_INVALID_GEOMETRY_ID);
  const SurfaceHit h = scene.surfaceHit(rh.hit.geomID, rh.hit.primID, rh.hit.u, rh.hit.v, dir);
  const Eigen::Vector3f expected = Eigen::Vector3f(0.1f, 0.2f, 2.5f) + (2.0f / -dir.z()) * dir;
  EXPECT_NEAR((h.p - expected).norm(), 0.0f, 1e-5f);
  EXPECT_NEAR(rh.ray.tfar, 2.0f / -dir.z(), 1e-5f);
  EXPECT_EQ(h.n, Eigen::Vector3f::UnitZ());
  EXPECT_FALSE(h.back_face);
  EXPECT_FLOAT_EQ(scene.albedo(h, 0.01f), 0.5f);
}

}  // namespace
}  // namespace evio::scenes
