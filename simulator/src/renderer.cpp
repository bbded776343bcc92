#include "evio/simulator/renderer.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "evio/core/cpu_features.h"
#include "evio/core/error.h"
#include "evio/scenes/embree_util.h"
#include "parallel_for.h"
#include "renderer_scratch.h"

#if defined(__GNUC__) && defined(__x86_64__)
#define EVIO_RENDER_AVX2 1  // an AVX2 copy of the shading code, chosen at run time
#endif

namespace evio::simulator {

namespace {
constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

Eigen::Vector3f unprojectOrNan(const Camera& camera, const Vec2& uv) {
  Vec3 b;
  if (!camera.unproject(uv, &b) || !b.allFinite() || !(b.norm() > 0.0)) return Eigen::Vector3f::Constant(kNaN);
  return b.normalized().cast<float>();
}
}  // namespace

Renderer::Renderer(const scenes::Scene& scene, const Camera& camera, const RendererOptions& options)
    : scene_(scene), camera_(camera), options_(options) {
  options_.validate();
  const int w = camera_.width(), h = camera_.height();
  const int n = options_.supersampling;
  bearings_.resize(static_cast<std::size_t>(w) * static_cast<std::size_t>(h));
  if (n > 1) sub_bearings_.resize(bearings_.size() * static_cast<std::size_t>(n * n));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::size_t p = static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x);
      bearings_[p] = unprojectOrNan(camera_, Vec2(x, y));
      for (int j = 0; j < n && n > 1; ++j)
        for (int i = 0; i < n; ++i)
          sub_bearings_[p * static_cast<std::size_t>(n * n) + static_cast<std::size_t>(j * n + i)] =
              unprojectOrNan(camera_, Vec2(x + (i + 0.5) / n - 0.5, y + (j + 0.5) / n - 0.5));
    }
  pixel_angle_rad_ = static_cast<float>(1.0 / camera_.intrinsics()[0]);
  if (const PinholeCamera* pinhole = camera_.as<PinholeCamera>()) {
    pinhole_flow_.emplace(*pinhole);
    flow_in_front_.resize(bearings_.size());
    for (std::size_t p = 0; p < bearings_.size(); ++p) {
      const Vec3 b = bearings_[p].cast<double>();
      flow_in_front_[p] = static_cast<std::uint8_t>(b.allFinite() && isInFrontOfCamera(b) &&
                                                    b.z() > 2.0 * kMinCosAngle * b.norm());
    }
  }
  // Tile buffers per thread, reused from render to render (no allocation
  // and first-touch page faults per frame). Copies of the renderer share
  // the pool, which is safe: a thread uses its buffers for one tile at a time.
  scratch_ = std::make_shared<ScratchPool>();
#if defined(EVIO_RENDER_AVX2)
  avx2_ = options_.avx2 && cpuHasAvx2();
#endif
  if (!avx2_ || n > 1) return;
  // The bearings tile by tile for the AVX2 path without supersampling: per
  // tile, x, y and z columns of tile_stride_ entries (rays in row-major
  // order, NaN padding).
  const int t = options_.tile_px;
  const int tiles_x = (w + t - 1) / t, tiles = tiles_x * ((h + t - 1) / t);
  tile_stride_ = (static_cast<std::size_t>(t) * static_cast<std::size_t>(t) + 7) / 8 * 8;
  tile_bearings_.assign(static_cast<std::size_t>(tiles) * 3 * tile_stride_, kNaN);
  for (int k = 0; k < tiles; ++k) {
    const int x0 = (k % tiles_x) * t, y0 = (k / tiles_x) * t;
    float* col = tile_bearings_.data() + static_cast<std::size_t>(k) * 3 * tile_stride_;
    std::size_t ri = 0;
    for (int y = y0; y < std::min(y0 + t, h); ++y)
      for (int x = x0; x < std::min(x0 + t, w); ++x, ++ri) {
        const Eigen::Vector3f& b = bearings_[static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x)];
        for (std::size_t i = 0; i < 3; ++i) col[i * tile_stride_ + ri] = b[static_cast<Eigen::Index>(i)];
      }
  }
}


RenderOutput Renderer::render(const Pose& T_W_C, const CameraVelocity* velocity, RenderStats* stats) const {
  RenderOutput out;
  render(T_W_C, velocity, &out, stats);
  return out;
}

void Renderer::render(const Pose& T_W_C, const CameraVelocity* velocity, RenderOutput* out_ptr,
                      RenderStats* stats) const {
  if (options_.check_viewpoint) scene_.checkViewpoint(T_W_C.translation());
  const int w = camera_.width(), h = camera_.height();
  RenderOutput& out = *out_ptr;
  const auto prepare = [h, w](cv::Mat& m, int type) {
    if (m.u != nullptr && m.u->refcount > 1) m.release();  // shared: do not overwrite the other's pixels
    m.create(h, w, type);
  };
  prepare(out.radiance, CV_32FC1);
  prepare(out.depth, CV_32FC1);
  prepare(out.normal, CV_32FC3);
  if (velocity) prepare(out.flow, CV_32FC2);
  else out.flow.release();
  renderTileList(T_W_C, velocity, nullptr, static_cast<std::size_t>(tileCount()), &out, stats);
}

cv::Rect Renderer::tileRect(int tile) const {
  if (tile < 0 || tile >= tileCount()) throw Error("Renderer::tileRect: tile " + std::to_string(tile) + " out of range");
  const int t = options_.tile_px, tiles_x = tilesX();
  const int x0 = (tile % tiles_x) * t, y0 = (tile / tiles_x) * t;
  return cv::Rect(x0, y0, std::min(t, camera_.width() - x0), std::min(t, camera_.height() - y0));
}

void Renderer::renderTiles(const Pose& T_W_C, const CameraVelocity* velocity, const int* tiles, std::size_t count,
                           RenderOutput* out_ptr, RenderStats* stats) const {
  const int w = camera_.width(), h = camera_.height(), n = tileCount();
  RenderOutput& out = *out_ptr;
  const auto check = [h, w](cv::Mat& m, int type, const char* name) {
    if (m.rows != h || m.cols != w || m.type() != type)
      throw Error(std::string("Renderer::renderTiles: ") + name + " is not the image of an earlier render of this camera");
    if (m.u != nullptr && m.u->refcount > 1) m = m.clone();  // shared: keep the other's pixels
  };
  check(out.radiance, CV_32FC1, "radiance");
  check(out.depth, CV_32FC1, "depth");
  check(out.normal, CV_32FC3, "normal");
  if (velocity) check(out.flow, CV_32FC2, "flow");
  for (std::size_t i = 0; i < count; ++i)
    if (tiles[i] < 0 || tiles[i] >= n)
      throw Error("Renderer::renderTiles: tile " + std::to_string(tiles[i]) + " out of range");
  if (options_.check_viewpoint && count > 0) scene_.checkViewpoint(T_W_C.translation());
  renderTileList(T_W_C, velocity, tiles, count, &out, stats);
}

void Renderer::renderTileList(const Pose& T_W_C, const CameraVelocity* velocity, const int* tiles, std::size_t count,
                              RenderOutput* out, RenderStats* stats) const {
  std::vector<RenderStats> counts(count);
  const auto tileAt = [tiles](std::size_t i) { return tiles ? tiles[i] : static_cast<int>(i); };
  sharedArena(options_.threads).execute([&] {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, count, 1), [&](const tbb::blocked_range<std::size_t>& r) {
      Scratch& s = scratch_->local.local();
      for (std::size_t i = r.begin(); i != r.end(); ++i) renderTile(tileAt(i), T_W_C, velocity, out, &counts[i], &s);
    });
  });
  if (stats) {
    *stats = RenderStats{};
    for (const auto& c : counts) {
      stats->camera_rays += c.camera_rays;
      stats->shadow_rays += c.shadow_rays;
    }
  }
}

/// The albedo of the tile's shaded rays with the textures' 8-lane lookups,
/// grouped by material; a last group of fewer than eight repeats its last
/// ray. The values are those of Scene::albedo bit for bit.
template <class Shaded, class Footprint>
[[gnu::always_inline]] inline void Renderer::albedoPassAvx2(std::size_t rays, const Shaded& shaded,
                                                          const Footprint& footprint, Scratch* scratch) const {
  Scratch& s = *scratch;
  s.footprint.resize(rays);
  s.material.resize(rays);
  for (std::size_t r = 0; r < rays; ++r) {
    if (!shaded(r)) continue;
    s.material[r] = scene_.materialOf(s.hits[r].mesh);
    s.footprint[r] = footprint(r);
  }
  alignas(32) float px[8], py[8], pz[8], u[8], v[8], fp[8], out[8];
  forMaterialGroups(rays, static_cast<std::size_t>(scene_.materialCount()), s, shaded,
                    [&](int m, const std::uint32_t* group, std::uint32_t n) {
                      for (std::uint32_t k = 0; k < 8; ++k) {
                        const std::uint32_t r = group[std::min(k, n - 1)];
                        const scenes::SurfaceHit& h = s.hits[r];
                        px[k] = h.p.x();
                        py[k] = h.p.y();
                        pz[k] = h.p.z();
                        u[k] = h.uv.x();
                        v[k] = h.uv.y();
                        fp[k] = s.footprint[r];
                      }
                      scene_.albedo8Avx2(m, px, py, pz, u, v, fp, out);
                      for (std::uint32_t k = 0; k < n; ++k) s.albedo[group[k]] = out[k];
                    });
}

// The tile body is compiled twice: for the baseline x86-64 target and for
// AVX2 without FMA. The compiler may choose other instructions (roundss for
// floor, wider moves) but no other float operations: without FMA and
// without -ffast-math every result is rounded exactly as in the baseline
// copy. Test: Renderer.Avx2PathRendersTheSameBitsAsTheBaselinePath.
template <bool kAvx2>
[[gnu::always_inline]] inline void Renderer::shadeTile(int tile, const Pose& T_W_C, const CameraVelocity* velocity,
                                                     RenderOutput* out, RenderStats* counts, Scratch* scratch) const {
  const int w = camera_.width(), h = camera_.height(), t = options_.tile_px;
  const int tiles_x = (w + t - 1) / t;
  const int x0 = (tile % tiles_x) * t, y0 = (tile / tiles_x) * t;
  const int x1 = std::min(x0 + t, w), y1 = std::min(y0 + t, h);
  const int n = options_.supersampling;
  const int nn = n * n;
  const bool super = n > 1;
  const int per_pixel = super ? 1 + nn : 1;  // centre ray (+ radiance rays)
  const int pixels = (x1 - x0) * (y1 - y0);
  const auto rays = static_cast<std::size_t>(pixels * per_pixel);
  const auto lights = static_cast<std::size_t>(scene_.shadowLightCount());

  const Eigen::Matrix3f R = T_W_C.rotation().cast<float>();
  const Eigen::Vector3f org = T_W_C.translation().cast<float>();

  Scratch& s = *scratch;
  const bool packets = kAvx2 && !super;  // the 8-lane path (renderer_avx2.cpp)
  if (!packets) {
    s.rays.resize(rays);
    s.dirs.resize(rays);
    s.hits.resize(rays);
    s.albedo.resize(rays);
    s.light.resize(rays * std::max<std::size_t>(lights, 1));  // written below for every shaded ray
    s.shadow.resize(rays * lights);
    s.shadow_slot.resize(rays * lights);
  }

  std::size_t ri = 0;
  if (packets) {
    counts->camera_rays = setupRaysAvx2(tile, rays, R, org, scratch);
    ri = rays;
  }
  for (int y = y0; y < y1 && ri < rays; ++y)
    for (int x = x0; x < x1; ++x) {
      const std::size_t p = static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x);
      for (int k = 0; k < per_pixel; ++k, ++ri) {
        const Eigen::Vector3f& b =
            k == 0 ? bearings_[p] : sub_bearings_[p * static_cast<std::size_t>(nn) + static_cast<std::size_t>(k - 1)];
        if (std::isnan(b.x())) {
          s.dirs[ri] = Eigen::Vector3f::UnitZ();
          scenes::setRayHit(s.rays[ri], org, s.dirs[ri], 1.0f, 0.0f);  // tnear > tfar: inactive
          continue;
        }
        s.dirs[ri] = R * b;
        scenes::setRayHit(s.rays[ri], org, s.dirs[ri]);
        ++counts->camera_rays;
      }
    }
  RTCIntersectContext coherent = scenes::intersectContext(true);
  rtcIntersect1M(scene_.embree(), &coherent, s.rays.data(), static_cast<unsigned>(rays), sizeof(RTCRayHit));

  // Shading inputs and occlusion rays.
  const float footprint_scale = pixel_angle_rad_ / static_cast<float>(n);
  if (packets) {
    counts->shadow_rays = shadePacketsAvx2(rays, footprint_scale, scratch);
    writeOutputs(x0, y0, x1, y1, velocity, out, *scratch);
    return;
  }
  std::size_t shadows = 0;
  // The shading data of large meshes is mostly not in cache: fetch the
  // triangle record kAhead hits ahead and its vertices kAhead / 2 ahead.
  constexpr std::size_t kAhead = 8;
  const auto prefetch = [&](std::size_t r, int stage) {
    if (r < rays && s.rays[r].hit.geomID != RTC_INVALID_GEOMETRY_ID)
      scene_.prefetchHit(s.rays[r].hit.geomID, s.rays[r].hit.primID, stage);
  };
  for (std::size_t r = 0; r < kAhead; ++r) prefetch(r, 0);
  for (std::size_t r = 0; r < kAhead / 2; ++r) prefetch(r, 1);
  // Three passes over the tile's rays (surface, albedo, lights) rather than
  // one: each loop body is short enough for the processor to overlap the
  // dependency chains of several rays. Per ray, the operations and their
  // order are unchanged.
  for (ri = 0; ri < rays; ++ri) {
    prefetch(ri + kAhead, 0);
    prefetch(ri + kAhead / 2, 1);
    const RTCRayHit& q = s.rays[ri];
    if (q.hit.geomID == RTC_INVALID_GEOMETRY_ID) continue;
    scene_.surfaceHit(q.hit.geomID, q.hit.primID, q.hit.u, q.hit.v, s.dirs[ri], &s.hits[ri]);
  }
  const auto shaded = [&](std::size_t r) {  // radiance rays that hit a surface
    return s.rays[r].hit.geomID != RTC_INVALID_GEOMETRY_ID && !(super && r % static_cast<std::size_t>(per_pixel) == 0);
  };
  const auto footprint = [&](std::size_t r) {  // the pixel's size on the surface (m)
    const float cos_view = std::max(-s.hits[r].n.dot(s.dirs[r]), 0.2f);
    return s.rays[r].ray.tfar * footprint_scale / cos_view;
  };
  if constexpr (kAvx2) {
    albedoPassAvx2(rays, shaded, footprint, scratch);
  } else {
    for (ri = 0; ri < rays; ++ri)
      if (shaded(ri)) s.albedo[ri] = scene_.albedo(s.hits[ri], footprint(ri));
  }
  for (ri = 0; ri < rays; ++ri) {
    if (!shaded(ri)) continue;
    const scenes::SurfaceHit& hit = s.hits[ri];
    for (std::size_t k = 0; k < lights; ++k) {
      scenes::ShadowRay sr;
      scenes::LightSample& sample = s.light[ri * lights + k];
      if (!scene_.shadowRay(static_cast<int>(k), hit, &sr)) {
        sample = scenes::LightSample{};
        continue;
      }
      sample = scenes::LightSample{sr.direction, sr.e_normal};
      scenes::setRay(s.shadow[shadows], sr.origin, sr.direction, 0.0f, sr.t_far);
      s.shadow_slot[shadows++] = static_cast<std::uint32_t>(ri * lights + k);
    }
  }
  counts->shadow_rays = shadows;
  if (shadows > 0)
    rtcOccluded1M(scene_.embree(), &coherent, s.shadow.data(), static_cast<unsigned>(shadows), sizeof(RTCRay));
  for (std::size_t i = 0; i < shadows; ++i)
    if (s.shadow[i].tfar < 0.0f) s.light[s.shadow_slot[i]].e_normal = 0.0f;  // occluded: tfar = -inf

  // Outputs.
  const float inv_rays = 1.0f / static_cast<float>(per_pixel - (super ? 1 : 0));
  ri = 0;
  for (int y = y0; y < y1; ++y) {
    float* radiance = out->radiance.ptr<float>(y);
    float* depth = out->depth.ptr<float>(y);
    cv::Vec3f* normal = out->normal.ptr<cv::Vec3f>(y);
    cv::Vec2f* flow = velocity ? out->flow.ptr<cv::Vec2f>(y) : nullptr;
    for (int x = x0; x < x1; ++x, ri += static_cast<std::size_t>(per_pixel)) {
      const Eigen::Vector3f& b = bearings_[static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x)];
      if (std::isnan(b.x())) {
        radiance[x] = 0.0f;
        depth[x] = kNaN;
        normal[x] = cv::Vec3f(0.0f, 0.0f, 0.0f);
        if (flow) flow[x] = cv::Vec2f(kNaN, kNaN);
        continue;
      }
      // Radiance: the centre ray, or the mean of the n² sub-pixel rays.
      float sum = 0.0f;
      for (std::size_t k = super ? 1 : 0; k < static_cast<std::size_t>(per_pixel); ++k) {
        const std::size_t r = ri + k;
        if (s.rays[r].hit.geomID == RTC_INVALID_GEOMETRY_ID)
          sum += s.rays[r].ray.tnear <= s.rays[r].ray.tfar ? scene_.background(s.dirs[r]) : 0.0f;
        else
          sum += scene_.radiance(s.hits[r], -s.dirs[r], s.albedo[r], &s.light[r * lights]);
      }
      radiance[x] = super ? sum * inv_rays : sum;
      const bool hit = s.rays[ri].hit.geomID != RTC_INVALID_GEOMETRY_ID;
      const float range = s.rays[ri].ray.tfar;
      depth[x] = hit ? range * b.z() : kInf;
      if (hit) {
        const Eigen::Vector3f& nrm = s.hits[ri].n;
        normal[x] = cv::Vec3f(nrm.x(), nrm.y(), nrm.z());
      } else {
        normal[x] = cv::Vec3f(0.0f, 0.0f, 0.0f);
      }
      if (flow) {
        Vec2 f;
        const bool ok = pixelFlow(b, hit, range, *velocity, &f);
        flow[x] = ok ? cv::Vec2f(static_cast<float>(f.x()), static_cast<float>(f.y())) : cv::Vec2f(kNaN, kNaN);
      }
    }
  }
}

void Renderer::renderTile(int tile, const Pose& T_W_C, const CameraVelocity* velocity, RenderOutput* out,
                          RenderStats* counts, Scratch* scratch) const {
#if defined(EVIO_RENDER_AVX2)
  if (avx2_) {
    renderTileAvx2(tile, T_W_C, velocity, out, counts, scratch);
    return;
  }
#endif
  shadeTile<false>(tile, T_W_C, velocity, out, counts, scratch);
}

#if defined(EVIO_RENDER_AVX2)
__attribute__((target("avx2"))) void Renderer::renderTileAvx2(int tile, const Pose& T_W_C,
                                                                const CameraVelocity* velocity, RenderOutput* out,
                                                                RenderStats* counts, Scratch* scratch) const {
  shadeTile<true>(tile, T_W_C, velocity, out, counts, scratch);
}
#else
void Renderer::renderTileAvx2(int tile, const Pose& T_W_C, const CameraVelocity* velocity, RenderOutput* out,
                              RenderStats* counts, Scratch* scratch) const {
  shadeTile<false>(tile, T_W_C, velocity, out, counts, scratch);
}
#endif

}  // namespace evio::simulator
