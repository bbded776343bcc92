#include "evio/scenes/scene.h"

#include <tbb/task_arena.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <numbers>
#include <sstream>

#include "evio/core/error.h"
#include "evio/core/io/mesh_file.h"
#include "evio/core/random_stream.h"
#include "evio/core/stopwatch.h"
#include "evio/scenes/embree_util.h"
#include "evio/scenes/heightmap.h"
#include "evio/scenes/irradiance_cache.h"
#include "evio/scenes/lava_tube.h"
#include "evio/scenes/mesh_ops.h"
#include "evio/scenes/primitives.h"
#include "evio/scenes/rocks.h"
#include "evio/scenes/terrain.h"

namespace evio::scenes {

namespace {

tbb::task_arena makeArena(int threads) {
  return threads > 0 ? tbb::task_arena(threads) : tbb::task_arena();
}

std::string show(const Vec3& p) {
  std::ostringstream s;
  s.precision(6);
  s << "(" << p.x() << ", " << p.y() << ", " << p.z() << ")";
  return s.str();
}

}  // namespace

Scene::Scene(const SceneDescription& description, const SceneBuildOptions& options)
    : description_(description) {
  options.validate();
  const auto& o = description_.options;
  // Materials.
  for (std::size_t i = 0; i < o.materials.size(); ++i) {
    const auto& m = o.materials[i];
    const std::string where =
        i < description_.material_where.size() ? description_.material_where[i] : "materials[" + std::to_string(i) + "]";
    MaterialData data;
    data.reflectance = Reflectance(m);
    data.texture = std::make_unique<Texture>(m.albedo, streamSeed(o.seed, "material/" + m.name),
                                             description_.base_dir, where + ".albedo");
    oren_nayar_.push_back(data.reflectance.orenNayar() ? 1 : 0);
    on_a_.push_back(data.reflectance.a());
    on_b_.push_back(data.reflectance.b());
    materials_.push_back(std::move(data));
  }
  // Lights.
  for (const auto& l : o.lights) {
    if (l.type == "sky") {
      sky_radiance_ = static_cast<float>(l.radiance_w_m2_sr);
      continue;
    }
    DirectLight d{};
    if (l.type == "sun") {
      d.kind = 0;
      d.vec = sunDirection(l.azimuth_deg, l.elevation_deg).cast<float>();
      d.power = static_cast<float>(l.irradiance_w_m2);
    } else {
      d.kind = l.type == "point" ? 1 : 2;
      d.vec = l.position_m.cast<float>();
      d.power = static_cast<float>(l.intensity_w_sr);
      if (d.kind == 2) {
        d.axis = (l.target_m - l.position_m).normalized().cast<float>();
        d.cos_inner = static_cast<float>(std::cos(l.inner_angle_deg * std::numbers::pi / 180.0));
        d.cos_outer = static_cast<float>(std::cos(l.outer_angle_deg * std::numbers::pi / 180.0));
      }
    }
    direct_.push_back(d);
  }
  Stopwatch watch;
  generate(options);
  stats_.generate_s = watch.seconds();
  watch.restart();
  buildEmbree(options);
  buildShadeMeshes();
  stats_.bvh_s = watch.seconds();
  if (o.indirect.bounces > 0) {
    watch.restart();
    indirect_ = computeIrradianceCache(*this, o.indirect, o.seed, options.threads);
    indirect_on_ = true;
    stats_.indirect_s = watch.seconds();
  }
}

Scene::~Scene() {
  if (scene_) rtcReleaseScene(scene_);
  if (device_) rtcReleaseDevice(device_);
}

void Scene::generate(const SceneBuildOptions& /*options*/) {
  const auto& o = description_.options;
  std::map<std::string, std::shared_ptr<TerrainField>> terrains;
  std::map<std::string, std::shared_ptr<Heightmap>> heightmaps;
  std::map<std::string, std::shared_ptr<LavaTube>> tubes;
  for (std::size_t i = 0; i < o.sources.size(); ++i) {
    const SourceOptions& s = o.sources[i];
    SceneMesh sm;
    sm.name = s.name;
    sm.where = i < description_.source_where.size() ? description_.source_where[i]
                                                     : "sources[" + std::to_string(i) + "]";
    sm.solid = s.solid;
    for (std::size_t m = 0; m < o.materials.size(); ++m)
      if (o.materials[m].name == s.material) sm.material = static_cast<int>(m);
    if (s.type == "plane") {
      sm.mesh = planeMesh(s.plane);
    } else if (s.type == "box") {
      sm.mesh = boxMesh(s.box);
    } else if (s.type == "terrain") {
      auto field = std::make_shared<TerrainField>(s.terrain, o.seed, s.name);
      sm.mesh = terrainMesh(s.terrain, *field);
      terrains[s.name] = field;
    } else if (s.type == "heightmap") {
      auto map = std::make_shared<Heightmap>(s.heightmap, description_.base_dir, sm.where);
      sm.mesh = map->mesh();
      heightmaps[s.name] = map;
    } else if (s.type == "tube") {
      auto tube = std::make_shared<LavaTube>(s.tube, o.seed, s.name);
      sm.mesh = tube->mesh();
      tubes[s.name] = tube;
    } else if (s.type == "rocks") {
      HeightFunction ground;
      const std::string& g = s.rocks.ground;
      if (terrains.count(g)) {
        auto f = terrains[g];
        ground = [f](double x, double y) { return f->height(x, y); };
      } else if (heightmaps.count(g)) {
        auto f = heightmaps[g];
        ground = [f](double x, double y) { return f->height(x, y); };
      } else if (tubes.count(g)) {
        auto f = tubes[g];
        ground = [f](double x, double y) { return f->floorHeight(x, y); };
      }
      sm.mesh = rocksMesh(s.rocks, o.seed, s.name, ground);
    } else if (s.type == "mesh") {
      std::filesystem::path path(s.mesh.path);
      if (path.is_relative() && !description_.base_dir.empty())
        path = std::filesystem::path(description_.base_dir) / path;
      try {
        sm.mesh = io::readMesh(path.string());
      } catch (const Error& e) {
        throw Error(sm.where + ".path: " + e.what());
      }
      for (const auto& p : sm.mesh.positions)
        if (!p.allFinite()) throw Error(sm.where + ".path: " + path.string() + ": non-finite vertex");
      for (auto& uv : sm.mesh.uvs) uv *= static_cast<float>(s.mesh.uv_size_m);
      if (sm.mesh.normals.empty()) computeVertexNormals(sm.mesh);
      transformMesh(sm.mesh, rotationFromRpyDeg(s.mesh.rotation_deg), s.mesh.position_m, s.mesh.scale);
    } else {
      throw Error(sm.where + ".type: unknown source type '" + s.type + "' (known: " +
                  SourceOptions::knownTypes() + ")");
    }
    if (sm.mesh.normals.size() != sm.mesh.positions.size()) computeVertexNormals(sm.mesh);
    if (sm.mesh.uvs.size() != sm.mesh.positions.size()) {
      sm.mesh.uvs.resize(sm.mesh.positions.size());
      for (std::size_t k = 0; k < sm.mesh.positions.size(); ++k) sm.mesh.uvs[k] = sm.mesh.positions[k].head<2>();
    }
    sm.face_normals.reserve(sm.mesh.triangles.size());
    for (const auto& t : sm.mesh.triangles) {
      const Eigen::Vector3f& p0 = sm.mesh.positions[static_cast<std::size_t>(t[0])];
      const Eigen::Vector3f n = (sm.mesh.positions[static_cast<std::size_t>(t[1])] - p0)
                                    .cross(sm.mesh.positions[static_cast<std::size_t>(t[2])] - p0);
      const float len = n.norm();
      sm.face_normals.push_back(len > 0.0f ? Eigen::Vector3f(n / len) : Eigen::Vector3f::Zero());
    }
    stats_.triangles += sm.mesh.triangles.size();
    stats_.vertices += sm.mesh.positions.size();
    meshes_.push_back(std::move(sm));
  }
}

void Scene::buildShadeMeshes() {
  shade_.resize(meshes_.size());
  for (std::size_t g = 0; g < meshes_.size(); ++g) {
    const TriangleMesh& m = meshes_[g].mesh;  // indices checked by buildEmbree
    ShadeMesh& s = shade_[g];
    s.vertices.resize(m.positions.size());
    for (std::size_t i = 0; i < m.positions.size(); ++i)
      s.vertices[i] = ShadeVertex{m.positions[i], m.normals[i], m.uvs[i]};
    s.triangles.resize(m.triangles.size());
    for (std::size_t i = 0; i < m.triangles.size(); ++i) {
      const Eigen::Vector3i& t = m.triangles[i];
      s.triangles[i] = ShadeTriangle{meshes_[g].face_normals[i],
                                     {static_cast<std::uint32_t>(t[0]), static_cast<std::uint32_t>(t[1]),
                                      static_cast<std::uint32_t>(t[2])}};
    }
  }
}

void Scene::buildEmbree(const SceneBuildOptions& options) {
  device_ = rtcNewDevice(nullptr);
  if (!device_) throw Error("Embree: cannot create a device (error " + std::to_string(rtcGetDeviceError(nullptr)) + ")");
  scene_ = rtcNewScene(device_);
  // Robust mode: watertight edges (no rays leaking between triangles, which
  // would flicker into false events).
  rtcSetSceneFlags(scene_, RTC_SCENE_FLAG_ROBUST);
  rtcSetSceneBuildQuality(scene_, RTC_BUILD_QUALITY_HIGH);
  for (std::size_t g = 0; g < meshes_.size(); ++g) {
    const TriangleMesh& m = meshes_[g].mesh;
    if (m.triangles.empty()) continue;
    RTCGeometry geom = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                          3 * sizeof(float), m.positions.size()));
    auto* t = static_cast<unsigned*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                             3 * sizeof(unsigned), m.triangles.size()));
    if (!v || !t) {
      rtcReleaseGeometry(geom);
      throw Error(meshes_[g].where + ": Embree could not allocate the geometry buffers");
    }
    for (std::size_t i = 0; i < m.positions.size(); ++i)
      for (int k = 0; k < 3; ++k) v[3 * i + static_cast<std::size_t>(k)] = m.positions[i][k];
    const auto nv = static_cast<int>(m.positions.size());
    for (std::size_t i = 0; i < m.triangles.size(); ++i)
      for (int k = 0; k < 3; ++k) {
        const int idx = m.triangles[i][k];
        if (idx < 0 || idx >= nv) {
          rtcReleaseGeometry(geom);
          throw Error(meshes_[g].where + ": triangle " + std::to_string(i) + " has a bad vertex index");
        }
        t[3 * i + static_cast<std::size_t>(k)] = static_cast<unsigned>(idx);
      }
    rtcCommitGeometry(geom);
    rtcAttachGeometryByID(scene_, geom, static_cast<unsigned>(g));
    rtcReleaseGeometry(geom);
  }
  tbb::task_arena arena = makeArena(options.threads);
  arena.execute([&] { rtcCommitScene(scene_); });
  const RTCError e = rtcGetDeviceError(device_);
  if (e != RTC_ERROR_NONE) throw Error("Embree: building the scene failed (error " + std::to_string(e) + ")");
}

float Scene::directIrradiance(const SurfaceHit& hit) const {
  float e_sum = 0.0f;
  for (int k = 0; k < static_cast<int>(direct_.size()); ++k) {
    ShadowRay s;
    if (!shadowRay(k, hit, &s)) continue;
    RTCIntersectContext ctx = intersectContext(false);
    RTCRay ray;
    setRay(ray, s.origin, s.direction, 0.0f, s.t_far);
    rtcOccluded1(scene_, &ctx, &ray);
    if (ray.tfar < 0.0f) continue;  // occluded: Embree sets tfar to -inf
    Eigen::Vector3f wi;
    float e = 0.0f;
    lightFrom(hit, k, &wi, &e);
    e_sum += e * hit.n.dot(wi);
  }
  return e_sum;
}

void Scene::checkViewpoint(const Vec3& p_W) const {
  if (!p_W.allFinite()) throw Error("camera position " + show(p_W) + " is not finite");
  constexpr int kRays = 64;
  const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
  RTCIntersectContext ctx = intersectContext(false);
  // Count, per solid source, the probe rays whose first hit is the back of
  // its surface. Inside a solid most hits are; outside, only a ray grazing a
  // tiny fold of an extracted surface could be, so a majority is required.
  std::vector<int> back(meshes_.size(), 0);
  int hits = 0;
  double nearest_back = std::numeric_limits<double>::infinity();
  for (int i = 0; i < kRays; ++i) {
    // Fibonacci sphere: evenly spread fixed directions.
    const double z = 1.0 - (2.0 * i + 1.0) / kRays;
    const double r = std::sqrt(1.0 - z * z);
    const Eigen::Vector3f dir(static_cast<float>(r * std::cos(golden * i)),
                              static_cast<float>(r * std::sin(golden * i)), static_cast<float>(z));
    RTCRayHit rh;
    setRayHit(rh, p_W.cast<float>(), dir);
    rtcIntersect1(scene_, &ctx, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) continue;
    ++hits;
    if (!meshes_[rh.hit.geomID].solid) continue;
    const SurfaceHit h = surfaceHit(rh.hit.geomID, rh.hit.primID, rh.hit.u, rh.hit.v, dir);
    if (!h.back_face) continue;
    ++back[rh.hit.geomID];
    nearest_back = std::min(nearest_back, static_cast<double>(rh.ray.tfar));
  }
  for (std::size_t g = 0; g < meshes_.size(); ++g)
    if (back[g] > 0 && 2 * back[g] > hits) {
      const SceneMesh& m = meshes_[g];
      throw Error(m.where + ": the camera at " + show(p_W) + " m is inside solid source '" + m.name +
                  "' (" + std::to_string(back[g]) + " of " + std::to_string(hits) +
                  " probe rays see the back of its surface, the nearest " + std::to_string(nearest_back) +
                  " m away); move the camera or set `solid: false` on a thin sheet");
    }
}

}  // namespace evio::scenes
