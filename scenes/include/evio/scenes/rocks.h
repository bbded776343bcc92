#pragma once
/// @file rocks.h
/// Scattered rocks: irregular, flattened icospheres resting on a ground.
///
/// Rock k (all numbers from RandomStream(seed, name + "/rocks")):
///   radius R from the cumulative size law N(>R) ∝ R^−k in [r_min, r_max];
///   centre (x, y) uniform in the region; yaw uniform;
///   surface r(ω) = R (1 + a · fbm3(1.5 ω + o_k)) along each unit direction ω
///   of the icosphere, z scaled by `flatten`;
///   a share `embed_fraction` of its height below the lowest ground point
///   under its footprint (so rocks on slopes do not float).

#include <cstdint>
#include <functional>
#include <string>

#include "evio/core/triangle_mesh.h"
#include "evio/scenes/source_options.h"

namespace evio::scenes {

/// Ground height z (m) at world (x, y).
using HeightFunction = std::function<double(double, double)>;

/// Unit icosphere: the icosahedron with every triangle split in 4,
/// `subdivisions` times, vertices pushed onto the unit sphere (outward faces).
TriangleMesh icosphere(int subdivisions);

/// All rocks of a source as one mesh (smooth vertex normals), uv = world (x, y).
/// `ground` may be empty: then the ground is z = base_height_m.
TriangleMesh rocksMesh(const RocksParams& params, std::uint64_t seed, const std::string& name,
                       const HeightFunction& ground);

}  // namespace evio::scenes
