#pragma once
// Private to the simulator module: the per-thread buffers of one tile,
// reused from tile to tile (renderer.cpp, renderer_avx2.cpp).

#include <embree3/rtcore.h>
#include <tbb/enumerable_thread_specific.h>

#include <algorithm>
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
  std::vector<float> bx, by, bz;  ///< the pixel's bearing in C (NaN: no ray), for the depth and the flow
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

/// The rays r < rays with included(r), grouped by their material
/// s.material[r] (a counting sort, in ray order within a material): calls
/// evaluate(m, group, n) for each run of n <= 8 rays group[0 .. n) of
/// material m (the albedo passes' 8-lane texture lookups).
template <class TileScratch, class Included, class Evaluate>
void forMaterialGroups(std::size_t rays, std::size_t materials, TileScratch& s, const Included& included,
                       Evaluate&& evaluate) {
  s.by_material.resize(rays);
  s.material_start.assign(materials + 1, 0);
  for (std::size_t r = 0; r < rays; ++r)
    if (included(r)) ++s.material_start[static_cast<std::size_t>(s.material[r]) + 1];
  for (std::size_t m = 0; m < materials; ++m) s.material_start[m + 1] += s.material_start[m];
  s.material_fill.assign(s.material_start.begin(), s.material_start.end() - 1);
  for (std::size_t r = 0; r < rays; ++r)
    if (included(r))
      s.by_material[s.material_fill[static_cast<std::size_t>(s.material[r])]++] = static_cast<std::uint32_t>(r);
  for (std::size_t m = 0; m < materials; ++m) {
    const std::uint32_t end = s.material_start[m + 1];
    for (std::uint32_t i = s.material_start[m]; i < end; i += 8)
      evaluate(static_cast<int>(m), s.by_material.data() + i, std::min<std::uint32_t>(8, end - i));
  }
}

}  // namespace evio::simulator
