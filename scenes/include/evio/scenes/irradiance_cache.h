#pragma once
/// @file irradiance_cache.h
/// Deterministic indirect light: irradiance from the sky and from
/// inter-reflections, precomputed once per scene on the mesh vertices and
/// interpolated at shading time (Scene::interpolate). No Monte Carlo noise
/// changes between renders: a static scene renders identically every time,
/// whatever the thread count.
///
/// For vertex x with normal n (rays start at x + δn, δ = 5 % of the mean
/// edge length at x), pass b = 1..B computes
///   E_b(x) = π/N Σ_{i=1}^{N} L_{b−1}(x, ω_i)
/// over N fixed cosine-distributed directions ω_i about n (a Hammersley set,
/// turned about n by an angle hashed from x's position so neighbouring
/// vertices use different directions, then the noise averages out over a
/// triangle). L_{b−1} is what the ray x + tω_i meets:
///   nothing, going up        L_sky                       (occluded sky)
///   nothing, going down      0
///   the back of a solid      0                           (x is inside rock)
///   a surface point y        ρ(y)/π · (E_direct(y) + E_{b−1}(y)),  E_0 = 0
/// (Lambertian reflection of direct light — sun, point, spot, with
/// occlusion — and of the previous pass; E_{b−1}(y) interpolated like at
/// shading time). E_B holds the sky and B bounces of light.

#include <cstdint>
#include <vector>

#include "evio/scenes/scene_description.h"

namespace evio::scenes {

class Scene;

/// Computes E_B per vertex of every mesh of `scene` (the BVH must be built):
/// result[mesh][vertex] in W/m². `threads` = 0 uses all cores; the result
/// does not depend on it.
std::vector<std::vector<float>> computeIrradianceCache(const Scene& scene, const IndirectOptions& options,
                                                       std::uint64_t seed, int threads);

}  // namespace evio::scenes
