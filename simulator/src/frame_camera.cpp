#include "evio/simulator/frame_camera.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "evio/core/error.h"
#include "evio/core/random_stream.h"
#include "evio/simulator/counter_rng.h"

namespace evio::simulator {

namespace {

constexpr double kPlanck = 6.62607015e-34;      // J s
constexpr double kLightSpeed = 299792458.0;     // m/s
constexpr double kExactPoissonBelow = 30.0;     // mean below which Poisson is drawn exactly

/// Poisson(μ) from counter-based uniforms of (key, pixel, base + j):
/// multiplication method below kExactPoissonBelow, else N(μ, μ) rounded.
double poisson(double mu, std::uint64_t key, std::uint64_t pixel, std::uint64_t base) {
  if (mu <= 0.0) return 0.0;
  if (mu >= kExactPoissonBelow)
    return std::max(0.0, std::round(mu + std::sqrt(mu) * counterNormal(key, pixel, base)));
  const double limit = std::exp(-mu);
  double prod = counterUniformPositive(key, pixel, 2 * base);
  double n = 0.0;
  for (std::uint64_t j = 1; prod > limit; ++j) {
    prod *= counterUniformPositive(key, pixel, 2 * base + j);
    n += 1.0;
  }
  return n;
}

}  // namespace

void FrameCamera::Options::validate() const {
  requirePositive("exposure_s", exposure_s);
  requireInRange("auto_exposure_target", auto_exposure_target, 1e-3, 1.0);
  requirePositive("auto_exposure_min_s", auto_exposure_min_s);
  requirePositive("auto_exposure_max_s", auto_exposure_max_s);
  requireField(auto_exposure_min_s <= auto_exposure_max_s, "auto_exposure_max_s", "must be >= auto_exposure_min_s");
  requireInRange("auto_exposure_gain", auto_exposure_gain, 1e-3, 1.0);
  requirePositive("f_number", f_number);
  requireInRange("lens_transmission", lens_transmission, 1e-6, 1.0);
  requirePositive("pixel_pitch_um", pixel_pitch_um);
  requireInRange("quantum_efficiency", quantum_efficiency, 1e-6, 1.0);
  requirePositive("wavelength_nm", wavelength_nm);
  requirePositive("full_well_e", full_well_e);
  requireNonNegative("read_noise_e", read_noise_e);
  requireInRange("gamma", gamma, 0.1, 10.0);
  requireInRange("threads", threads, 0, 1024);
}

FrameCamera::FrameCamera(int width, int height, const Options& options, std::uint64_t seed)
    : width_(width), height_(height), options_(options) {
  options_.validate();
  requireField(width > 0 && height > 0, "width/height", "must be > 0");
  const double p = options_.pixel_pitch_um * 1e-6;
  const double lambda = options_.wavelength_nm * 1e-9;
  k_ = std::numbers::pi * options_.lens_transmission * p * p * options_.quantum_efficiency * lambda /
       (4.0 * options_.f_number * options_.f_number * kPlanck * kLightSpeed);
  exposure_s_ = options_.auto_exposure
                    ? std::clamp(options_.exposure_s, options_.auto_exposure_min_s, options_.auto_exposure_max_s)
                    : options_.exposure_s;
  key_shot_ = counterKey(seed, "frame_shot_noise");
  key_read_ = counterKey(seed, "frame_read_noise");
}

double FrameCamera::idealDn(double radiance_w_m2_sr, double exposure_s) const {
  const double x = std::clamp(k_ * std::max(0.0, radiance_w_m2_sr) * exposure_s / options_.full_well_e, 0.0, 1.0);
  return 255.0 * std::pow(x, 1.0 / options_.gamma);
}

Frame FrameCamera::capture(TimeNs t_start_ns, const std::vector<cv::Mat>& sub_samples) {
  require(!sub_samples.empty(), "FrameCamera::capture: no radiance sub-sample");
  for (const auto& s : sub_samples)
    require(s.type() == CV_32FC1 && s.rows == height_ && s.cols == width_,
            "FrameCamera::capture: sub-samples must be CV_32FC1 images of " + std::to_string(width_) + "x" +
                std::to_string(height_));
  const std::size_t n_sub = sub_samples.size();
  // Trapezoid weights over n_sub evenly spaced samples, both ends included.
  std::vector<double> weight(n_sub, 1.0);
  if (n_sub > 1) {
    for (auto& w : weight) w = 1.0 / static_cast<double>(n_sub - 1);
    weight.front() *= 0.5;
    weight.back() *= 0.5;
  }
  const double exposure = exposure_s_;
  const double e_per_radiance = k_ * exposure;
  const double full_well = options_.full_well_e;
  const double inv_gamma = 1.0 / options_.gamma;
  const std::uint64_t frame = frame_index_;
  Frame out;
  out.image.create(height_, width_, CV_8UC1);
  std::vector<double> row_sum(static_cast<std::size_t>(height_), 0.0);
  std::vector<std::size_t> row_saturated(static_cast<std::size_t>(height_), 0);
  const auto rows = [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y) {
      std::uint8_t* o = out.image.ptr<std::uint8_t>(y);
      double sum = 0.0;
      std::size_t saturated = 0;
      for (int x = 0; x < width_; ++x) {
        double radiance = 0.0;
        for (std::size_t j = 0; j < n_sub; ++j) {
          const float v = sub_samples[j].ptr<float>(y)[x];
          radiance += weight[j] * (v > 0.0f ? static_cast<double>(v) : 0.0);  // NaN counts as 0
        }
        const std::uint64_t pixel = static_cast<std::uint64_t>(y) * static_cast<std::uint64_t>(width_) +
                                    static_cast<std::uint64_t>(x);
        const double mu = e_per_radiance * radiance;
        double e = options_.shot_noise ? poisson(mu, key_shot_, pixel, frame << 20) : mu;
        if (e >= full_well) {
          e = full_well;
          ++saturated;
        }
        if (options_.read_noise_e > 0.0) e += options_.read_noise_e * counterNormal(key_read_, pixel, frame);
        const double xs = std::clamp(e / full_well, 0.0, 1.0);
        const double dn = std::round(255.0 * (inv_gamma == 1.0 ? xs : std::pow(xs, inv_gamma)));
        o[x] = static_cast<std::uint8_t>(dn);
        sum += dn;
      }
      row_sum[static_cast<std::size_t>(y)] = sum;
      row_saturated[static_cast<std::size_t>(y)] = saturated;
    }
  };
  if (options_.threads == 1) {
    rows(0, height_);
  } else {
    tbb::task_arena arena = options_.threads > 0 ? tbb::task_arena(options_.threads) : tbb::task_arena();
    arena.execute([&] {
      tbb::parallel_for(tbb::blocked_range<int>(0, height_, 8),
                        [&](const tbb::blocked_range<int>& r) { rows(r.begin(), r.end()); });
    });
  }
  double sum = 0.0;
  std::size_t saturated = 0;
  for (int y = 0; y < height_; ++y) {  // fixed order: the mean does not depend on threads
    sum += row_sum[static_cast<std::size_t>(y)];
    saturated += row_saturated[static_cast<std::size_t>(y)];
  }
  const double pixels = static_cast<double>(width_) * static_cast<double>(height_);
  out.t_start_ns = t_start_ns;
  out.exposure_s = exposure;
  out.t_ns = t_start_ns + secondsToNs(0.5 * exposure);
  out.mean_dn = sum / pixels;
  out.saturated_fraction = static_cast<double>(saturated) / pixels;

  if (options_.auto_exposure) {
    const double mean = std::max(out.mean_dn / 255.0, 1.0 / 255.0);
    const double factor = std::pow(options_.auto_exposure_target / mean, options_.gamma * options_.auto_exposure_gain);
    exposure_s_ = std::clamp(exposure * factor, options_.auto_exposure_min_s, options_.auto_exposure_max_s);
  }
  ++frame_index_;
  return out;
}

}  // namespace evio::simulator
