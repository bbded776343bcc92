#include "evio/scenes/rocks.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <utility>

#include "evio/core/random_stream.h"
#include "evio/scenes/mesh_ops.h"
#include "evio/scenes/noise.h"

namespace evio::scenes {

TriangleMesh icosphere(int subdivisions) {
  const float t = (1.0f + std::sqrt(5.0f)) * 0.5f;
  TriangleMesh m;
  m.positions = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                 {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  for (auto& p : m.positions) p.normalize();
  m.triangles = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                 {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                 {3, 8, 9},  {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (int s = 0; s < subdivisions; ++s) {
    std::map<std::pair<int, int>, int> midpoint;
    const auto mid = [&](int a, int b) {
      const auto key = std::minmax(a, b);
      auto it = midpoint.find(key);
      if (it != midpoint.end()) return it->second;
      const int idx = static_cast<int>(m.positions.size());
      m.positions.push_back((m.positions[static_cast<std::size_t>(a)] +
                             m.positions[static_cast<std::size_t>(b)]).normalized());
      midpoint.emplace(key, idx);
      return idx;
    };
    std::vector<Eigen::Vector3i> next;
    next.reserve(m.triangles.size() * 4);
    for (const auto& tri : m.triangles) {
      const int a = mid(tri[0], tri[1]), b = mid(tri[1], tri[2]), c = mid(tri[2], tri[0]);
      next.emplace_back(tri[0], a, c);
      next.emplace_back(tri[1], b, a);
      next.emplace_back(tri[2], c, b);
      next.emplace_back(a, b, c);
    }
    m.triangles = std::move(next);
  }
  m.normals = m.positions;
  return m;
}

TriangleMesh rocksMesh(const RocksParams& params, std::uint64_t seed, const std::string& name,
                       const HeightFunction& ground) {
  const TriangleMesh unit = icosphere(params.subdivisions);
  RandomStream rng(seed, name + "/rocks");
  const auto noise_seed = static_cast<std::uint32_t>(streamSeed(seed, name + "/rock shapes"));
  const double rmin = params.radius_m.x(), rmax = params.radius_m.y();
  const double q = std::pow(rmin / rmax, params.size_exponent);
  const auto groundAt = [&](double x, double y) {
    return ground ? ground(x, y) : params.base_height_m;
  };
  TriangleMesh all;
  for (int k = 0; k < params.count; ++k) {
    const double radius = rmin * std::pow(1.0 - rng.uniform() * (1.0 - q), -1.0 / params.size_exponent);
    const double x = params.region_center_m.x() + rng.uniform(-0.5, 0.5) * params.region_size_m.x();
    const double y = params.region_center_m.y() + rng.uniform(-0.5, 0.5) * params.region_size_m.y();
    const double yaw = rng.uniform(0.0, 2.0 * std::numbers::pi);
    const double elongation = rng.uniform(0.75, 1.25);
    const Eigen::Vector3f offset(static_cast<float>(rng.uniform(-1000.0, 1000.0)),
                                 static_cast<float>(rng.uniform(-1000.0, 1000.0)),
                                 static_cast<float>(rng.uniform(-1000.0, 1000.0)));
    const double rz = radius * params.flatten;
    double g = groundAt(x, y);
    for (int s = 0; s < 8; ++s) {
      const double a = s * std::numbers::pi / 4.0;
      g = std::min(g, groundAt(x + radius * std::cos(a), y + radius * std::sin(a)));
    }
    const double bottom = g - params.embed_fraction * 2.0 * rz;
    const Vec3 centre(x, y, bottom + rz);
    const Mat3 R = Eigen::AngleAxisd(yaw, Vec3::UnitZ()).toRotationMatrix();
    TriangleMesh rock = unit;
    for (auto& p : rock.positions) {
      const double r = 1.0 + params.shape_noise *
                                 static_cast<double>(noise::fbm3(1.5f * p + offset, 4, 0.5f, noise_seed));
      const Vec3 pd = p.cast<double>();
      const Vec3 local(radius * elongation * r * pd.x(), radius / elongation * r * pd.y(), rz * r * pd.z());
      p = (R * local + centre).cast<float>();
    }
    rock.uvs.resize(rock.positions.size());
    for (std::size_t i = 0; i < rock.positions.size(); ++i) rock.uvs[i] = rock.positions[i].head<2>();
    computeVertexNormals(rock);
    appendMesh(all, rock);
  }
  return all;
}

}  // namespace evio::scenes
