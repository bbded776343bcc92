#include "evio/scenes/terrain.h"

#include <algorithm>
#include <cmath>

#include "evio/core/random_stream.h"
#include "evio/scenes/mesh_ops.h"
#include "evio/scenes/noise.h"

namespace evio::scenes {

TerrainField::TerrainField(const TerrainParams& params, std::uint64_t seed, const std::string& name)
    : params_(params), noise_seed_(static_cast<std::uint32_t>(streamSeed(seed, name + "/relief"))) {
  RandomStream rng(seed, name + "/craters");
  const double rmin = params.crater_radius_m.x(), rmax = params.crater_radius_m.y();
  const double k = 2.0;  // cumulative exponent
  const double q = std::pow(rmin / rmax, k);
  for (int i = 0; i < params.crater_count; ++i) {
    Crater c;
    // Inverse CDF of N(>R) ∝ R^-k truncated to [rmin, rmax].
    const double u = rng.uniform();
    c.radius = rmin * std::pow(1.0 - u * (1.0 - q), -1.0 / k);
    c.x = params.position_m.x() + rng.uniform(-0.5, 0.5) * params.size_m.x();
    c.y = params.position_m.y() + rng.uniform(-0.5, 0.5) * params.size_m.y();
    c.depth = 2.0 * c.radius * params.crater_depth_ratio * rng.uniform(0.6, 1.0);  // degraded ones shallower
    c.rim = params.crater_rim_ratio * c.depth;
    craters_.push_back(c);
  }
}

double TerrainField::height(double x, double y) const {
  const double lx = (x - params_.position_m.x()) / params_.wavelength_m;
  const double ly = (y - params_.position_m.y()) / params_.wavelength_m;
  double z = params_.position_m.z() +
             params_.amplitude_m * noise::fbm2(lx, ly, params_.octaves, params_.gain, noise_seed_);
  for (const Crater& c : craters_) {
    const double dx = x - c.x, dy = y - c.y;
    const double r2 = dx * dx + dy * dy;
    if (r2 >= 16.0 * c.radius * c.radius) continue;
    const double rho = std::sqrt(r2) / c.radius;
    if (rho < 1.0) {
      z += (c.depth + c.rim) * rho * rho - c.depth;
    } else {
      const double t = std::clamp(4.0 - rho, 0.0, 1.0);  // 1 at ρ <= 3, 0 at ρ = 4
      z += c.rim / (rho * rho * rho) * t * t * (3.0 - 2.0 * t);
    }
  }
  return z;
}

TriangleMesh terrainMesh(const TerrainParams& params, const TerrainField& field) {
  const int nx = std::max(2, static_cast<int>(std::round(params.size_m.x() / params.cell_m)) + 1);
  const int ny = std::max(2, static_cast<int>(std::round(params.size_m.y() / params.cell_m)) + 1);
  const double x0 = params.position_m.x() - 0.5 * params.size_m.x();
  const double y0 = params.position_m.y() - 0.5 * params.size_m.y();
  const double dx = params.size_m.x() / (nx - 1), dy = params.size_m.y() / (ny - 1);
  TriangleMesh m = gridMesh(
      nx, ny,
      [&](int i, int j) {
        const double x = x0 + i * dx, y = y0 + j * dy;
        return Eigen::Vector3f(static_cast<float>(x), static_cast<float>(y),
                               static_cast<float>(field.height(x, y)));
      },
      [&](int i, int j) {
        return Eigen::Vector2f(static_cast<float>(x0 + i * dx), static_cast<float>(y0 + j * dy));
      });
  computeVertexNormals(m);
  return m;
}

}  // namespace evio::scenes
