#include "evio/simulator/adaptive_sampler.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

#include "evio/core/cpu_features.h"
#include "evio/core/error.h"

#if defined(__GNUC__) && defined(__x86_64__)
#include <immintrin.h>
#endif

namespace evio::simulator {

void AdaptiveSampler::Options::validate() const {
  requireInRange("lambda", lambda, 1e-3, 10.0);
  requireInRange("min_rate_hz", min_rate_hz, 1e-3, 1e5);
  requireInRange("max_rate_hz", max_rate_hz, 1e-3, 1e5);
  requireField(max_rate_hz >= min_rate_hz, "max_rate_hz", "must be >= min_rate_hz");
  requireInRange("tile_px", tile_px, 1, 1024);
}

AdaptiveSampler::AdaptiveSampler(const Options& options, double threshold, double log_eps)
    : options_(options), threshold_(threshold), log_eps_(static_cast<float>(log_eps)), avx2_(cpuHasAvx2()) {
  options_.validate();
  requirePositive("threshold", threshold);
  requirePositive("log_eps", log_eps);
  min_interval_ns_ = std::max<TimeNs>(1, secondsToNs(1.0 / options_.max_rate_hz));
  max_interval_ns_ = std::max<TimeNs>(min_interval_ns_, secondsToNs(1.0 / options_.min_rate_hz));
}

cv::Mat AdaptiveSampler::logImage(const cv::Mat& radiance) const {
  require(radiance.type() == CV_32FC1, "AdaptiveSampler: radiance must be CV_32FC1");
  cv::Mat out(radiance.size(), CV_32FC1);
  for (int y = 0; y < radiance.rows; ++y) {
    const float* in = radiance.ptr<float>(y);
    float* o = out.ptr<float>(y);
    for (int x = 0; x < radiance.cols; ++x) o[x] = std::log(log_eps_ + (in[x] > 0.0f ? in[x] : 0.0f));
  }
  return out;
}

void AdaptiveSampler::logRow(const cv::Mat& radiance, int y, int x0, int x1, cv::Mat* log_image) const {
  const float* in = radiance.ptr<float>(y);
  float* o = log_image->ptr<float>(y);
  for (int x = x0; x < x1; ++x) o[x] = std::log(log_eps_ + (in[x] > 0.0f ? in[x] : 0.0f));  // as logImage
}

namespace {
constexpr float kDiag = 0.70710678f;     ///< 1 / ‖q − p‖ of a diagonal neighbour
constexpr float kBound = 1.0823922f;     ///< 1 / cos 22.5°

#if defined(__GNUC__) && defined(__x86_64__)
/// The interior loop of logRatesOfRow for x in [xa, xb), eight pixels per
/// step (AVX2, no FMA): per lane the scalar loop's operations in its order
/// (max(d, slope) is "d > slope ? d : slope"; sqrt correctly rounded as
/// std::sqrt); returns the first x it did not do.
__attribute__((target("avx2"))) int interiorRatesAvx2(const float* up, const float* mid, const float* down,
                                                       const cv::Vec2f* f, int xa, int xb, float* rates) {
  const __m256 sign = _mm256_set1_ps(-0.0f), diag = _mm256_set1_ps(kDiag), one = _mm256_set1_ps(1.0f);
  const __m256 bound = _mm256_set1_ps(kBound), inf = _mm256_set1_ps(std::numeric_limits<float>::infinity());
  int x = xa;
  for (; x + 8 <= xb; x += 8) {
    const __m256 l = _mm256_loadu_ps(mid + x);
    __m256 slope = _mm256_setzero_ps();
    const auto take = [&](const float* row, int dx, __m256 weight) __attribute__((target("avx2"), always_inline)) {
      const __m256 d = _mm256_mul_ps(_mm256_andnot_ps(sign, _mm256_sub_ps(_mm256_loadu_ps(row + x + dx), l)), weight);
      slope = _mm256_max_ps(d, slope);
    };
    take(up, -1, diag);
    take(up, 0, one);
    take(up, 1, diag);
    take(mid, -1, one);
    take(mid, 1, one);
    take(down, -1, diag);
    take(down, 0, one);
    take(down, 1, diag);
    // ‖u̇v‖² = u̇·u̇ + v̇·v̇ from the interleaved (u̇, v̇) pairs, in pixel order.
    const auto* fv = reinterpret_cast<const float*>(f + x);
    const __m256 a = _mm256_loadu_ps(fv), b = _mm256_loadu_ps(fv + 8);
    const __m256 pairs = _mm256_hadd_ps(_mm256_mul_ps(a, a), _mm256_mul_ps(b, b));
    const __m256 norm2 = _mm256_castpd_ps(_mm256_permute4x64_pd(_mm256_castps_pd(pairs), 0xD8));
    const __m256 rate = _mm256_mul_ps(_mm256_mul_ps(slope, bound), _mm256_sqrt_ps(norm2));
    const __m256 finite = _mm256_cmp_ps(_mm256_andnot_ps(sign, rate), inf, _CMP_LT_OQ);
    _mm256_storeu_ps(rates + (x - xa), _mm256_and_ps(rate, finite));
  }
  return x;
}
#endif
}  // namespace

void AdaptiveSampler::logRatesOfRow(const cv::Mat& log_image, const cv::Mat& flow, int y, int x0, int x1,
                                    float* rates) const {
  const int w = log_image.cols, h = log_image.rows;
  if (!options_.rate_bound || y == 0 || y + 1 == h) {
    for (int x = x0; x < x1; ++x) rates[x - x0] = logRateAt(log_image, flow, x, y);
    return;
  }
  // Pixels with all 8 neighbours: logRateAt's float operations in the same
  // order, without its bounds tests (the maximum does not depend on the order
  // of its terms; NaN never wins).
  const int xa = std::max(x0, 1), xb = std::max(xa, std::min(x1, w - 1));
  for (int x = x0; x < xa; ++x) rates[x - x0] = logRateAt(log_image, flow, x, y);
  const float* up = log_image.ptr<float>(y - 1);
  const float* mid = log_image.ptr<float>(y);
  const float* down = log_image.ptr<float>(y + 1);
  const cv::Vec2f* f = flow.ptr<cv::Vec2f>(y);
  int x = xa;
#if defined(__GNUC__) && defined(__x86_64__)
  if (avx2_) x = interiorRatesAvx2(up, mid, down, f, xa, xb, rates + (xa - x0));
#endif
  for (; x < xb; ++x) {
    const float l = mid[x];
    float slope = 0.0f;
    const auto take = [&slope](float d) { slope = d > slope ? d : slope; };
    take(std::abs(up[x - 1] - l) * kDiag);
    take(std::abs(up[x] - l) * 1.0f);
    take(std::abs(up[x + 1] - l) * kDiag);
    take(std::abs(mid[x - 1] - l) * 1.0f);
    take(std::abs(mid[x + 1] - l) * 1.0f);
    take(std::abs(down[x - 1] - l) * kDiag);
    take(std::abs(down[x] - l) * 1.0f);
    take(std::abs(down[x + 1] - l) * kDiag);
    const float rate = slope * kBound * std::sqrt(f[x][0] * f[x][0] + f[x][1] * f[x][1]);
    rates[x - x0] = std::isfinite(rate) ? rate : 0.0f;
  }
  for (; x < x1; ++x) rates[x - x0] = logRateAt(log_image, flow, x, y);
}

float AdaptiveSampler::logRateAt(const cv::Mat& log_image, const cv::Mat& flow, int x, int y) const {
  const int w = log_image.cols, h = log_image.rows;
  const cv::Vec2f f = flow.at<cv::Vec2f>(y, x);
  float rate = 0.0f;
  if (options_.rate_bound) {
    const float l = log_image.at<float>(y, x);
    float slope = 0.0f;
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const int qx = x + dx, qy = y + dy;
        if ((dx == 0 && dy == 0) || qx < 0 || qy < 0 || qx >= w || qy >= h) continue;
        const float d = std::abs(log_image.at<float>(qy, qx) - l) * (dx != 0 && dy != 0 ? 0.70710678f : 1.0f);
        if (d > slope) slope = d;  // NaN never wins
      }
    // The steepest of 8 directions is within 22.5° of ∇L: slope / cos 22.5° >= ‖∇L‖ for linear L.
    rate = slope * 1.0823922f * std::sqrt(f[0] * f[0] + f[1] * f[1]);
  } else {
    const int x0 = std::max(0, x - 1), x1 = std::min(w - 1, x + 1);
    const int y0 = std::max(0, y - 1), y1 = std::min(h - 1, y + 1);
    const float gx = x1 > x0 ? (log_image.at<float>(y, x1) - log_image.at<float>(y, x0)) / static_cast<float>(x1 - x0)
                             : 0.0f;
    const float gy = y1 > y0 ? (log_image.at<float>(y1, x) - log_image.at<float>(y0, x)) / static_cast<float>(y1 - y0)
                             : 0.0f;
    rate = std::abs(gx * f[0] + gy * f[1]);
  }
  return std::isfinite(rate) ? rate : 0.0f;
}

namespace {
/// A key of a float's bits that sorts as the floats do (−0 before +0).
std::uint32_t orderedKey(float v) {
  std::uint32_t bits = 0;
  std::memcpy(&bits, &v, sizeof(bits));
  return (bits & 0x80000000u) != 0 ? ~bits : bits | 0x80000000u;
}
}  // namespace

float AdaptiveSampler::kthSmallest(std::vector<float>* values, std::size_t k) {
  std::vector<float>& v = *values;
  require(k < v.size(), "AdaptiveSampler::kthSmallest: k out of range");
  // Bins of the top 12 bits of the key: count, find the k-th's bin, then
  // select within the values of that bin only.
  constexpr int kShift = 20;
  std::array<std::uint32_t, (1u << (32 - kShift))> count{};
  for (const float x : v) ++count[orderedKey(x) >> kShift];
  std::size_t below = 0, bin = 0;
  while (below + count[bin] <= k) below += count[bin++];
  std::size_t n = 0;  // the bin's values, moved to the front
  for (std::size_t i = 0; i < v.size(); ++i)
    if ((orderedKey(v[i]) >> kShift) == bin) std::swap(v[n++], v[i]);
  const auto kth = v.begin() + static_cast<std::ptrdiff_t>(k - below);
  std::nth_element(v.begin(), kth, v.begin() + static_cast<std::ptrdiff_t>(n));
  return *kth;
}

TimeNs AdaptiveSampler::interval(float log_rate) const {
  const double rate = static_cast<double>(log_rate);
  if (!(rate > 0.0)) return max_interval_ns_;
  const double dt_ns = options_.lambda * threshold_ / rate * 1e9;
  if (dt_ns >= static_cast<double>(max_interval_ns_)) return max_interval_ns_;
  return std::max(min_interval_ns_, static_cast<TimeNs>(dt_ns));
}

void AdaptiveSampler::schedule(TimeNs t_ns, const cv::Mat& radiance, const cv::Mat& flow,
                               std::vector<TimeNs>* next_ns) const {
  require(flow.type() == CV_32FC2 && flow.size() == radiance.size(),
          "AdaptiveSampler::schedule: flow must be CV_32FC2 of the radiance's size");
  const cv::Mat l = logImage(radiance);
  const int w = radiance.cols, h = radiance.rows;
  next_ns->resize(static_cast<std::size_t>(w) * static_cast<std::size_t>(h));
  const int tile = options_.tile_px;
  for (int ty = 0; ty < h; ty += tile) {
    for (int tx = 0; tx < w; tx += tile) {
      const int ye = std::min(h, ty + tile), xe = std::min(w, tx + tile);
      TimeNs tile_dt = max_interval_ns_;
      for (int y = ty; y < ye; ++y)
        for (int x = tx; x < xe; ++x) {
          const TimeNs dt = interval(logRateAt(l, flow, x, y));
          if (tile == 1) {
            (*next_ns)[static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x)] =
                t_ns + dt;
          }
          tile_dt = std::min(tile_dt, dt);
        }
      if (tile > 1)
        for (int y = ty; y < ye; ++y)
          for (int x = tx; x < xe; ++x)
            (*next_ns)[static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x)] =
                t_ns + tile_dt;
    }
  }
}

TimeNs AdaptiveSampler::wholeFrameInterval(const cv::Mat& radiance, const cv::Mat& flow) const {
  require(flow.type() == CV_32FC2 && flow.size() == radiance.size(),
          "AdaptiveSampler::wholeFrameInterval: flow must be CV_32FC2 of the radiance's size");
  const cv::Mat l = logImage(radiance);
  float max_rate = 0.0f;
  for (int y = 0; y < radiance.rows; ++y)
    for (int x = 0; x < radiance.cols; ++x) max_rate = std::max(max_rate, logRateAt(l, flow, x, y));
  return interval(max_rate);
}

}  // namespace evio::simulator
