#include "evio/scenes/lava_tube.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "evio/core/random_stream.h"
#include "evio/scenes/isosurface.h"
#include "evio/scenes/noise.h"

namespace evio::scenes {

LavaTube::LavaTube(const TubeParams& params, std::uint64_t seed, const std::string& name)
    : p_(params),
      seed_(static_cast<std::uint32_t>(streamSeed(seed, name + "/tube"))),
      R_(Eigen::AngleAxisd(params.yaw_deg * std::numbers::pi / 180.0, Vec3::UnitZ()).toRotationMatrix()) {}

double LavaTube::meander(double x) const {
  const auto m = [&](double s) { return noise::fbm2(s / 25.0, 0.5, 2, 0.5, seed_ + 11U); };
  return p_.meander_m * (m(x) - m(0.0));
}

double LavaTube::pitPlan(double x, double y) const {
  const double u = 2.0 * (x + 0.5 * p_.pit_length_m) / p_.pit_length_m;
  const double v = 2.0 * y / p_.pit_width_m;
  const double r = std::pow(std::pow(std::abs(u), 4.0) + std::pow(std::abs(v), 4.0), 0.25);
  return (1.0 - r) * 0.5 * p_.pit_width_m + 0.8 * noise::fbm2(x / 3.0, y / 3.0, 3, 0.5, seed_ + 23U);
}

double LavaTube::pitFloor(double x, double y) const {
  return 0.15 * noise::fbm2(x / 2.0, y / 2.0, 3, 0.5, seed_ + 29U);
}

double LavaTube::tubeFloor(double x, double y) const {
  return 0.04 * noise::fbm2(x / 0.8, y / 0.8, 3, 0.5, seed_ + 13U);
}

double LavaTube::freeSpace(const Vec3& q) const {
  const double x = q.x(), y = q.y(), z = q.z();
  const double air = z - (p_.surface_height_m + p_.surface_relief_m * noise::fbm2(x / 12.0, y / 12.0, 4, 0.5, seed_ + 31U));
  const double pit = std::min(pitPlan(x, y) + 0.12 * z, z - pitFloor(x, y));
  const double a = 0.5 * p_.width_m, b = 0.5 * p_.height_m;
  const double dy = (y - meander(x)) / a, dz = (z - p_.floor_depth_m) / b;
  const double rho = std::sqrt(dy * dy + dz * dz);
  double tube = -1e9;
  if (rho < 2.0) {  // the noise only matters near the wall
    const Eigen::Vector3f probe = (q / p_.roughness_wavelength_m).cast<float>();
    const double g = 1.0 + 1.4 * p_.roughness * static_cast<double>(noise::fbm3(probe, 4, 0.5f, seed_));
    tube = std::min({(g - rho) * std::min(a, b), z - tubeFloor(x, y), p_.length_m - x, x + 3.0});
  }
  return std::max({air, pit, tube});
}

TriangleMesh LavaTube::mesh() const {
  const double c = p_.cell_m;
  const double half_y = std::max(0.5 * p_.pit_width_m, 0.75 * p_.width_m) + p_.margin_m + p_.meander_m;
  const double x0 = -p_.pit_length_m - p_.margin_m, x1 = p_.length_m + 1.0;
  // Grid levels offset from z = 0 so that the flat floors never lie on one.
  const double z0 = -1.0 - 0.377 * c, z1 = p_.surface_height_m + p_.surface_relief_m + 1.0;
  IsoGrid grid;
  grid.cell_m = c;
  grid.origin = Vec3(x0, -half_y, z0);
  grid.nx = static_cast<int>(std::ceil((x1 - x0) / c)) + 1;
  grid.ny = static_cast<int>(std::ceil(2.0 * half_y / c)) + 1;
  grid.nz = static_cast<int>(std::ceil((z1 - z0) / c)) + 1;
  TriangleMesh m = extractIsosurface(grid, [this](const Vec3& q) { return -freeSpace(q); });
  // Local → world.
  const Eigen::Matrix3f Rf = R_.cast<float>();
  for (auto& v : m.positions) v = toWorld(v.cast<double>()).cast<float>();
  for (auto& n : m.normals) n = Rf * n;
  for (std::size_t i = 0; i < m.positions.size(); ++i) m.uvs[i] = m.positions[i].head<2>();
  return m;
}

double LavaTube::floorHeight(double x, double y) const {
  const Vec3 q = R_.transpose() * (Vec3(x, y, 0.0) - p_.position_m);
  const double f = pitPlan(q.x(), q.y()) > 0.0 ? pitFloor(q.x(), q.y()) : tubeFloor(q.x(), q.y());
  return p_.position_m.z() + f;
}

Vec3 LavaTube::pointAboveFloor(double s, double h) const {
  const double y = meander(s);
  return toWorld(Vec3(s, y, tubeFloor(s, y) + h));
}

}  // namespace evio::scenes
