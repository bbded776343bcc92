#include "evio/scenes/irradiance_cache.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <bit>
#include <cmath>
#include <numbers>

#include "evio/core/random_stream.h"
#include "evio/scenes/embree_util.h"
#include "evio/scenes/noise.h"
#include "evio/scenes/scene.h"

namespace evio::scenes {

namespace {

/// Van der Corput radical inverse in base 2.
float radicalInverse(std::uint32_t i) {
  i = (i << 16U) | (i >> 16U);
  i = ((i & 0x55555555U) << 1U) | ((i & 0xAAAAAAAAU) >> 1U);
  i = ((i & 0x33333333U) << 2U) | ((i & 0xCCCCCCCCU) >> 2U);
  i = ((i & 0x0F0F0F0FU) << 4U) | ((i & 0xF0F0F0F0U) >> 4U);
  i = ((i & 0x00FF00FFU) << 8U) | ((i & 0xFF00FF00U) >> 8U);
  return static_cast<float>(i) * 2.3283064365386963e-10f;
}

/// Orthonormal basis (t, b) with t × b = n (Duff et al. 2017, "Building an
/// orthonormal basis, revisited").
void basis(const Eigen::Vector3f& n, Eigen::Vector3f* t, Eigen::Vector3f* b) {
  const float sign = std::copysign(1.0f, n.z());
  const float a = -1.0f / (sign + n.z());
  const float c = n.x() * n.y() * a;
  *t = Eigen::Vector3f(1.0f + sign * n.x() * n.x() * a, sign * c, -sign * n.x());
  *b = Eigen::Vector3f(c, sign + n.y() * n.y() * a, -n.y());
}

}  // namespace

std::vector<std::vector<float>> computeIrradianceCache(const Scene& scene, const IndirectOptions& options,
                                                       std::uint64_t seed, int threads) {
  const auto& meshes = scene.meshes();
  const int n_dirs = options.directions;
  // The fixed direction set in the local frame (z = normal), cosine-distributed.
  std::vector<float> u1(static_cast<std::size_t>(n_dirs)), u2(static_cast<std::size_t>(n_dirs));
  for (int i = 0; i < n_dirs; ++i) {
    u1[static_cast<std::size_t>(i)] = (static_cast<float>(i) + 0.5f) / static_cast<float>(n_dirs);
    u2[static_cast<std::size_t>(i)] = radicalInverse(static_cast<std::uint32_t>(i));
  }
  const auto rot_seed = static_cast<std::uint32_t>(streamSeed(seed, "indirect/rotation"));

  // Flattened vertex index → (mesh, vertex).
  std::vector<std::size_t> offset(meshes.size() + 1, 0);
  for (std::size_t m = 0; m < meshes.size(); ++m) offset[m + 1] = offset[m] + meshes[m].mesh.positions.size();
  const std::size_t total = offset.back();

  // Ray origins leave each vertex along its normal by 5 % of its mean edge
  // length (at least 1e-4 (1 + |p|∞)): enough to clear small folds of
  // extracted surfaces, small against the geometry.
  std::vector<std::vector<float>> lift(meshes.size());
  for (std::size_t m = 0; m < meshes.size(); ++m) {
    const TriangleMesh& mesh = meshes[m].mesh;
    std::vector<float> sum(mesh.positions.size(), 0.0f);
    std::vector<int> count(mesh.positions.size(), 0);
    for (const auto& t : mesh.triangles)
      for (int k = 0; k < 3; ++k) {
        const auto a = static_cast<std::size_t>(t[k]), b = static_cast<std::size_t>(t[(k + 1) % 3]);
        const float len = (mesh.positions[a] - mesh.positions[b]).norm();
        sum[a] += len;
        sum[b] += len;
        count[a] += 1;
        count[b] += 1;
      }
    lift[m].resize(mesh.positions.size());
    for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
      const float floor_eps = 1e-4f * (1.0f + mesh.positions[v].cwiseAbs().maxCoeff());
      lift[m][v] = std::max(floor_eps, count[v] > 0 ? 0.05f * sum[v] / static_cast<float>(count[v]) : 0.0f);
    }
  }

  std::vector<std::vector<float>> prev(meshes.size()), next(meshes.size());
  for (std::size_t m = 0; m < meshes.size(); ++m) next[m].assign(meshes[m].mesh.positions.size(), 0.0f);

  tbb::task_arena arena = threads > 0 ? tbb::task_arena(threads) : tbb::task_arena();
  for (int bounce = 0; bounce < options.bounces; ++bounce) {
    prev = next;
    const std::vector<std::vector<float>>& cache_prev = prev;
    const bool use_prev = bounce > 0;
    arena.execute([&] {
      tbb::parallel_for(tbb::blocked_range<std::size_t>(0, total, 256), [&](const tbb::blocked_range<std::size_t>& r) {
        RTCIntersectContext ctx = intersectContext(false);
        std::size_t m = 0;
        for (std::size_t flat = r.begin(); flat != r.end(); ++flat) {
          while (flat >= offset[m + 1]) ++m;
          const std::size_t v = flat - offset[m];
          const Eigen::Vector3f& p = meshes[m].mesh.positions[v];
          const Eigen::Vector3f& n = meshes[m].mesh.normals[v];
          Eigen::Vector3f t, b;
          basis(n, &t, &b);
          // Rotation about n hashed from the position, so that coincident
          // vertices (seams) get identical values.
          const float phi0 = 2.0f * std::numbers::pi_v<float> *
                             noise::unit(noise::hash(std::bit_cast<std::int32_t>(p.x()),
                                                     std::bit_cast<std::int32_t>(p.y()),
                                                     std::bit_cast<std::int32_t>(p.z()), rot_seed));
          const Eigen::Vector3f origin = p + lift[m][v] * n;
          double sum = 0.0;
          for (int i = 0; i < n_dirs; ++i) {
            const float s1 = u1[static_cast<std::size_t>(i)];
            const float rr = std::sqrt(s1);
            const float phi = phi0 + 2.0f * std::numbers::pi_v<float> * u2[static_cast<std::size_t>(i)];
            const Eigen::Vector3f d = (rr * std::cos(phi)) * t + (rr * std::sin(phi)) * b +
                                      std::sqrt(std::max(0.0f, 1.0f - s1)) * n;
            RTCRayHit rh;
            setRayHit(rh, origin, d);
            rtcIntersect1(scene.embree(), &ctx, &rh);
            if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) {
              sum += static_cast<double>(scene.background(d));
              continue;
            }
            const SurfaceHit h = scene.surfaceHit(rh.hit.geomID, rh.hit.primID, rh.hit.u, rh.hit.v, d);
            if (h.back_face && meshes[h.mesh].solid) continue;
            const float rho = scene.albedo(h, 0.02f * rh.ray.tfar);
            float e = scene.directIrradiance(h);
            if (use_prev) e += scene.interpolate(h, cache_prev);
            sum += static_cast<double>(rho * e * (1.0f / std::numbers::pi_v<float>));
          }
          next[m][v] = static_cast<float>(std::numbers::pi * sum / n_dirs);
        }
      });
    });
  }
  return next;
}

}  // namespace evio::scenes
