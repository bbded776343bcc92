#include "evio/scenes/isosurface.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <array>
#include <vector>

#include "evio/core/error.h"
#include "evio/scenes/mesh_ops.h"

namespace evio::scenes {

TriangleMesh extractIsosurface(const IsoGrid& g, const std::function<double(const Vec3&)>& F) {
  require(g.nx >= 2 && g.ny >= 2 && g.nz >= 2 && g.cell_m > 0.0, "extractIsosurface: bad grid");
  const std::size_t nx = static_cast<std::size_t>(g.nx), ny = static_cast<std::size_t>(g.ny),
                    nz = static_cast<std::size_t>(g.nz);
  require(nx * ny * nz < 200'000'000, "extractIsosurface: grid too large");
  const auto point = [&](std::size_t i, std::size_t j, std::size_t k) {
    return Vec3(g.origin.x() + g.cell_m * static_cast<double>(i), g.origin.y() + g.cell_m * static_cast<double>(j),
                g.origin.z() + g.cell_m * static_cast<double>(k));
  };
  const auto gidx = [&](std::size_t i, std::size_t j, std::size_t k) { return (k * ny + j) * nx + i; };

  std::vector<float> values(nx * ny * nz);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nz), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t k = r.begin(); k != r.end(); ++k)
      for (std::size_t j = 0; j < ny; ++j)
        for (std::size_t i = 0; i < nx; ++i) values[gidx(i, j, k)] = static_cast<float>(F(point(i, j, k)));
  });
  const auto solid = [&](std::size_t i, std::size_t j, std::size_t k) { return values[gidx(i, j, k)] > 0.0f; };

  // One vertex per cell with a sign change.
  const std::size_t cx = nx - 1, cy = ny - 1, cz = nz - 1;
  const auto cidx = [&](std::size_t i, std::size_t j, std::size_t k) { return (k * cy + j) * cx + i; };
  std::vector<int> cell_vertex(cx * cy * cz, -1);
  TriangleMesh mesh;
  static constexpr std::array<std::array<int, 6>, 12> kEdges = {{
      {0, 0, 0, 1, 0, 0}, {0, 1, 0, 1, 1, 0}, {0, 0, 1, 1, 0, 1}, {0, 1, 1, 1, 1, 1},
      {0, 0, 0, 0, 1, 0}, {1, 0, 0, 1, 1, 0}, {0, 0, 1, 0, 1, 1}, {1, 0, 1, 1, 1, 1},
      {0, 0, 0, 0, 0, 1}, {1, 0, 0, 1, 0, 1}, {0, 1, 0, 0, 1, 1}, {1, 1, 0, 1, 1, 1}}};
  for (std::size_t k = 0; k < cz; ++k)
    for (std::size_t j = 0; j < cy; ++j)
      for (std::size_t i = 0; i < cx; ++i) {
        Vec3 sum = Vec3::Zero();
        int n = 0;
        for (const auto& e : kEdges) {
          const std::size_t i0 = i + static_cast<std::size_t>(e[0]), j0 = j + static_cast<std::size_t>(e[1]),
                            k0 = k + static_cast<std::size_t>(e[2]);
          const std::size_t i1 = i + static_cast<std::size_t>(e[3]), j1 = j + static_cast<std::size_t>(e[4]),
                            k1 = k + static_cast<std::size_t>(e[5]);
          const float a = values[gidx(i0, j0, k0)], b = values[gidx(i1, j1, k1)];
          if ((a > 0.0f) == (b > 0.0f)) continue;
          const double t = static_cast<double>(a) / (static_cast<double>(a) - static_cast<double>(b));
          sum += point(i0, j0, k0) + t * (point(i1, j1, k1) - point(i0, j0, k0));
          ++n;
        }
        if (n == 0) continue;
        cell_vertex[cidx(i, j, k)] = static_cast<int>(mesh.positions.size());
        const Vec3 v = sum / n;
        mesh.positions.push_back(v.cast<float>());
        mesh.uvs.emplace_back(static_cast<float>(v.x()), static_cast<float>(v.y()));
      }

  // One quad per grid edge with a sign change whose 4 surrounding cells exist.
  const auto quad = [&](int a, int b, int c, int d, bool flip) {
    if (a < 0 || b < 0 || c < 0 || d < 0) return;
    if (flip) std::swap(b, d);
    mesh.triangles.emplace_back(a, b, c);
    mesh.triangles.emplace_back(a, c, d);
  };
  for (std::size_t k = 0; k < nz; ++k)
    for (std::size_t j = 0; j < ny; ++j)
      for (std::size_t i = 0; i < nx; ++i) {
        const bool s0 = solid(i, j, k);
        // Edge along x: cells around it in the (y, z) plane, counter-clockwise
        // seen from +x; front towards +x when the solid is at the lower end.
        if (i + 1 < nx && j > 0 && k > 0 && j < cy && k < cz && s0 != solid(i + 1, j, k))
          quad(cell_vertex[cidx(i, j - 1, k - 1)], cell_vertex[cidx(i, j, k - 1)], cell_vertex[cidx(i, j, k)],
               cell_vertex[cidx(i, j - 1, k)], !s0);
        if (j + 1 < ny && i > 0 && k > 0 && i < cx && k < cz && s0 != solid(i, j + 1, k))
          quad(cell_vertex[cidx(i - 1, j, k - 1)], cell_vertex[cidx(i - 1, j, k)], cell_vertex[cidx(i, j, k)],
               cell_vertex[cidx(i, j, k - 1)], !s0);
        if (k + 1 < nz && i > 0 && j > 0 && i < cx && j < cy && s0 != solid(i, j, k + 1))
          quad(cell_vertex[cidx(i - 1, j - 1, k)], cell_vertex[cidx(i, j - 1, k)], cell_vertex[cidx(i, j, k)],
               cell_vertex[cidx(i - 1, j, k)], !s0);
      }
  computeVertexNormals(mesh);
  return mesh;
}

}  // namespace evio::scenes
