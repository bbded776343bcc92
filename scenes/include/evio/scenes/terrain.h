#pragma once
/// @file terrain.h
/// Procedural Mars-like terrain: fractal relief plus craters.
///
/// Height (z, m) at world (x, y), with (x', y') = (x, y) − position:
///   z = position_z + A · fbm2(x'/λ, y'/λ) + Σ_craters c(r / R)
/// (noise.h for fbm2; A = amplitude_m, λ = wavelength_m). A crater of radius
/// R, depth d = 2R · depth_ratio and rim height h = rim_ratio · d has the
/// radial profile (ρ = r / R):
///   c(ρ) = (d + h) ρ² − d              for ρ < 1  (bowl, rim at ρ = 1)
///   c(ρ) = h ρ⁻³ · s(ρ)                 for ρ ≥ 1  (ejecta blanket)
/// with s a smoothstep taper from 1 at ρ = 3 to 0 at ρ = 4. Crater radii
/// follow a cumulative power law N(>R) ∝ R⁻² between the given bounds.
/// Craters and noise derive from (scene seed, source name) only.

#include <cstdint>
#include <string>
#include <vector>

#include "evio/core/triangle_mesh.h"
#include "evio/scenes/source_options.h"

namespace evio::scenes {

class TerrainField {
 public:
  TerrainField(const TerrainParams& params, std::uint64_t seed, const std::string& name);

  /// Terrain height z (m) at world (x, y); defined everywhere (the mesh covers
  /// only the terrain's extent).
  double height(double x, double y) const;

  struct Crater {
    double x, y, radius, depth, rim;
  };
  const std::vector<Crater>& craters() const { return craters_; }

 private:
  TerrainParams params_;
  std::uint32_t noise_seed_;
  std::vector<Crater> craters_;
};

/// The terrain as a grid mesh (front up), uv = world (x, y).
TriangleMesh terrainMesh(const TerrainParams& params, const TerrainField& field);

}  // namespace evio::scenes
