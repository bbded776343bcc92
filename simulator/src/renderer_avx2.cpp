// The renderer's 8-lane shading (AVX2, chosen at run time; renderer.h): the
// tile's rays go through Scene's 8-lane surface, texture, light and
// radiance functions, which equal the scalar ones bit for bit, so the images
// are those of the baseline path (test:
// Renderer.Avx2PathRendersTheSameBitsAsTheBaselinePath).
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <cmath>
#include <limits>

#include "evio/core/error.h"
#include "evio/scenes/embree_util.h"
#include "evio/simulator/renderer.h"
#include "renderer_scratch.h"

#if defined(__GNUC__) && defined(__x86_64__)
#include <immintrin.h>
#endif

namespace evio::simulator {

namespace {
constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr std::size_t kLanes = 8;
}  // namespace

#if defined(__GNUC__) && defined(__x86_64__)
#define EVIO_AVX2_FN __attribute__((target("avx2")))
#define EVIO_AVX2_LAMBDA __attribute__((target("avx2"), always_inline))

namespace {
/// A lane mask: lane k set where its argument is 1.
__attribute__((target("avx2"), always_inline)) inline __m256 laneMask(int a, int b, int c, int d, int e, int f, int g,
                                                                  int h) {
  return _mm256_castsi256_ps(_mm256_setr_epi32(-a, -b, -c, -d, -e, -f, -g, -h));
}

/// ray.tfar of the eight Embree records rays[0 .. 8).
EVIO_AVX2_FN inline __m256 tfar8(const RTCRayHit* rays) {
  constexpr int kStride = sizeof(RTCRayHit) / sizeof(float);
  constexpr int kTfar = offsetof(RTCRay, tfar) / sizeof(float);
  static_assert(sizeof(RTCRayHit) % sizeof(float) == 0 && offsetof(RTCRayHit, ray) == 0, "RTCRayHit layout");
  const __m256i index = _mm256_mullo_epi32(_mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7), _mm256_set1_epi32(kStride));
  return _mm256_i32gather_ps(reinterpret_cast<const float*>(rays) + kTfar, index, 4);
}

/// footprint[r]: the pixel's size on the surface (m) as the scalar path
/// computes it, tfar · scale / max(−n·d, 0.2), eight rays at a time
/// (meaningless where the ray missed).
EVIO_AVX2_FN void footprints8(std::size_t padded, float footprint_scale, const RTCRayHit* rays,
                                  const scenes::SurfaceHitColumns& c, const float* dx, const float* dy,
                                  const float* dz, float* footprint) {
  const __m256 scale = _mm256_set1_ps(footprint_scale), min_cos = _mm256_set1_ps(0.2f);
  for (std::size_t at = 0; at < padded; at += kLanes) {
    const __m256 t_far = tfar8(rays + at);
    // n·d = n_x d_x + (n_y d_y + n_z d_z), as Eigen's dot.
    const __m256 nd = _mm256_add_ps(
        _mm256_mul_ps(_mm256_loadu_ps(c.nx.data() + at), _mm256_loadu_ps(dx + at)),
        _mm256_add_ps(_mm256_mul_ps(_mm256_loadu_ps(c.ny.data() + at), _mm256_loadu_ps(dy + at)),
                      _mm256_mul_ps(_mm256_loadu_ps(c.nz.data() + at), _mm256_loadu_ps(dz + at))));
    const __m256 cos_view = _mm256_xor_ps(nd, _mm256_set1_ps(-0.0f));
    // std::max(cos_view, 0.2f) = cos_view < 0.2 ? 0.2 : cos_view
    const __m256 clamped = _mm256_blendv_ps(cos_view, min_cos, _mm256_cmp_ps(cos_view, min_cos, _CMP_LT_OQ));
    _mm256_storeu_ps(footprint + at, _mm256_div_ps(_mm256_mul_ps(t_far, scale), clamped));
  }
}
}  // namespace

EVIO_AVX2_FN
std::uint64_t Renderer::shadePacketsAvx2(std::size_t rays, float footprint_scale, Scratch* scratch) const {
  Scratch& s = *scratch;
  const std::size_t padded = (rays + kLanes - 1) / kLanes * kLanes;
  const auto lights = static_cast<std::size_t>(scene_.shadowLightCount());
  const auto hit = [&](std::size_t r) { return (s.hit_mask[r / kLanes] >> (r % kLanes)) & 1; };

  // setupRaysAvx2 padded the rays and their columns to whole groups with
  // rays that were not traced.

  // Surface points.
  s.columns.resize(padded);
  s.hit_mask.resize(padded / kLanes);
  for (std::size_t at = 0; at < padded; at += kLanes)
    s.hit_mask[at / kLanes] = static_cast<std::uint8_t>(
        scene_.surfaceHits8Avx2(s.rays.data(), s.dx.data(), s.dy.data(), s.dz.data(), at, &s.columns));
  const scenes::SurfaceHitColumns& c = s.columns;

  // Albedo: footprints (as the scalar path), the hits grouped by material.
  s.footprint.resize(padded);
  s.material.assign(padded, 0);
  s.albedo.assign(padded, 0.0f);
  footprints8(padded, footprint_scale, s.rays.data(), c, s.dx.data(), s.dy.data(), s.dz.data(), s.footprint.data());
  for (std::size_t r = 0; r < rays; ++r)
    if (hit(r)) s.material[r] = scene_.materialOf(c.mesh[r]);
  alignas(32) float px[8], py[8], pz[8], u[8], v[8], fp[8], albedo[8];
  // Eight hits of material m, rays[i] for i < n (the rest repeat the last).
  const auto gathered = [&](int m, const std::uint32_t* rays_of, std::uint32_t n) {
    for (std::uint32_t k = 0; k < kLanes; ++k) {
      const std::uint32_t r = rays_of[std::min(k, n - 1)];
      px[k] = c.px[r];
      py[k] = c.py[r];
      pz[k] = c.pz[r];
      u[k] = c.u[r];
      v[k] = c.v[r];
      fp[k] = s.footprint[r];
    }
    scene_.albedo8Avx2(m, px, py, pz, u, v, fp, albedo);
    for (std::uint32_t k = 0; k < n; ++k) s.albedo[rays_of[k]] = albedo[k];
  };
  // Group by group of eight rays: eight hits of one material go to the
  // texture as they are, the hits of a group that some rays missed or that
  // holds several materials are gathered material by material (each lane's
  // albedo depends on its own ray only, so any grouping gives the same values).
  std::uint32_t group[8];
  for (std::size_t at = 0; at < padded; at += kLanes) {
    int left = s.hit_mask[at / kLanes];
    while (left != 0) {
      const int m = s.material[at + static_cast<std::size_t>(__builtin_ctz(static_cast<unsigned>(left)))];
      std::uint32_t n = 0;
      int lanes = 0;
      for (std::size_t j = 0; j < kLanes; ++j)
        if (((left >> j) & 1) && s.material[at + j] == m) {
          group[n++] = static_cast<std::uint32_t>(at + j);
          lanes |= 1 << j;
        }
      left &= ~lanes;
      if (lanes == 0xff) {
        scene_.albedo8Avx2(m, c.px.data() + at, c.py.data() + at, c.pz.data() + at, c.u.data() + at,
                           c.v.data() + at, s.footprint.data() + at, s.albedo.data() + at);
      } else {
        gathered(m, group, n);
      }
    }
  }


  // Light samples (light by light), then the occlusion rays in the scalar
  // path's order, ray by ray and light by light within a ray, so that Embree
  // gets the same stream.
  s.light_columns.resize(lights);
  s.shadow_origin.resize(lights);
  s.shadow_need.assign(lights * (padded / kLanes), 0);
  for (std::size_t k = 0; k < lights; ++k) {
    scenes::LightColumns& lc = s.light_columns[k];
    lc.resize(padded);
    ShadowColumns& o = s.shadow_origin[k];
    o.x.resize(padded);
    o.y.resize(padded);
    o.z.resize(padded);
    o.t_far.resize(padded);
    for (std::size_t at = 0; at < padded; at += kLanes) {
      const int hits = s.hit_mask[at / kLanes];
      if (hits == 0) continue;  // nothing reads a sample of a ray that missed
      s.shadow_need[k * (padded / kLanes) + at / kLanes] = static_cast<std::uint8_t>(
          scene_.shadowRays8Avx2(static_cast<int>(k), c, at, &lc, o.x.data() + at, o.y.data() + at,
                                 o.z.data() + at, o.t_far.data() + at) &
          hits);
    }
  }
  s.shadow.resize(padded * lights);
  s.shadow_slot.resize(padded * lights);
  std::size_t shadows = 0;
  for (std::size_t g = 0; g < padded / kLanes; ++g) {
    int any = 0;
    for (std::size_t k = 0; k < lights; ++k) any |= s.shadow_need[k * (padded / kLanes) + g];
    for (; any != 0; any &= any - 1) {
      const auto j = static_cast<std::size_t>(__builtin_ctz(static_cast<unsigned>(any)));
      const std::size_t r = g * kLanes + j;
      for (std::size_t k = 0; k < lights; ++k) {
        if (!((s.shadow_need[k * (padded / kLanes) + g] >> j) & 1)) continue;
        const scenes::LightColumns& lc = s.light_columns[k];
        const ShadowColumns& o = s.shadow_origin[k];
        scenes::setRay(s.shadow[shadows], Eigen::Vector3f(o.x[r], o.y[r], o.z[r]),
                       Eigen::Vector3f(lc.wx[r], lc.wy[r], lc.wz[r]), 0.0f, o.t_far[r]);
        s.shadow_slot[shadows++] = static_cast<std::uint32_t>(k * padded + r);
      }
    }
  }
  if (shadows > 0) {
    RTCIntersectContext coherent = scenes::intersectContext(true);
    rtcOccluded1M(scene_.embree(), &coherent, s.shadow.data(), static_cast<unsigned>(shadows), sizeof(RTCRay));
  }
  for (std::size_t i = 0; i < shadows; ++i)
    if (s.shadow[i].tfar < 0.0f) {  // occluded: tfar = -inf
      const std::uint32_t slot = s.shadow_slot[i];
      s.light_columns[slot / padded].e[slot % padded] = 0.0f;
    }

  // Radiance; rays that left the scene see the sky (or nothing).
  s.radiance.resize(padded);
  for (std::size_t at = 0; at < padded; at += kLanes)
    if (const int hits = s.hit_mask[at / kLanes]; hits != 0)
      scene_.radiance8Avx2(c, s.material.data(), s.dx.data(), s.dy.data(), s.dz.data(), s.albedo.data(),
                           s.light_columns.data(), at, hits, s.radiance.data());
  for (std::size_t r = 0; r < rays; ++r)
    if (!hit(r))
      s.radiance[r] = s.rays[r].ray.tnear <= s.rays[r].ray.tfar
                          ? scene_.background(Eigen::Vector3f(s.dx[r], s.dy[r], s.dz[r]))
                          : 0.0f;
  s.rays.resize(rays);
  return shadows;
}

EVIO_AVX2_FN
std::uint64_t Renderer::setupRaysAvx2(int tile, std::size_t rays, const Eigen::Matrix3f& R,
                                      const Eigen::Vector3f& org, Scratch* scratch) const {
  Scratch& s = *scratch;
  const std::size_t padded = (rays + kLanes - 1) / kLanes * kLanes;
  s.rays.resize(padded);
  s.dx.resize(padded);
  s.dy.resize(padded);
  s.dz.resize(padded);
  s.bx.resize(padded);
  s.by.resize(padded);
  s.bz.resize(padded);
  RTCRayHit active{};  // every field but the direction
  scenes::setRayHit(active, org, Eigen::Vector3f::UnitZ());
  RTCRayHit inactive{};  // a pixel without a ray (and the padding): tnear > tfar
  scenes::setRayHit(inactive, org, Eigen::Vector3f::UnitZ(), 1.0f, 0.0f);
  // The constant parts of a ray's record (scenes::setRayHit's values).
  static_assert(sizeof(RTCRayHit) == 80 && offsetof(RTCRayHit, ray.dir_x) == 16 && offsetof(RTCRayHit, ray.tfar) == 32 &&
                    offsetof(RTCRayHit, hit.v) == 64 && offsetof(RTCRayHit, hit.geomID) == 72,
                "RTCRayHit layout");
  const auto* on_record = reinterpret_cast<const float*>(&active);
  const auto* off_record = reinterpret_cast<const float*>(&inactive);
  const __m256 origin_on = _mm256_castps128_ps256(_mm_loadu_ps(on_record)), origin_off = _mm256_castps128_ps256(_mm_loadu_ps(off_record));
  const __m128 far_on = _mm_loadu_ps(on_record + 8), far_off = _mm_loadu_ps(off_record + 8), no_hit = _mm_loadu_ps(on_record + 16);
  // The tile's bearings, ray after ray (NaN: no ray; the padding too).
  const float* bearing = tile_bearings_.data() + static_cast<std::size_t>(tile) * 3 * tile_stride_;
  std::uint64_t traced = 0;
  for (std::size_t ri = 0; ri < padded; ri += kLanes) {
    const __m256 bx = _mm256_loadu_ps(bearing + ri);
    const __m256 by = _mm256_loadu_ps(bearing + tile_stride_ + ri);
    const __m256 bz = _mm256_loadu_ps(bearing + 2 * tile_stride_ + ri);
    const __m256 none = _mm256_cmp_ps(bx, bx, _CMP_UNORD_Q);
    _mm256_storeu_ps(s.bx.data() + ri, bx);  // for writeOutputs
    _mm256_storeu_ps(s.by.data() + ri, by);
    _mm256_storeu_ps(s.bz.data() + ri, bz);
    // d = R b, row i as Eigen evaluates it: R_i0 b_x + (R_i1 b_y + R_i2 b_z);
    // +z where there is no ray (as the scalar path).
    float* d[3] = {s.dx.data() + ri, s.dy.data() + ri, s.dz.data() + ri};
    for (int i = 0; i < 3; ++i) {
      const __m256 v = _mm256_add_ps(
          _mm256_mul_ps(_mm256_set1_ps(R(i, 0)), bx),
          _mm256_add_ps(_mm256_mul_ps(_mm256_set1_ps(R(i, 1)), by), _mm256_mul_ps(_mm256_set1_ps(R(i, 2)), bz)));
      _mm256_storeu_ps(d[i], _mm256_blendv_ps(v, _mm256_set1_ps(i == 2 ? 1.0f : 0.0f), none));
    }
    const int no_ray = _mm256_movemask_ps(none);
    // Each ray as three stores: (origin, tnear, direction, time),
    // (tfar, mask, id, flags) and (v, primID, geomID, instID) of the hit.
    // quad[k] holds (d_x, d_y, d_z, 0) of ray k in its low half and of ray
    // k + 4 in its high half.
    const __m256 dxv = _mm256_loadu_ps(d[0]), dyv = _mm256_loadu_ps(d[1]), dzv = _mm256_loadu_ps(d[2]);
    const __m256 xy_lo = _mm256_unpacklo_ps(dxv, dyv), xy_hi = _mm256_unpackhi_ps(dxv, dyv);
    const __m256 z0_lo = _mm256_unpacklo_ps(dzv, _mm256_setzero_ps()), z0_hi = _mm256_unpackhi_ps(dzv, _mm256_setzero_ps());
    const __m256 quad[4] = {_mm256_shuffle_ps(xy_lo, z0_lo, 0x44), _mm256_shuffle_ps(xy_lo, z0_lo, 0xEE),
                            _mm256_shuffle_ps(xy_hi, z0_hi, 0x44), _mm256_shuffle_ps(xy_hi, z0_hi, 0xEE)};
    for (std::size_t j = 0; j < kLanes; ++j) {
      const bool off = (no_ray >> j) & 1;
      const __m128 dir = j < 4 ? _mm256_castps256_ps128(quad[j]) : _mm256_extractf128_ps(quad[j - 4], 1);
      auto* q = reinterpret_cast<float*>(&s.rays[ri + j]);
      _mm256_storeu_ps(q, _mm256_insertf128_ps(off ? origin_off : origin_on, dir, 1));
      _mm_storeu_ps(q + 8, off ? far_off : far_on);
      _mm_storeu_ps(q + 16, no_hit);
    }
    traced += kLanes - static_cast<std::uint64_t>(__builtin_popcount(static_cast<unsigned>(no_ray)));
  }
  return traced;
}

EVIO_AVX2_FN
void Renderer::writeOutputs(int x0, int y0, int x1, int y1, const CameraVelocity* velocity, RenderOutput* out,
                            const Scratch& s) const {
  const int w = camera_.width();
  std::size_t ri = 0;
  const __m256 inf = _mm256_set1_ps(kInf), nan = _mm256_set1_ps(kNaN), zero = _mm256_setzero_ps();
  // (x, y, z) of eight pixels interleaved: lane k of output register q is
  // component (8 q + k) mod 3 of pixel (8 q + k) / 3.
  const __m256i pick[3] = {_mm256_setr_epi32(0, 0, 0, 1, 1, 1, 2, 2), _mm256_setr_epi32(2, 3, 3, 3, 4, 4, 4, 5),
                           _mm256_setr_epi32(5, 5, 6, 6, 6, 7, 7, 7)};
  // Lanes holding a y or a z component: (8 q + k) mod 3 = 1 or 2.
  const __m256 is_y[3] = {laneMask(0, 1, 0, 0, 1, 0, 0, 1), laneMask(0, 0, 1, 0, 0, 1, 0, 0), laneMask(1, 0, 0, 1, 0, 0, 1, 0)};
  const __m256 is_z[3] = {laneMask(0, 0, 1, 0, 0, 1, 0, 0), laneMask(1, 0, 0, 1, 0, 0, 1, 0), laneMask(0, 1, 0, 0, 1, 0, 0, 1)};
  for (int y = y0; y < y1; ++y) {
    float* radiance = out->radiance.ptr<float>(y);
    float* depth = out->depth.ptr<float>(y);
    cv::Vec3f* normal = out->normal.ptr<cv::Vec3f>(y);
    cv::Vec2f* flow = velocity ? out->flow.ptr<cv::Vec2f>(y) : nullptr;
    const std::size_t row = static_cast<std::size_t>(y) * static_cast<std::size_t>(w);
    int x = x0;
    // Depth and normals bypass the cache (streaming stores) where the rows
    // allow it: at 640 × 480 they are 4.9 MB a frame that nothing reads
    // during the render.
    const bool stream = (reinterpret_cast<std::uintptr_t>(depth + x0) % 32 == 0) &&
                        (reinterpret_cast<std::uintptr_t>(normal + x0) % 32 == 0);
    const auto store = [stream](float* to, __m256 v) EVIO_AVX2_LAMBDA {
      if (stream) _mm256_stream_ps(to, v);
      else _mm256_storeu_ps(to, v);
    };
    for (; x + static_cast<int>(kLanes) <= x1; x += static_cast<int>(kLanes), ri += kLanes) {
      const __m256 bz = _mm256_loadu_ps(s.bz.data() + ri);  // NaN where the pixel has no ray
      const __m256 none = _mm256_cmp_ps(bz, bz, _CMP_UNORD_Q);
      // Rays ri .. ri + 7 (a tile row need not start at a multiple of eight).
      const std::size_t g = ri / kLanes, shift = ri % kLanes;
      const unsigned bits = shift == 0 ? s.hit_mask[g] : ((s.hit_mask[g] | (unsigned{s.hit_mask[g + 1]} << 8)) >> shift) & 0xffu;
      const __m256i lane_bit = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
      const __m256 hit = _mm256_castsi256_ps(_mm256_cmpeq_epi32(
          _mm256_and_si256(_mm256_set1_epi32(static_cast<int>(bits)), lane_bit), lane_bit));
      const __m256 range = tfar8(s.rays.data() + ri);
      // radiance: 0 + L (the scalar path's sum over one ray); 0 without a ray.
      const __m256 rad = _mm256_add_ps(zero, _mm256_loadu_ps(s.radiance.data() + ri));
      _mm256_storeu_ps(radiance + x, _mm256_blendv_ps(rad, zero, none));
      const __m256 z = _mm256_blendv_ps(inf, _mm256_mul_ps(range, bz), hit);
      store(depth + x, _mm256_blendv_ps(z, nan, none));
      // normal: the shading normal where the ray hit, else 0 (also without a ray).
      const __m256 keep = _mm256_andnot_ps(none, hit);
      const __m256 n[3] = {_mm256_and_ps(keep, _mm256_loadu_ps(s.columns.nx.data() + ri)),
                           _mm256_and_ps(keep, _mm256_loadu_ps(s.columns.ny.data() + ri)),
                           _mm256_and_ps(keep, _mm256_loadu_ps(s.columns.nz.data() + ri))};
      float* nrm = reinterpret_cast<float*>(normal + x);
      for (int q = 0; q < 3; ++q) {
        const __m256 vx = _mm256_permutevar8x32_ps(n[0], pick[q]), vy = _mm256_permutevar8x32_ps(n[1], pick[q]),
                     vz = _mm256_permutevar8x32_ps(n[2], pick[q]);
        const __m256 r = _mm256_blendv_ps(_mm256_blendv_ps(vx, vy, is_y[q]), vz, is_z[q]);
        store(nrm + 8 * q, r);
      }
    }
    for (; x < x1; ++x, ++ri) {  // the rest of the row, and every pixel's flow
      const Eigen::Vector3f& b = bearings_[row + static_cast<std::size_t>(x)];
      if (std::isnan(b.x())) {
        radiance[x] = 0.0f;
        depth[x] = kNaN;
        normal[x] = cv::Vec3f(0.0f, 0.0f, 0.0f);
        continue;
      }
      float sum = 0.0f;  // as the scalar path's sum over one ray (0 + −0 = +0)
      sum += s.radiance[ri];
      radiance[x] = sum;
      const bool hit = (s.hit_mask[ri / kLanes] >> (ri % kLanes)) & 1;
      depth[x] = hit ? s.rays[ri].ray.tfar * b.z() : kInf;
      normal[x] = hit ? cv::Vec3f(s.columns.nx[ri], s.columns.ny[ri], s.columns.nz[ri]) : cv::Vec3f(0.0f, 0.0f, 0.0f);
    }
    if (flow) flowRowAvx2(y, x0, x1, ri - static_cast<std::size_t>(x1 - x0), *velocity, flow, s);
  }
  _mm_sfence();  // the streaming stores are visible before the tile is reported done
}

EVIO_AVX2_FN
void Renderer::flowRowAvx2(int y, int x0, int x1, std::size_t r0, const CameraVelocity& velocity, cv::Vec2f* flow,
                           const Scratch& s) const {
  const std::size_t row = static_cast<std::size_t>(y) * static_cast<std::size_t>(camera_.width());
  const auto hitAt = [&s](std::size_t r) { return ((s.hit_mask[r / kLanes] >> (r % kLanes)) & 1) != 0; };
  const auto onePixel = [&](int x) {
    const std::size_t r = r0 + static_cast<std::size_t>(x - x0);
    const Eigen::Vector3f& b = bearings_[row + static_cast<std::size_t>(x)];
    Vec2 f;
    const bool ok = !std::isnan(b.x()) && pixelFlow(b, hitAt(r), s.rays[r].ray.tfar, velocity, &f);
    flow[x] = ok ? cv::Vec2f(static_cast<float>(f.x()), static_cast<float>(f.y())) : cv::Vec2f(kNaN, kNaN);
  };
  int x = x0;
  if (pinhole_flow_) {
    // PinholeFlow::point and ::direction lane by lane (double), the same
    // operations in the same order; the front test is flow_in_front_.
    const __m256d fx = _mm256_set1_pd(pinhole_flow_->fx()), fy = _mm256_set1_pd(pinhole_flow_->fy());
    const __m256d zero = _mm256_setzero_pd(), one = _mm256_set1_pd(1.0), sign = _mm256_set1_pd(-0.0);
    const __m256d wx = _mm256_set1_pd(velocity.omega_C.x()), wy = _mm256_set1_pd(velocity.omega_C.y()),
                  wz = _mm256_set1_pd(velocity.omega_C.z());
    const __m256d nvx = _mm256_set1_pd(-velocity.v_C.x()), nvy = _mm256_set1_pd(-velocity.v_C.y()),
                  nvz = _mm256_set1_pd(-velocity.v_C.z());
    const __m256d inf = _mm256_set1_pd(std::numeric_limits<double>::infinity());
    const __m256d nan = _mm256_set1_pd(std::numeric_limits<double>::quiet_NaN());
    const __m256i lane_bit = _mm256_setr_epi64x(1, 2, 4, 8);
    const __m128i tfar_index = _mm_setr_epi32(0, 20, 40, 60);  // RTCRayHit is 20 floats
    static_assert(sizeof(RTCRayHit) == 20 * sizeof(float), "RTCRayHit layout");
    for (; x + 4 <= x1; x += 4) {
      const std::size_t p = row + static_cast<std::size_t>(x);
      std::uint32_t in_front = 0;  // four flags, one byte each
      std::memcpy(&in_front, flow_in_front_.data() + p, sizeof(in_front));
      if (in_front != 0x01010101u) {
        for (int k = 0; k < 4; ++k) onePixel(x + k);
        continue;
      }
      // Rays r .. r + 3: bearings (float, exactly widened), ray lengths, hits.
      const std::size_t r = r0 + static_cast<std::size_t>(x - x0);
      const __m256d b_x = _mm256_cvtps_pd(_mm_loadu_ps(s.bx.data() + r));
      const __m256d b_y = _mm256_cvtps_pd(_mm_loadu_ps(s.by.data() + r));
      const __m256d b_z = _mm256_cvtps_pd(_mm_loadu_ps(s.bz.data() + r));
      const __m256d t = _mm256_cvtps_pd(_mm_i32gather_ps(&s.rays[r].ray.tfar, tfar_index, 4));
      const std::size_t g = r / kLanes, shift = r % kLanes;
      const unsigned word = shift <= 4 ? s.hit_mask[g] : s.hit_mask[g] | (unsigned{s.hit_mask[g + 1]} << 8);
      const __m256i bits = _mm256_set1_epi64x(static_cast<long long>((word >> shift) & 0xfu));
      const __m256d is_hit = _mm256_castsi256_pd(_mm256_cmpeq_epi64(_mm256_and_si256(bits, lane_bit), lane_bit));
      // p: the point b · range where the ray hit, the bearing b elsewhere.
      const __m256d px = _mm256_blendv_pd(b_x, _mm256_mul_pd(b_x, t), is_hit);
      const __m256d py = _mm256_blendv_pd(b_y, _mm256_mul_pd(b_y, t), is_hit);
      const __m256d pz = _mm256_blendv_pd(b_z, _mm256_mul_pd(b_z, t), is_hit);
      // ω × p, then ṗ = −v − ω × p (hit) or −(ω × p) (direction).
      const __m256d cx = _mm256_sub_pd(_mm256_mul_pd(wy, pz), _mm256_mul_pd(wz, py));
      const __m256d cy = _mm256_sub_pd(_mm256_mul_pd(wz, px), _mm256_mul_pd(wx, pz));
      const __m256d cz = _mm256_sub_pd(_mm256_mul_pd(wx, py), _mm256_mul_pd(wy, px));
      const __m256d dx = _mm256_blendv_pd(_mm256_xor_pd(cx, sign), _mm256_sub_pd(nvx, cx), is_hit);
      const __m256d dy = _mm256_blendv_pd(_mm256_xor_pd(cy, sign), _mm256_sub_pd(nvy, cy), is_hit);
      const __m256d dz = _mm256_blendv_pd(_mm256_xor_pd(cz, sign), _mm256_sub_pd(nvz, cz), is_hit);
      // J = [fx z⁻¹, fx·0, fx (−a z⁻¹); fy·0, fy z⁻¹, fy (−b z⁻¹)], a = x z⁻¹, b = y z⁻¹.
      const __m256d z_inv = _mm256_div_pd(one, pz);
      const __m256d a = _mm256_mul_pd(px, z_inv), b = _mm256_mul_pd(py, z_inv);
      const __m256d u0 = _mm256_mul_pd(fx, z_inv), u1 = _mm256_mul_pd(fx, zero),
                    u2 = _mm256_mul_pd(fx, _mm256_mul_pd(_mm256_xor_pd(a, sign), z_inv));
      const __m256d v0 = _mm256_mul_pd(fy, zero), v1 = _mm256_mul_pd(fy, z_inv),
                    v2 = _mm256_mul_pd(fy, _mm256_mul_pd(_mm256_xor_pd(b, sign), z_inv));
      const __m256d u = _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(u0, dx), _mm256_mul_pd(u1, dy)), _mm256_mul_pd(u2, dz));
      const __m256d v = _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(v0, dx), _mm256_mul_pd(v1, dy)), _mm256_mul_pd(v2, dz));
      // Both finite: |value| < inf (false for NaN); else the flow is NaN
      // (the double quiet NaN narrows to kNaN's bits). Stored as (u̇, v̇) pairs.
      const __m256d finite = _mm256_and_pd(_mm256_cmp_pd(_mm256_andnot_pd(sign, u), inf, _CMP_LT_OQ),
                                           _mm256_cmp_pd(_mm256_andnot_pd(sign, v), inf, _CMP_LT_OQ));
      const __m128 u_f = _mm256_cvtpd_ps(_mm256_blendv_pd(nan, u, finite));
      const __m128 v_f = _mm256_cvtpd_ps(_mm256_blendv_pd(nan, v, finite));
      auto* out = reinterpret_cast<float*>(flow + x);
      _mm_storeu_ps(out, _mm_unpacklo_ps(u_f, v_f));
      _mm_storeu_ps(out + 4, _mm_unpackhi_ps(u_f, v_f));
    }
  }
  for (; x < x1; ++x) onePixel(x);
}

#else  // no AVX2 code path in this build: avx2_ is never set, these are never called
std::uint64_t Renderer::shadePacketsAvx2(std::size_t, float, Scratch*) const {
  throw Error("Renderer: this build has no AVX2 path");
}
std::uint64_t Renderer::setupRaysAvx2(int, std::size_t, const Eigen::Matrix3f&, const Eigen::Vector3f&,
                                      Scratch*) const {
  throw Error("Renderer: this build has no AVX2 path");
}
void Renderer::writeOutputs(int, int, int, int, const CameraVelocity*, RenderOutput*, const Scratch&) const {
  throw Error("Renderer: this build has no AVX2 path");
}
void Renderer::flowRowAvx2(int, int, int, std::size_t, const CameraVelocity&, cv::Vec2f*, const Scratch&) const {
  throw Error("Renderer: this build has no AVX2 path");
}
#endif

}  // namespace evio::simulator
