#include "evio/scenes/mip_map.h"

#include <algorithm>
#include <cmath>

#include "evio/core/error.h"
#include "avx2.h"

namespace evio::scenes {

MipMap::MipMap(const cv::Mat& image, bool repeat) : repeat_(repeat) {
  require(!image.empty() && image.type() == CV_32FC1, "MipMap: expected a non-empty CV_32FC1 image");
  levels_.push_back(image.clone());
  while (levels_.back().cols > 1 || levels_.back().rows > 1) {
    const cv::Mat& a = levels_.back();
    const int w = std::max(1, a.cols / 2), h = std::max(1, a.rows / 2);
    cv::Mat b(h, w, CV_32FC1);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        // Source block: 2 × 2, widened to 3 at an odd last row/column.
        const int x0 = 2 * x, y0 = 2 * y;
        const int x1 = (x == w - 1) ? a.cols : std::min(a.cols, x0 + 2);
        const int y1 = (y == h - 1) ? a.rows : std::min(a.rows, y0 + 2);
        double sum = 0.0;
        for (int yy = y0; yy < y1; ++yy)
          for (int xx = x0; xx < x1; ++xx) sum += static_cast<double>(a.at<float>(yy, xx));
        b.at<float>(y, x) = static_cast<float>(sum / ((x1 - x0) * (y1 - y0)));
      }
    levels_.push_back(b);
  }
  // One unpadded buffer for all levels (the 8-lane lookup indexes it with
  // 32-bit offsets); levels_ become views into it.
  std::size_t total = 0;
  for (const cv::Mat& m : levels_) total += m.total();
  require(total < (std::size_t{1} << 30), "MipMap: image too large");
  texels_.create(1, static_cast<int>(total) + 1, CV_32FC1);  // + 1: the 8-lane lookup reads texel i + 1
  texels_.at<float>(0, static_cast<int>(total)) = 0.0f;
  int first = 0;
  for (cv::Mat& m : levels_) {
    cv::Mat view = texels_.colRange(first, first + static_cast<int>(m.total())).reshape(1, m.rows);
    m.copyTo(view);
    first_.push_back(first);
    cols_.push_back(m.cols);
    rows_.push_back(m.rows);
    fcols_.push_back(static_cast<float>(m.cols));
    frows_.push_back(static_cast<float>(m.rows));
    first += static_cast<int>(m.total());
    m = view;
  }
  for (const cv::Mat& m : levels_)
    table_.push_back(Level{m.data, m.step[0], m.cols, m.rows, static_cast<float>(m.cols), static_cast<float>(m.rows)});
  fcols0_ = table_[0].fcols;
  frows0_ = table_[0].frows;
}

#if defined(EVIO_SCENES_AVX2)
namespace {
/// One level's parameters per lane: columns and rows (as int and float)
/// and the index of its first texel in the flat buffer.
struct LevelParams {
  __m256 fcols, frows;
  __m256i cols, rows, first;
};

/// texels[i_k] and texels[i_k + 1] of eight lanes: each pair read as one
/// 64-bit element (four per gather instead of eight single floats), then
/// split into the two columns.
EVIO_AVX2_INLINE void texelPairs(const float* texels, __m256i i, __m256* first, __m256* second) {
  const auto* base = reinterpret_cast<const long long*>(texels);
  const __m256 lo = _mm256_castsi256_ps(_mm256_i32gather_epi64(base, _mm256_castsi256_si128(i), 4));       // lanes 0-3
  const __m256 hi = _mm256_castsi256_ps(_mm256_i32gather_epi64(base, _mm256_extracti128_si256(i, 1), 4));  // lanes 4-7
  // lo = a0 b0 a1 b1 | a2 b2 a3 b3, hi = a4 b4 a5 b5 | a6 b6 a7 b7
  const __m256 a = _mm256_shuffle_ps(lo, hi, 0x88);  // a0 a1 a4 a5 | a2 a3 a6 a7
  const __m256 b = _mm256_shuffle_ps(lo, hi, 0xDD);  // b0 b1 b4 b5 | b2 b3 b6 b7
  *first = _mm256_castpd_ps(_mm256_permute4x64_pd(_mm256_castps_pd(a), 0xD8));
  *second = _mm256_castpd_ps(_mm256_permute4x64_pd(_mm256_castps_pd(b), 0xD8));
}

/// The bilinear lookups of MipMap::bilinear, eight lanes at a time; `ok`
/// collects the lanes that stayed inside their level (the others are
/// recomputed by the scalar lookup).
EVIO_AVX2_INLINE __m256 bilinear8(const float* texels, const LevelParams& l, __m256 fcols0, __m256 frows0, __m256 s,
                                  __m256 t, __m256* ok) {
  const __m256 half = _mm256_set1_ps(0.5f);
  // x = s · cols_l / cols_0 − 0.5 (texel centres at integers), as in bilinear().
  const __m256 x = _mm256_sub_ps(_mm256_div_ps(_mm256_mul_ps(s, l.fcols), fcols0), half);
  const __m256 y = _mm256_sub_ps(_mm256_div_ps(_mm256_mul_ps(t, l.frows), frows0), half);
  const __m256 fx0 = _mm256_floor_ps(x), fy0 = _mm256_floor_ps(y);
  const __m256 fx = _mm256_sub_ps(x, fx0), fy = _mm256_sub_ps(y, fy0);
  const __m256i x0 = _mm256_cvttps_epi32(fx0), y0 = _mm256_cvttps_epi32(fy0);
  const __m256i one = _mm256_set1_epi32(1), neg1 = _mm256_set1_epi32(-1);
  // Inside: x0 >= 0, x0 + 1 < cols, y0 >= 0, y0 + 1 < rows.
  const __m256i in = _mm256_and_si256(
      _mm256_and_si256(_mm256_cmpgt_epi32(x0, neg1), _mm256_cmpgt_epi32(l.cols, _mm256_add_epi32(x0, one))),
      _mm256_and_si256(_mm256_cmpgt_epi32(y0, neg1), _mm256_cmpgt_epi32(l.rows, _mm256_add_epi32(y0, one))));
  *ok = _mm256_and_ps(*ok, _mm256_castsi256_ps(in));
  // Texel (x0, y0) of the level; outside lanes read texel 0.
  const __m256i i00 = _mm256_and_si256(in, _mm256_add_epi32(l.first, _mm256_add_epi32(_mm256_mullo_epi32(y0, l.cols), x0)));
  const __m256i i10 = _mm256_and_si256(in, _mm256_add_epi32(i00, l.cols));
  __m256 r00, r01, r10, r11;
  texelPairs(texels, i00, &r00, &r01);
  texelPairs(texels, i10, &r10, &r11);
  const __m256 a = avx2::lerp(r00, r01, fx);
  const __m256 b = avx2::lerp(r10, r11, fx);
  return avx2::lerp(a, b, fy);
}

}  // namespace

EVIO_AVX2 void MipMap::sample8Avx2(const float* s_in, const float* t_in, const float* footprint, float* out) const {
  const int top = levels() - 1;
  // λ = log2(footprint) per lane through the C library, as sample() does;
  // fine: footprint <= 1 (or NaN): level 0 alone.
  alignas(32) float lambda[8];
  alignas(32) int l0[8];
  for (int k = 0; k < 8; ++k) {
    const bool fine = !(footprint[k] > 1.0f);
    lambda[k] = fine ? 0.0f : std::log2(footprint[k]);
    l0[k] = fine ? 0 : !(lambda[k] < static_cast<float>(top)) ? top : static_cast<int>(lambda[k]);
  }
  const __m256 lam = _mm256_load_ps(lambda);
  const __m256i level = _mm256_load_si256(reinterpret_cast<const __m256i*>(l0));
  const __m256 fine = _mm256_cmp_ps(_mm256_loadu_ps(footprint), _mm256_set1_ps(1.0f), _CMP_NGT_UQ);
  // A single lookup at level 0 (fine) or at the top level (l0 = top).
  const __m256 single =
      _mm256_or_ps(fine, _mm256_castsi256_ps(_mm256_cmpeq_epi32(level, _mm256_set1_epi32(top))));
  // The parameters of each lane's two levels: broadcast when the eight
  // lanes share their levels (neighbouring pixels mostly do), else gathered.
  const __m256i next = _mm256_min_epi32(_mm256_add_epi32(level, _mm256_set1_epi32(1)), _mm256_set1_epi32(top));
  const auto params = [this](__m256i l) EVIO_AVX2_LAMBDA {
    const int first_level = _mm256_extract_epi32(l, 0);
    if (_mm256_movemask_epi8(_mm256_cmpeq_epi32(l, _mm256_set1_epi32(first_level))) == -1) {
      const auto k = static_cast<std::size_t>(first_level);
      return LevelParams{_mm256_set1_ps(fcols_[k]), _mm256_set1_ps(frows_[k]), _mm256_set1_epi32(cols_[k]),
                         _mm256_set1_epi32(rows_[k]), _mm256_set1_epi32(first_[k])};
    }
    return LevelParams{_mm256_i32gather_ps(fcols_.data(), l, 4), _mm256_i32gather_ps(frows_.data(), l, 4),
                       _mm256_i32gather_epi32(cols_.data(), l, 4), _mm256_i32gather_epi32(rows_.data(), l, 4),
                       _mm256_i32gather_epi32(first_.data(), l, 4)};
  };
  const float* texels = texels_.ptr<float>();
  const __m256 fcols0 = _mm256_set1_ps(fcols0_), frows0 = _mm256_set1_ps(frows0_);
  const __m256 s = _mm256_loadu_ps(s_in), t = _mm256_loadu_ps(t_in);
  __m256 ok = _mm256_castsi256_ps(_mm256_set1_epi32(-1));
  const __m256 a = bilinear8(texels, params(level), fcols0, frows0, s, t, &ok);
  if (_mm256_movemask_ps(single) == 0xff) {  // no lane blends: one level each
    _mm256_storeu_ps(out, a);
  } else {  // the next level where blending (level + 1 <= top there)
    __m256 ok_b = ok;
    const __m256 b = bilinear8(texels, params(next), fcols0, frows0, s, t, &ok_b);
    ok = _mm256_blendv_ps(ok_b, ok, single);  // the second lookup counts only where blending
    const __m256 f = _mm256_sub_ps(lam, _mm256_cvtepi32_ps(level));
    _mm256_storeu_ps(out, _mm256_blendv_ps(avx2::lerp(a, b, f), a, single));
  }
  const int inside = _mm256_movemask_ps(ok);
  if (inside != 0xff)
    for (int k = 0; k < 8; ++k)
      if (!(inside & (1 << k))) out[k] = sample(s_in[k], t_in[k], footprint[k]);
}
#else
void MipMap::sample8Avx2(const float* s, const float* t, const float* footprint, float* out) const {
  for (int k = 0; k < 8; ++k) out[k] = sample(s[k], t[k], footprint[k]);
}
#endif

}  // namespace evio::scenes
