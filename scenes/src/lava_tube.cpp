#include "evio/scenes/lava_tube.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "evio/core/random_stream.h"
#include "evio/scenes/mesh_ops.h"
#include "evio/scenes/noise.h"

namespace evio::scenes {

namespace {
constexpr double kPi = std::numbers::pi;
}

LavaTube::LavaTube(const TubeParams& params, std::uint64_t seed, const std::string& name)
    : p_(params),
      seed_(static_cast<std::uint32_t>(streamSeed(seed, name + "/tube"))),
      R_(Eigen::AngleAxisd(params.yaw_deg * kPi / 180.0, Vec3::UnitZ()).toRotationMatrix()) {}

Vec3 LavaTube::toWorld(const Vec3& local) const { return R_ * local + p_.position_m; }

double LavaTube::meander(double s) const {
  return p_.meander_m * noise::fbm2(s / 25.0, 0.5, 2, 0.5, seed_ + 11U);
}

double LavaTube::floorLocal(double s, double y) const {
  return -p_.floor_depth_m + 0.03 * noise::fbm2(s / 0.7, y / 0.7, 3, 0.5, seed_ + 13U);
}

double LavaTube::floorHeight(double x, double y) const {
  const Vec3 local = R_.transpose() * (Vec3(x, y, 0.0) - p_.position_m);
  return p_.position_m.z() + floorLocal(local.x(), local.y() - meander(local.x()));
}

Vec3 LavaTube::pointAboveFloor(double s, double h) const {
  const double y = meander(s);
  return toWorld(Vec3(s, y, floorLocal(s, 0.0) + h));
}

TriangleMesh LavaTube::mesh() const {
  const double a = 0.5 * p_.width_m, b = 0.5 * p_.height_m;
  const double perimeter = kPi * (3.0 * (a + b) - std::sqrt((3.0 * a + b) * (a + 3.0 * b)));
  const int nx = std::max(2, static_cast<int>(std::ceil(p_.length_m / p_.cell_m)) + 1);
  const int nt = std::max(8, static_cast<int>(std::ceil(perimeter / p_.cell_m)));
  const float inv_wl = static_cast<float>(1.0 / p_.roughness_wavelength_m);

  // Ring vertices: nt per section (θ_j = 2π j / nt), plus a duplicated seam
  // column j = nt (same position as j = 0, uv continues) so uv do not wrap.
  const auto section = [&](int i, int j) -> Vec3 {
    const double s = p_.length_m * i / (nx - 1);
    const double theta = 2.0 * kPi * (j % nt) / nt;
    const Vec3 dir(0.0, a * std::sin(theta), -b * std::cos(theta));
    const Eigen::Vector3f probe = (Vec3(s, dir.y(), dir.z()) * inv_wl).cast<float>();
    const double f = 1.0 + p_.roughness * 1.4 * static_cast<double>(noise::fbm3(probe, 4, 0.5f, seed_));
    Vec3 q(s, f * dir.y(), f * dir.z());
    q.z() = std::max(q.z(), floorLocal(s, q.y()));
    q.y() += meander(s);
    return q;
  };
  const auto in_opening = [&](int i, int j) {
    if (p_.collapse_length_m <= 0.0 || p_.collapse_width_m <= 0.0) return false;
    const double s = p_.length_m * (i + 0.5) / (nx - 1);
    double arc = perimeter * ((j + 0.5) / nt - 0.5);  // 0 at the top (θ = π)
    const double u = (s - p_.collapse_center_m) / (0.5 * p_.collapse_length_m);
    const double v = arc / (0.5 * p_.collapse_width_m);
    const double jag = 0.35 * noise::fbm2(s / 1.2, arc / 1.2, 3, 0.5, seed_ + 17U);
    return u * u + v * v + jag < 1.0;
  };
  TriangleMesh m = gridMesh(
      nx, nt + 1,
      [&](int i, int j) { return Eigen::Vector3f(toWorld(section(i, j)).cast<float>()); },
      [&](int i, int j) {
        return Eigen::Vector2f(static_cast<float>(p_.length_m * i / (nx - 1)),
                               static_cast<float>(perimeter * j / nt));
      },
      [&](int i, int j) { return !in_opening(i, j); });
  // gridMesh faces along ∂p/∂s × ∂p/∂θ, which points inwards (at the bottom,
  // x̂ × ŷ = +z): the wanted orientation. The seam column j = nt repeats
  // j = 0 (same positions, uv continued); their normals are averaged below.
  const auto idx = [nx](int i, int j) { return j * nx + i; };

  // End caps, facing into the tube: a fan around the ring's centroid.
  for (int end = 0; end < 2; ++end) {
    const int i = end == 0 ? 0 : nx - 1;
    Eigen::Vector3f c = Eigen::Vector3f::Zero();
    for (int j = 0; j < nt; ++j) c += m.positions[static_cast<std::size_t>(idx(i, j))];
    c /= static_cast<float>(nt);
    const int ci = static_cast<int>(m.positions.size());
    m.positions.push_back(c);
    m.uvs.emplace_back(static_cast<float>(p_.length_m * i / (nx - 1)), 0.0f);
    for (int j = 0; j < nt; ++j) {
      const int r0 = idx(i, j), r1 = idx(i, (j + 1) % nt);
      if (end == 0) m.triangles.emplace_back(ci, r0, r1);
      else m.triangles.emplace_back(ci, r1, r0);
    }
  }
  computeVertexNormals(m);
  for (int i = 0; i < nx; ++i) {
    auto& n0 = m.normals[static_cast<std::size_t>(idx(i, 0))];
    auto& n1 = m.normals[static_cast<std::size_t>(idx(i, nt))];
    n0 = (n0 + n1).normalized();
    n1 = n0;
  }
  return m;
}

}  // namespace evio::scenes
