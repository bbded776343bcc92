// Scene's 8-lane shading functions (scene.h): surfaceHit, shadowRay and
// radiance for eight rays at once with AVX2. Lane by lane they do the float
// operations of the inline scalar functions in scene.h in the same order,
// without FMA, so every lane equals the scalar result bit for bit. Eigen's
// 3-vector reductions (dot, squaredNorm) add as x + (y + z); the scalar
// code's sums of three products (w0 a + u b + v c) add left to right.
#include <cmath>
#include <cstddef>
#include <limits>
#include <numbers>

#include "avx2.h"
#include "evio/core/error.h"
#include "evio/scenes/scene.h"

namespace evio::scenes {

#if defined(EVIO_SCENES_AVX2)
namespace {

struct V3 {
  __m256 x, y, z;
};

EVIO_AVX2_INLINE __m256 dot(const V3& a, const V3& b) {
  return _mm256_add_ps(_mm256_mul_ps(a.x, b.x), _mm256_add_ps(_mm256_mul_ps(a.y, b.y), _mm256_mul_ps(a.z, b.z)));
}
EVIO_AVX2_INLINE __m256 neg(__m256 a) { return _mm256_xor_ps(a, _mm256_set1_ps(-0.0f)); }
EVIO_AVX2_INLINE V3 neg(const V3& a) { return {neg(a.x), neg(a.y), neg(a.z)}; }
EVIO_AVX2_INLINE V3 select(__m256 mask, const V3& yes, const V3& no) {
  return {_mm256_blendv_ps(no.x, yes.x, mask), _mm256_blendv_ps(no.y, yes.y, mask), _mm256_blendv_ps(no.z, yes.z, mask)};
}
/// (w0 a + u b) + v c, the barycentric interpolation of surfaceHit.
EVIO_AVX2_INLINE __m256 blend3(__m256 w0, __m256 a, __m256 u, __m256 b, __m256 v, __m256 c) {
  return _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(w0, a), _mm256_mul_ps(u, b)), _mm256_mul_ps(v, c));
}
EVIO_AVX2_INLINE V3 load(const std::vector<float>& x, const std::vector<float>& y, const std::vector<float>& z,
                         std::size_t at) {
  return {_mm256_loadu_ps(x.data() + at), _mm256_loadu_ps(y.data() + at), _mm256_loadu_ps(z.data() + at)};
}
EVIO_AVX2_INLINE V3 load(const float* x, const float* y, const float* z) {
  return {_mm256_loadu_ps(x), _mm256_loadu_ps(y), _mm256_loadu_ps(z)};
}
EVIO_AVX2_INLINE void store(const V3& a, std::vector<float>& x, std::vector<float>& y, std::vector<float>& z,
                            std::size_t at) {
  _mm256_storeu_ps(x.data() + at, a.x);
  _mm256_storeu_ps(y.data() + at, a.y);
  _mm256_storeu_ps(z.data() + at, a.z);
}

}  // namespace

/// Field f (f < fields) of eight 32-byte records as column[f], lane j from
/// record j. Each register is loaded as the same half of records j and
/// j + 4 (the load unit does the cross-lane move), then transposed 4 × 4
/// within each 128-bit half.
template <int kFields>
EVIO_AVX2_INLINE void columns8(const float* const (&record)[8], __m256 (&column)[kFields]) {
  static_assert(kFields == 4 || kFields == 8);
  for (int half = 0; half < kFields / 4; ++half) {
    __m256 r[4];
    for (int j = 0; j < 4; ++j)
      r[j] = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_load_ps(record[j] + 4 * half)),
                                  _mm_load_ps(record[j + 4] + 4 * half), 1);
    const __m256 t0 = _mm256_unpacklo_ps(r[0], r[1]), t1 = _mm256_unpacklo_ps(r[2], r[3]);
    const __m256 t2 = _mm256_unpackhi_ps(r[0], r[1]), t3 = _mm256_unpackhi_ps(r[2], r[3]);
    column[4 * half + 0] = _mm256_shuffle_ps(t0, t1, 0x44);
    column[4 * half + 1] = _mm256_shuffle_ps(t0, t1, 0xEE);
    column[4 * half + 2] = _mm256_shuffle_ps(t2, t3, 0x44);
    column[4 * half + 3] = _mm256_shuffle_ps(t2, t3, 0xEE);
  }
}

EVIO_AVX2 int Scene::surfaceHits8Avx2(const RTCRayHit* rays, const float* dx, const float* dy, const float* dz,
                                       std::size_t at, SurfaceHitColumns* out) const {
  // The eight hit records' ids and barycentrics, gathered with the stride
  // of RTCRayHit.
  static_assert(sizeof(RTCRayHit) % 4 == 0 && sizeof(ShadeTriangle) == 32 && sizeof(ShadeVertex) == 32 &&
                    offsetof(ShadeTriangle, ng) == 0 && offsetof(ShadeTriangle, v) == 12 &&
                    offsetof(ShadeVertex, p) == 0 && offsetof(ShadeVertex, n) == 12 && offsetof(ShadeVertex, uv) == 24,
                "the field order columns8 and the broadcasts assume");
  constexpr int kStride = sizeof(RTCRayHit) / 4;
  const __m256i index = _mm256_mullo_epi32(_mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7), _mm256_set1_epi32(kStride));
  const auto* base = reinterpret_cast<const int*>(rays + at);
  const __m256i geom = _mm256_i32gather_epi32(base + offsetof(RTCRayHit, hit.geomID) / 4, index, 4);
  const __m256i prim = _mm256_i32gather_epi32(base + offsetof(RTCRayHit, hit.primID) / 4, index, 4);
  const __m256 u = _mm256_i32gather_ps(reinterpret_cast<const float*>(base) + offsetof(RTCRayHit, hit.u) / 4, index, 4);
  const __m256 v = _mm256_i32gather_ps(reinterpret_cast<const float*>(base) + offsetof(RTCRayHit, hit.v) / 4, index, 4);
  const __m256i invalid = _mm256_set1_epi32(static_cast<int>(RTC_INVALID_GEOMETRY_ID));
  const int hit = ~_mm256_movemask_ps(_mm256_castsi256_ps(_mm256_cmpeq_epi32(geom, invalid))) & 0xff;
  if (hit == 0) return 0;
  _mm256_storeu_si256(reinterpret_cast<__m256i*>(out->mesh.data() + at), geom);
  _mm256_storeu_si256(reinterpret_cast<__m256i*>(out->prim.data() + at), prim);
  __m256 tri[4], vert[3][8];
  const unsigned g0 = rays[at].hit.geomID, p0 = rays[at].hit.primID;
  const bool one_triangle =
      hit == 0xff && _mm256_movemask_epi8(_mm256_and_si256(_mm256_cmpeq_epi32(geom, _mm256_set1_epi32(static_cast<int>(g0))),
                                                           _mm256_cmpeq_epi32(prim, _mm256_set1_epi32(static_cast<int>(p0))))) == -1;
  if (one_triangle) {
    // One triangle for all eight rays (large flat faces seen by coherent
    // rays): every field is a broadcast.
    const ShadeMesh& sm = shade_[g0];
    const ShadeTriangle& t = sm.triangles[p0];
    const auto* tr = reinterpret_cast<const float*>(&t);
    for (int f = 0; f < 4; ++f) tri[f] = _mm256_broadcast_ss(tr + f);
    for (int c = 0; c < 3; ++c) {
      const auto* vr = reinterpret_cast<const float*>(&sm.vertices[t.v[c]]);
      for (int f = 0; f < 8; ++f) vert[c][f] = _mm256_broadcast_ss(vr + f);
    }
  } else {
    // Each lane's triangle record and its three vertex records, then
    // transposed into columns; a lane whose ray missed reads zeros.
    alignas(32) static const float kZeros[8] = {};
    const float* tri_record[8];
    const float* vertex_record[3][8];
    for (int j = 0; j < 8; ++j) {
      const RTCRayHit& q = rays[at + static_cast<std::size_t>(j)];
      if (q.hit.geomID == RTC_INVALID_GEOMETRY_ID) {
        tri_record[j] = vertex_record[0][j] = vertex_record[1][j] = vertex_record[2][j] = kZeros;
        continue;
      }
      const ShadeMesh& sm = shade_[q.hit.geomID];
      const ShadeTriangle& t = sm.triangles[q.hit.primID];
      tri_record[j] = reinterpret_cast<const float*>(&t);
      for (int c = 0; c < 3; ++c) vertex_record[c][j] = reinterpret_cast<const float*>(&sm.vertices[t.v[c]]);
    }
    columns8(tri_record, tri);  // ng x, y, z, the first index
    for (int c = 0; c < 3; ++c) columns8(vertex_record[c], vert[c]);  // p x, y, z, n x, y, z, uv u, v
  }
  const __m256 w0 = _mm256_sub_ps(_mm256_sub_ps(_mm256_set1_ps(1.0f), u), v);
  const auto interpolate = [&](int field) EVIO_AVX2_LAMBDA {
    return blend3(w0, vert[0][field], u, vert[1][field], v, vert[2][field]);
  };
  const V3 dir = load(dx + at, dy + at, dz + at);
  const V3 p{interpolate(0), interpolate(1), interpolate(2)};
  V3 g{tri[0], tri[1], tri[2]};
  const __m256 zero = _mm256_setzero_ps();
  const __m256 degenerate = _mm256_and_ps(_mm256_and_ps(_mm256_cmp_ps(g.x, zero, _CMP_EQ_OQ), _mm256_cmp_ps(g.y, zero, _CMP_EQ_OQ)),
                                          _mm256_cmp_ps(g.z, zero, _CMP_EQ_OQ));
  g = select(degenerate, neg(dir), g);
  V3 n{interpolate(3), interpolate(4), interpolate(5)};
  const __m256 nlen2 = dot(n, n);
  const __m256 inv = _mm256_div_ps(_mm256_set1_ps(1.0f), _mm256_sqrt_ps(nlen2));
  n = select(_mm256_cmp_ps(nlen2, zero, _CMP_GT_OQ), V3{_mm256_mul_ps(n.x, inv), _mm256_mul_ps(n.y, inv), _mm256_mul_ps(n.z, inv)}, g);
  const __m256 back = _mm256_cmp_ps(dot(g, dir), zero, _CMP_GT_OQ);
  g = select(back, neg(g), g);
  n = select(back, neg(n), n);
  n = select(_mm256_cmp_ps(dot(n, dir), zero, _CMP_GE_OQ), g, n);  // a shading normal facing away from the viewer
  store(p, out->px, out->py, out->pz, at);
  store(n, out->nx, out->ny, out->nz, at);
  store(g, out->gx, out->gy, out->gz, at);
  _mm256_storeu_ps(out->u.data() + at, interpolate(6));
  _mm256_storeu_ps(out->v.data() + at, interpolate(7));
  _mm256_storeu_ps(out->b1.data() + at, u);
  _mm256_storeu_ps(out->b2.data() + at, v);
  return hit;
}

EVIO_AVX2 int Scene::shadowRays8Avx2(int k, const SurfaceHitColumns& hits, std::size_t at, LightColumns* light,
                                     float* ox, float* oy, float* oz, float* t_far) const {
  const DirectLight& d = direct_[static_cast<std::size_t>(k)];
  const V3 p = load(hits.px, hits.py, hits.pz, at);
  const V3 n = load(hits.nx, hits.ny, hits.nz, at);
  const V3 g = load(hits.gx, hits.gy, hits.gz, at);
  const __m256 zero = _mm256_setzero_ps(), one = _mm256_set1_ps(1.0f);
  const V3 light_vec{_mm256_set1_ps(d.vec.x()), _mm256_set1_ps(d.vec.y()), _mm256_set1_ps(d.vec.z())};
  // lightFrom
  V3 wi = light_vec;
  __m256 e = _mm256_set1_ps(d.power);
  if (d.kind != 0) {
    const V3 to{_mm256_sub_ps(light_vec.x, p.x), _mm256_sub_ps(light_vec.y, p.y), _mm256_sub_ps(light_vec.z, p.z)};
    const __m256 d2 = dot(to, to);
    const __m256 reach = _mm256_cmp_ps(d2, zero, _CMP_GT_OQ);
    const __m256 len = _mm256_sqrt_ps(d2);
    wi = {_mm256_div_ps(to.x, len), _mm256_div_ps(to.y, len), _mm256_div_ps(to.z, len)};
    e = _mm256_div_ps(e, d2);
    if (d.kind == 2) {
      const V3 axis{_mm256_set1_ps(d.axis.x()), _mm256_set1_ps(d.axis.y()), _mm256_set1_ps(d.axis.z())};
      const __m256 c = neg(dot(wi, axis));
      const __m256 t = avx2::clamp01(
          _mm256_div_ps(_mm256_sub_ps(c, _mm256_set1_ps(d.cos_outer)), _mm256_set1_ps(d.cos_inner - d.cos_outer)));
      e = _mm256_mul_ps(e, _mm256_mul_ps(_mm256_mul_ps(t, t), _mm256_sub_ps(_mm256_set1_ps(3.0f), _mm256_mul_ps(_mm256_set1_ps(2.0f), t))));
    }
    e = _mm256_and_ps(e, reach);
    wi = select(reach, wi, n);
  }
  // shadowRay: reachable only in front of both normals.
  const __m256 lit = _mm256_and_ps(
      _mm256_cmp_ps(e, zero, _CMP_GT_OQ),
      _mm256_and_ps(_mm256_cmp_ps(dot(g, wi), zero, _CMP_NLE_UQ), _mm256_cmp_ps(dot(n, wi), zero, _CMP_NLE_UQ)));
  const __m256 abs_mask = _mm256_castsi256_ps(_mm256_set1_epi32(0x7fffffff));
  // cwiseAbs().maxCoeff() = std::max(|x|, std::max(|y|, |z|)); std::max(a, b)
  // is (a < b ? b : a), which is _mm256_max_ps(b, a) also when one is NaN.
  const __m256 largest = _mm256_max_ps(_mm256_max_ps(_mm256_and_ps(p.z, abs_mask), _mm256_and_ps(p.y, abs_mask)),
                                       _mm256_and_ps(p.x, abs_mask));
  const __m256 eps = _mm256_mul_ps(_mm256_set1_ps(5e-5f), _mm256_add_ps(one, largest));
  const V3 o{_mm256_add_ps(p.x, _mm256_mul_ps(eps, g.x)), _mm256_add_ps(p.y, _mm256_mul_ps(eps, g.y)),
             _mm256_add_ps(p.z, _mm256_mul_ps(eps, g.z))};
  __m256 far = _mm256_set1_ps(std::numeric_limits<float>::infinity());
  if (d.kind != 0) {
    const V3 to{_mm256_sub_ps(light_vec.x, o.x), _mm256_sub_ps(light_vec.y, o.y), _mm256_sub_ps(light_vec.z, o.z)};
    far = _mm256_mul_ps(_mm256_sqrt_ps(dot(to, to)), _mm256_set1_ps(1.0f - 1e-5f));
  }
  // The renderer's LightSample: {wi, e} where lit, else {+z, 0}.
  const V3 unit_z{zero, zero, one};
  store(select(lit, wi, unit_z), light->wx, light->wy, light->wz, at);
  _mm256_storeu_ps(light->e.data() + at, _mm256_and_ps(e, lit));
  _mm256_storeu_ps(ox, o.x);
  _mm256_storeu_ps(oy, o.y);
  _mm256_storeu_ps(oz, o.z);
  _mm256_storeu_ps(t_far, far);
  return _mm256_movemask_ps(lit);
}

EVIO_AVX2 void Scene::radiance8Avx2(const SurfaceHitColumns& hits, const int* material, const float* dx,
                                    const float* dy, const float* dz, const float* albedo, const LightColumns* lights,
                                    std::size_t at, int lanes, float* out) const {
  constexpr float kInvPi = 0.318309886183790671538f;
  const __m256 zero = _mm256_setzero_ps(), inv_pi = _mm256_set1_ps(kInvPi);
  const __m256i m = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(material + at));
  const __m256 oren_nayar = _mm256_castsi256_ps(
      _mm256_cmpeq_epi32(_mm256_i32gather_epi32(oren_nayar_.data(), m, 4), _mm256_set1_epi32(1)));
  const __m256 a = _mm256_i32gather_ps(on_a_.data(), m, 4), b = _mm256_i32gather_ps(on_b_.data(), m, 4);
  const V3 n = load(hits.nx, hits.ny, hits.nz, at);
  const V3 wo = neg(load(dx + at, dy + at, dz + at));  // towards the viewer
  const __m256 c_o = dot(n, wo);
  __m256 l = zero;
  for (std::size_t k = 0; k < direct_.size(); ++k) {
    const LightColumns& s = lights[k];
    const V3 wi = load(s.wx, s.wy, s.wz, at);
    const __m256 e = _mm256_loadu_ps(s.e.data() + at);
    const __m256 c_i = dot(n, wi);
    const __m256 on = _mm256_and_ps(_mm256_cmp_ps(e, zero, _CMP_GT_OQ), _mm256_cmp_ps(c_i, zero, _CMP_NLE_UQ));
    if (_mm256_movemask_ps(on) == 0) continue;
    // Reflectance::brdfOverAlbedo
    const __m256 sv = _mm256_sub_ps(dot(wi, wo), _mm256_mul_ps(c_i, c_o));
    const __m256 mx = _mm256_blendv_ps(c_o, c_i, _mm256_cmp_ps(c_i, c_o, _CMP_GT_OQ));
    const __m256 rough = _mm256_blendv_ps(zero, _mm256_div_ps(_mm256_mul_ps(b, sv), mx), _mm256_cmp_ps(sv, zero, _CMP_GT_OQ));
    __m256 brdf = _mm256_mul_ps(inv_pi, _mm256_add_ps(a, rough));
    brdf = _mm256_blendv_ps(brdf, _mm256_mul_ps(a, inv_pi), _mm256_cmp_ps(c_o, zero, _CMP_LE_OQ));
    brdf = _mm256_blendv_ps(inv_pi, brdf, oren_nayar);
    l = _mm256_blendv_ps(l, _mm256_add_ps(l, _mm256_mul_ps(_mm256_mul_ps(brdf, e), c_i)), on);
  }
  __m256 e_amb;
  if (indirect_on_) {  // interpolate(): (1 − b1 − b2) v0 + b1 v1 + b2 v2, 0 for a mesh without values
    alignas(32) float v0[8], v1[8], v2[8];
    for (int j = 0; j < 8; ++j) {
      const std::size_t r = at + static_cast<std::size_t>(j);
      if (!((lanes >> j) & 1) || indirect_[hits.mesh[r]].empty()) {
        v0[j] = v1[j] = v2[j] = 0.0f;
        continue;
      }
      const auto& values = indirect_[hits.mesh[r]];
      const std::uint32_t* t = shade_[hits.mesh[r]].triangles[hits.prim[r]].v;
      v0[j] = values[t[0]];
      v1[j] = values[t[1]];
      v2[j] = values[t[2]];
    }
    const __m256 b1 = _mm256_loadu_ps(hits.b1.data() + at), b2 = _mm256_loadu_ps(hits.b2.data() + at);
    e_amb = blend3(_mm256_sub_ps(_mm256_sub_ps(_mm256_set1_ps(1.0f), b1), b2), _mm256_load_ps(v0), b1,
                   _mm256_load_ps(v1), b2, _mm256_load_ps(v2));
    // A mesh without values gives exactly 0 in the scalar code (not 0 · x).
    for (int j = 0; j < 8; ++j)
      if (((lanes >> j) & 1) && indirect_[hits.mesh[at + static_cast<std::size_t>(j)]].empty())
        reinterpret_cast<float*>(&e_amb)[j] = 0.0f;
  } else {
    e_amb = _mm256_mul_ps(_mm256_set1_ps(std::numbers::pi_v<float> * sky_radiance_ * 0.5f),
                          _mm256_add_ps(_mm256_set1_ps(1.0f), n.z));
  }
  const __m256 r = _mm256_mul_ps(_mm256_loadu_ps(albedo + at),
                                 _mm256_add_ps(l, _mm256_mul_ps(e_amb, _mm256_set1_ps(1.0f / std::numbers::pi_v<float>))));
  _mm256_storeu_ps(out + at, r);
}

#else
int Scene::surfaceHits8Avx2(const RTCRayHit*, const float*, const float*, const float*, std::size_t,
                             SurfaceHitColumns*) const {
  throw Error("Scene::surfaceHits8Avx2: this build has no AVX2 path");
}
int Scene::shadowRays8Avx2(int, const SurfaceHitColumns&, std::size_t, LightColumns*, float*, float*, float*,
                           float*) const {
  throw Error("Scene::shadowRays8Avx2: this build has no AVX2 path");
}
void Scene::radiance8Avx2(const SurfaceHitColumns&, const int*, const float*, const float*, const float*,
                          const float*, const LightColumns*, std::size_t, int, float*) const {
  throw Error("Scene::radiance8Avx2: this build has no AVX2 path");
}
#endif

}  // namespace evio::scenes
