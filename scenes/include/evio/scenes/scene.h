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

#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <numbers>
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
  double bvh_s = 0.0;        ///< Embree BVH build and the interleaved shading copy of the meshes
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

/// Surface hits as columns, ray r in entry r (the renderer's AVX2 path):
/// the fields of SurfaceHit, meaningless where the ray missed. Sized in
/// whole groups of eight.
struct SurfaceHitColumns {
  std::vector<float> px, py, pz;  ///< world point (m)
  std::vector<float> nx, ny, nz;  ///< unit shading normal
  std::vector<float> gx, gy, gz;  ///< unit geometric normal
  std::vector<float> u, v;        ///< surface coordinates (m)
  std::vector<float> b1, b2;      ///< barycentric weights of the 2nd and 3rd vertex
  std::vector<std::uint32_t> mesh, prim;
  void resize(std::size_t n) {
    for (auto* c : {&px, &py, &pz, &nx, &ny, &nz, &gx, &gy, &gz, &u, &v, &b1, &b2}) c->resize(n);
    mesh.resize(n);
    prim.resize(n);
  }
};

/// One shadow light's samples as columns, ray r in entry r (the renderer's
/// AVX2 path): LightSample's fields.
struct LightColumns {
  std::vector<float> wx, wy, wz;  ///< unit direction to the light
  std::vector<float> e;           ///< irradiance on a surface facing it (W/m²); 0 blocked or unreachable
  void resize(std::size_t n) {
    for (auto* c : {&wx, &wy, &wz, &e}) c->resize(n);
  }
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

  /// Cache hints for a later surfaceHit(geom, prim, ...) on a large mesh:
  /// stage 0 fetches the triangle's record, stage 1 (issued some hits after
  /// stage 0, when the record has arrived) its three vertices. No effect on
  /// results.
  void prefetchHit(unsigned geom, unsigned prim, int stage) const;

  /// Albedo ρ at a hit; footprint_m is the pixel size on the surface (m).
  float albedo(const SurfaceHit& hit, float footprint_m) const;

  /// The material index of mesh `mesh`, and the number of materials.
  int materialOf(unsigned mesh) const { return meshes_[mesh].material; }
  int materialCount() const { return static_cast<int>(materials_.size()); }
  /// albedo() of eight hits of one material, given their points p_W, surface
  /// coordinates uv (m) and footprints as columns, with AVX2 across the hits
  /// (only on a CPU that has it): bit for bit albedo()'s values.
  void albedo8Avx2(int material, const float* px, const float* py, const float* pz, const float* u, const float* v,
                   const float* footprint_m, float* out) const {
    materials_[static_cast<std::size_t>(material)].texture->evaluate8Avx2(px, py, pz, u, v, footprint_m, out);
  }

  // The 8-lane (AVX2) shading functions: each works on entries [at, at + 8)
  // of its columns and is, lane by lane, its scalar counterpart bit for bit
  // (the same float operations in the same order, no FMA). Only on a CPU
  // with AVX2. Test: Renderer.Avx2PathRendersTheSameBitsAsTheBaselinePath.

  /// surfaceHit() of rays[at .. at + 8) whose directions are (dx, dy, dz);
  /// returns the mask of lanes whose ray hit (bit j = lane j); the others'
  /// entries are meaningless.
  int surfaceHits8Avx2(const RTCRayHit* rays, const float* dx, const float* dy, const float* dz, std::size_t at,
                        SurfaceHitColumns* hits) const;
  /// shadowRay(k, ·) of eight hits: the light sample (direction, and the
  /// irradiance, 0 where shadowRay returns false), the ray origin and t_far;
  /// returns the mask of lanes that need an occlusion ray (bit j = lane j).
  int shadowRays8Avx2(int k, const SurfaceHitColumns& hits, std::size_t at, LightColumns* light, float* ox,
                      float* oy, float* oz, float* t_far) const;
  /// radiance() of eight hits seen along (dx, dy, dz) (to_viewer = −d),
  /// given their material indices, albedos and one LightColumns per shadow
  /// light; only the lanes in mask `lanes` are hits (the others' results are
  /// meaningless).
  void radiance8Avx2(const SurfaceHitColumns& hits, const int* material, const float* dx, const float* dy,
                     const float* dz, const float* albedo, const LightColumns* lights, std::size_t at, int lanes,
                     float* out) const;

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
  /// The data surfaceHit reads, interleaved so that a hit touches one
  /// cache line per vertex and one per triangle (a copy of meshes_).
  struct alignas(32) ShadeVertex {
    Eigen::Vector3f p;   ///< position (m)
    Eigen::Vector3f n;   ///< unit vertex normal
    Eigen::Vector2f uv;  ///< surface coordinates (m)
  };
  struct alignas(32) ShadeTriangle {  ///< 32 bytes: the 8-lane path loads one per register
    Eigen::Vector3f ng;  ///< unit face normal (0 for a degenerate triangle)
    std::uint32_t v[3];  ///< vertex indices
  };
  struct ShadeMesh {
    std::vector<ShadeVertex> vertices;
    std::vector<ShadeTriangle> triangles;
  };
  void generate(const SceneBuildOptions& options);
  void buildEmbree(const SceneBuildOptions& options);
  void buildShadeMeshes();
  void lightFrom(const SurfaceHit& hit, int k, Eigen::Vector3f* wi, float* e_normal) const;

  SceneDescription description_;
  std::vector<SceneMesh> meshes_;
  std::vector<ShadeMesh> shade_;  ///< shade_[g] mirrors meshes_[g]
  std::vector<MaterialData> materials_;
  /// Per material, for radiance8Avx2: Oren–Nayar on (1/0), A and B.
  std::vector<int> oren_nayar_;
  std::vector<float> on_a_, on_b_;
  std::vector<DirectLight> direct_;
  float sky_radiance_ = 0.0f;
  bool indirect_on_ = false;
  std::vector<std::vector<float>> indirect_;
  SceneStats stats_;
  RTCDevice device_ = nullptr;
  RTCScene scene_ = nullptr;
};

// The per-pixel functions, inline for the renderer's inner loop.

inline void Scene::surfaceHit(unsigned geom, unsigned prim, float u, float v, const Eigen::Vector3f& dir,
                              SurfaceHit* hit) const {
  const ShadeMesh& sm = shade_[geom];
  const ShadeTriangle& t = sm.triangles[prim];
  const ShadeVertex& a = sm.vertices[t.v[0]];
  const ShadeVertex& b = sm.vertices[t.v[1]];
  const ShadeVertex& c = sm.vertices[t.v[2]];
  const float w0 = 1.0f - u - v;
  SurfaceHit& h = *hit;
  h.mesh = geom;
  h.prim = prim;
  h.b1 = u;
  h.b2 = v;
  h.p = w0 * a.p + u * b.p + v * c.p;
  Eigen::Vector3f ng = t.ng;
  if (ng.x() == 0.0f && ng.y() == 0.0f && ng.z() == 0.0f) ng = -dir;  // degenerate triangle
  Eigen::Vector3f n = w0 * a.n + u * b.n + v * c.n;
  const float nlen2 = n.squaredNorm();
  n = nlen2 > 0.0f ? Eigen::Vector3f(n * (1.0f / std::sqrt(nlen2))) : ng;
  h.back_face = ng.dot(dir) > 0.0f;
  if (h.back_face) {
    ng = -ng;
    n = -n;
  }
  if (n.dot(dir) >= 0.0f) n = ng;  // a shading normal facing away from the viewer
  h.n = n;
  h.ng = ng;
  h.uv = w0 * a.uv + u * b.uv + v * c.uv;
}

inline void Scene::prefetchHit(unsigned geom, unsigned prim, int stage) const {
#if defined(__GNUC__)
  const ShadeMesh& sm = shade_[geom];
  const ShadeTriangle& t = sm.triangles[prim];
  if (stage == 0) {
    __builtin_prefetch(&t);
  } else {
    __builtin_prefetch(&sm.vertices[t.v[0]]);
    __builtin_prefetch(&sm.vertices[t.v[1]]);
    __builtin_prefetch(&sm.vertices[t.v[2]]);
  }
#else
  (void)geom, (void)prim, (void)stage;
#endif
}

inline float Scene::albedo(const SurfaceHit& hit, float footprint_m) const {
  const auto& mat = materials_[static_cast<std::size_t>(meshes_[hit.mesh].material)];
  return mat.texture->evaluate(hit.p, hit.uv, footprint_m);
}

inline void Scene::lightFrom(const SurfaceHit& hit, int k, Eigen::Vector3f* wi, float* e_normal) const {
  const DirectLight& d = direct_[static_cast<std::size_t>(k)];
  if (d.kind == 0) {
    *wi = d.vec;
    *e_normal = d.power;
    return;
  }
  const Eigen::Vector3f to = d.vec - hit.p;
  const float d2 = to.squaredNorm();
  if (!(d2 > 0.0f)) {
    *e_normal = 0.0f;
    *wi = hit.n;
    return;
  }
  *wi = to / std::sqrt(d2);
  float e = d.power / d2;
  if (d.kind == 2) {
    const float c = -wi->dot(d.axis);
    float t = (c - d.cos_outer) / (d.cos_inner - d.cos_outer);
    t = t < 0.0f ? 0.0f : (t > 1.0f ? 1.0f : t);
    e *= t * t * (3.0f - 2.0f * t);
  }
  *e_normal = e;
}

inline bool Scene::shadowRay(int k, const SurfaceHit& hit, ShadowRay* ray) const {
  Eigen::Vector3f wi;
  float e = 0.0f;
  lightFrom(hit, k, &wi, &e);
  if (!(e > 0.0f) || hit.ng.dot(wi) <= 0.0f || hit.n.dot(wi) <= 0.0f) return false;
  const float eps = 5e-5f * (1.0f + hit.p.cwiseAbs().maxCoeff());
  ray->origin = hit.p + eps * hit.ng;
  ray->direction = wi;
  ray->e_normal = e;
  const DirectLight& d = direct_[static_cast<std::size_t>(k)];
  ray->t_far = d.kind == 0 ? std::numeric_limits<float>::infinity()
                           : (d.vec - ray->origin).norm() * (1.0f - 1e-5f);
  return true;
}

inline float Scene::radiance(const SurfaceHit& hit, const Eigen::Vector3f& to_viewer, float albedo,
                      const LightSample* lights) const {
  const Reflectance& refl = materials_[static_cast<std::size_t>(meshes_[hit.mesh].material)].reflectance;
  const float c_o = hit.n.dot(to_viewer);
  float l = 0.0f;
  for (int k = 0; k < static_cast<int>(direct_.size()); ++k) {
    const LightSample& s = lights[k];
    if (!(s.e_normal > 0.0f)) continue;
    const float c_i = hit.n.dot(s.wi);
    if (c_i <= 0.0f) continue;
    l += refl.brdfOverAlbedo(s.wi, to_viewer, c_i, c_o) * s.e_normal * c_i;
  }
  float e_amb;
  if (indirect_on_) e_amb = interpolate(hit, indirect_);
  else e_amb = std::numbers::pi_v<float> * sky_radiance_ * 0.5f * (1.0f + hit.n.z());
  return albedo * (l + e_amb * (1.0f / std::numbers::pi_v<float>));
}

inline float Scene::background(const Eigen::Vector3f& dir) const { return dir.z() > 0.0f ? sky_radiance_ : 0.0f; }

inline float Scene::interpolate(const SurfaceHit& hit, const std::vector<std::vector<float>>& cache) const {
  if (cache.empty()) return 0.0f;
  const auto& values = cache[hit.mesh];
  if (values.empty()) return 0.0f;
  const std::uint32_t* t = shade_[hit.mesh].triangles[hit.prim].v;
  return (1.0f - hit.b1 - hit.b2) * values[t[0]] + hit.b1 * values[t[1]] + hit.b2 * values[t[2]];
}

}  // namespace evio::scenes
