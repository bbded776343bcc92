#pragma once
/// @file scene.h
/// A scene ready to ray-trace: the sources of a SceneDescription turned into
/// world-frame triangle meshes in one Embree 3 scene (built once), with their
/// materials, the lights and, when enabled, the indirect-light cache.
///
/// Embree geometry ID g is meshes()[g]. Light transport at a surface point x
/// with shading normal n, seen from direction ω_o (light_transport in the
/// implementation):
///   L(x, ω_o) = Σ_k V_k · ρ f̂(ω_k, ω_o) · E_k(x) · max(0, n·ω_k)  (sun, point, spot)
///             + ρ/π · E_amb(x)
/// with V_k ∈ {0, 1} from one occlusion ray per light, f̂ = f/ρ the
/// reflectance (material.h), E_k the light's irradiance (light.h) and
/// E_amb = π L_sky (1 + n_z)/2 without indirect light, else the cached
/// irradiance from sky and inter-reflections (irradiance_cache.h),
/// interpolated with the hit's barycentric coordinates.

#include <embree3/rtcore.h>

#include <memory>
#include <string>
#include <vector>

#include "evio/core/eigen_types.h"
#include "evio/core/options.h"
#include "evio/core/triangle_mesh.h"
#include "evio/scenes/material.h"
#include "evio/scenes/scene_description.h"
#include "evio/scenes/texture.h"

namespace evio::scenes {

struct SceneBuildOptions {
  int threads = 0;  ///< threads for the BVH and the indirect-light cache; 0 = all cores
  template <class V>
  void fields(V& v) {
    v("threads", threads, "build threads, 0 = all cores");
  }
  void validate() const { requireInRange("threads", threads, 0, 1024); }
};

/// One source's geometry in the world frame.
struct SceneMesh {
  std::string name;                   ///< the source name
  std::string where;                  ///< "file:line: sources[i]" for messages
  int material = 0;                   ///< index into the scene's materials
  bool solid = true;                  ///< back side is inside matter
  TriangleMesh mesh;                  ///< positions (m), unit vertex normals, uv (m)
  std::vector<Eigen::Vector3f> face_normals;  ///< unit geometric normal per triangle (front side)
};

/// Timings (wall clock, s) and sizes of the build.
struct SceneStats {
  double generate_s = 0.0;   ///< procedural generation and file import
  double bvh_s = 0.0;        ///< Embree BVH build
  double indirect_s = 0.0;   ///< irradiance cache
  std::size_t triangles = 0;
  std::size_t vertices = 0;
  double total_s() const { return generate_s + bvh_s + indirect_s; }
};

/// A ray-surface intersection prepared for shading. Normals are flipped to
/// the side the ray came from.
struct SurfaceHit {
  Eigen::Vector3f p;    ///< world point (m), from the barycentric coordinates
  Eigen::Vector3f n;    ///< unit shading normal (interpolated vertex normals)
  Eigen::Vector3f ng;   ///< unit geometric normal
  Eigen::Vector2f uv;   ///< surface coordinates (m)
  unsigned mesh = 0;    ///< Embree geometry ID = index in meshes()
  unsigned prim = 0;    ///< triangle index
  float b1 = 0.0f;      ///< barycentric weight of the triangle's 2nd vertex
  float b2 = 0.0f;      ///< barycentric weight of the 3rd vertex
  bool back_face = false;  ///< the ray met the back of the triangle
};

/// An occlusion ray towards a light: origin, unit direction, length, and the
/// light's irradiance on a surface facing it at the hit (W/m²).
struct ShadowRay {
  Eigen::Vector3f origin;
  Eigen::Vector3f direction;
  float t_far = 0.0f;
  float e_normal = 0.0f;
};

/// What one light delivers at a hit: the unit direction towards it and its
/// irradiance on a surface facing it (W/m²); 0 when it is blocked or cannot
/// reach the point.
struct LightSample {
  Eigen::Vector3f wi = Eigen::Vector3f::UnitZ();
  float e_normal = 0.0f;
};

class Scene {
 public:
  /// Generates and imports every source, builds the Embree BVH and, if
  /// description.options.indirect.bounces > 0, the irradiance cache. Throws
  /// Error naming the scene file, line and field for bad input.
  explicit Scene(const SceneDescription& description, const SceneBuildOptions& options = {});
  ~Scene();
  Scene(const Scene&) = delete;
  Scene& operator=(const Scene&) = delete;

  RTCScene embree() const { return scene_; }
  const SceneDescription& description() const { return description_; }
  const std::vector<SceneMesh>& meshes() const { return meshes_; }
  const SceneStats& stats() const { return stats_; }
  bool hasIndirect() const { return indirect_on_; }
  /// The irradiance cache: indirect()[mesh][vertex] in W/m² (empty when off).
  const std::vector<std::vector<float>>& indirect() const { return indirect_; }

  /// The surface point of an Embree hit (geomID, primID, u, v) of the ray
  /// org + t·dir.
  SurfaceHit surfaceHit(unsigned geom, unsigned prim, float u, float v,
                        const Eigen::Vector3f& dir) const {
    SurfaceHit h;
    surfaceHit(geom, prim, u, v, dir, &h);
    return h;
  }
  /// The same, written into *hit (no copy; for the renderer's inner loop).
  void surfaceHit(unsigned geom, unsigned prim, float u, float v, const Eigen::Vector3f& dir,
                  SurfaceHit* hit) const;

  /// Albedo ρ at a hit; footprint_m is the pixel size on the surface (m).
  float albedo(const SurfaceHit& hit, float footprint_m) const;

  /// Number of lights that need an occlusion ray (sun, point, spot).
  int shadowLightCount() const { return static_cast<int>(direct_.size()); }

  /// The occlusion ray from `hit` towards shadow light k; false when the
  /// light cannot reach the point (behind the surface, outside a spot cone).
  bool shadowRay(int k, const SurfaceHit& hit, ShadowRay* ray) const;

  /// Radiance (W/(m²·sr)) leaving `hit` towards `to_viewer` (unit), given the
  /// albedo and one LightSample per shadow light (e_normal = 0 when the
  /// light's occlusion ray was blocked or shadowRay returned false).
  float radiance(const SurfaceHit& hit, const Eigen::Vector3f& to_viewer, float albedo,
                 const LightSample* lights) const;

  /// Radiance of a ray that leaves the scene in direction `dir`: the sky
  /// radiance upwards (dir_z > 0), 0 otherwise. The sun disc is not drawn.
  float background(const Eigen::Vector3f& dir) const;

  /// Irradiance (W/m²) from lights k at a hit, without the reflectance:
  /// Σ_k V_k E_k max(0, n·ω_k), occlusion traced with single rays.
  float directIrradiance(const SurfaceHit& hit) const;

  /// Indirect irradiance at a hit interpolated from per-vertex values
  /// `cache[mesh][vertex]` (W/m²); 0 when the cache is empty.
  float interpolate(const SurfaceHit& hit, const std::vector<std::vector<float>>& cache) const;

  /// Throws Error naming the source (file:line) when the point p_W lies
  /// inside a solid source: of 64 fixed rays from p_W (a Fibonacci sphere),
  /// more than half of those that hit anything first meet the back of that
  /// source's surface (inside a closed solid all do; below a terrain all
  /// upward rays do and the others escape).
  void checkViewpoint(const Vec3& p_W) const;

 private:
  struct DirectLight {
    int kind;                  // 0 sun, 1 point, 2 spot
    Eigen::Vector3f vec;       // sun: unit direction to it; else position
    float power;               // sun: irradiance W/m²; else intensity W/sr
    Eigen::Vector3f axis;      // spot: unit axis
    float cos_inner, cos_outer;
  };
  struct MaterialData {
    Reflectance reflectance;
    std::unique_ptr<Texture> texture;
  };
  void generate(const SceneBuildOptions& options);
  void buildEmbree(const SceneBuildOptions& options);
  void lightFrom(const SurfaceHit& hit, int k, Eigen::Vector3f* wi, float* e_normal) const;

  SceneDescription description_;
  std::vector<SceneMesh> meshes_;
  std::vector<MaterialData> materials_;
  std::vector<DirectLight> direct_;
  float sky_radiance_ = 0.0f;
  bool indirect_on_ = false;
  std::vector<std::vector<float>> indirect_;
  SceneStats stats_;
  RTCDevice device_ = nullptr;
  RTCScene scene_ = nullptr;
};

}  // namespace evio::scenes
