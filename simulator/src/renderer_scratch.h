#pragma once
// Private to the simulator module: the per-thread buffers of one tile,
// reused from tile to tile (renderer.cpp, renderer_avx2.cpp).

#include <embree3/rtcore.h>
#include <tbb/enumerable_thread_specific.h>

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "evio/scenes/scene.h"
#include "evio/simulator/renderer.h"

namespace evio::simulator {

/// Per-thread buffers of one tile, reused from tile to tile.
/// One light's occlusion-ray origins and lengths per ray (the AVX2 path).
struct ShadowColumns {
  std::vector<float> x, y, z, t_far;
};

struct Renderer::Scratch {
  std::vector<RTCRayHit> rays;
  std::vector<Eigen::Vector3f> dirs;
  std::vector<scenes::SurfaceHit> hits;
  std::vector<float> albedo;
  std::vector<scenes::LightSample> light;
  std::vector<RTCRay> shadow;
  std::vector<std::uint32_t> shadow_slot;
  // The AVX2 albedo pass: footprints, materials, and the shaded rays
  // grouped by material.
  std::vector<float> footprint;
  std::vector<int> material;
  std::vector<std::uint32_t> by_material;
  std::vector<std::uint32_t> material_start;  ///< first entry of each material in by_material (+ the end)
  std::vector<std::uint32_t> material_fill;
  // The 8-lane path (renderer_avx2.cpp): directions, hits and light samples
  // as columns, and the radiance of each ray.
  std::vector<float> dx, dy, dz;
  std::vector<float> bz;  ///< z of the pixel's bearing in C (NaN: no ray), for the depth
  scenes::SurfaceHitColumns columns;
  std::vector<scenes::LightColumns> light_columns;
  std::vector<ShadowColumns> shadow_origin;  ///< per light
  std::vector<std::uint8_t> shadow_need;     ///< per light and group of eight: the rays that need an occlusion ray
  std::vector<float> radiance;
  std::vector<std::uint8_t> hit_mask;  ///< per group of eight rays: bit j = ray 8 g + j hit a surface
};

struct Renderer::ScratchPool {
  tbb::enumerable_thread_specific<Scratch> local;
};

}  // namespace evio::simulator
