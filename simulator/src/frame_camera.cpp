#include "evio/simulator/frame_camera.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "evio/core/error.h"
#include "evio/simulator/counter_rng.h"
#include "evio/simulator/davis_auto_exposure.h"
#include "parallel_for.h"

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

/// ∫_{-∞}^{x} of the unit hat max(0, 1 − |s|) ds.
double hatIntegral(double x) {
  if (x <= -1.0) return 0.0;
  if (x <= 0.0) return 0.5 * (x + 1.0) * (x + 1.0);
  if (x <= 1.0) return 1.0 - 0.5 * (1.0 - x) * (1.0 - x);
  return 1.0;
}

/// Per-pixel fixed-pattern values 1 + σ·N(0,1) (or σ·N(0,1)); empty if σ = 0.
std::vector<float> fixedPattern(std::uint64_t seed, const char* stream, double sigma, double mean, std::size_t n) {
  if (sigma == 0.0) return {};
  const std::uint64_t key = counterKey(seed, stream);
  std::vector<float> out(n);
  for (std::size_t i = 0; i < n; ++i) out[i] = static_cast<float>(mean + sigma * counterNormal(key, i, 0));
  return out;
}

}  // namespace

void FrameCamera::Options::validate() const {
  requirePositive("exposure_s", exposure_s);
  requireField(auto_exposure_method == "mean_target" || auto_exposure_method == "davis", "auto_exposure_method",
               "must be mean_target or davis, not '" + auto_exposure_method + "'");
  requireInRange("auto_exposure_target", auto_exposure_target, 1e-3, 1.0);
  requireInRange("auto_exposure_min_s", auto_exposure_min_s, 1e-6, 10.0);
  requireInRange("auto_exposure_max_s", auto_exposure_max_s, 1e-6, 10.0);
  requireField(auto_exposure_min_s <= auto_exposure_max_s, "auto_exposure_max_s", "must be >= auto_exposure_min_s");
  requireInRange("auto_exposure_gain", auto_exposure_gain, 1e-3, 1.0);
  requireField(shutter == "global" || shutter == "rolling", "shutter",
               "must be global or rolling, not '" + shutter + "'");
  requireInRange("readout_s", readout_s, 0.0, 10.0);
  requireInRange("f_number", f_number, 0.5, 64.0);
  requireInRange("lens_transmission", lens_transmission, 1e-6, 1.0);
  requireInRange("pixel_pitch_um", pixel_pitch_um, 0.1, 1000.0);
  requireInRange("fill_factor", fill_factor, 1e-3, 1.0);
  requireInRange("quantum_efficiency", quantum_efficiency, 1e-6, 1.0);
  requireInRange("wavelength_nm", wavelength_nm, 200.0, 2000.0);
  requireInRange("full_well_e", full_well_e, 1.0, 1e8);
  requireInRange("dark_current_e_per_s", dark_current_e_per_s, 0.0, 1e9);
  requireInRange("read_noise_e", read_noise_e, 0.0, 1e6);
  requireInRange("dark_offset_dn", dark_offset_dn, -255.0, 255.0);
  requireInRange("saturation_dn", saturation_dn, 1.0, 1e4);
  requireInRange("gain_fpn_sigma", gain_fpn_sigma, 0.0, 0.5);
  requireInRange("offset_fpn_sigma_dn", offset_fpn_sigma_dn, 0.0, 100.0);
  requireInRange("gamma", gamma, 0.1, 10.0);
  requireInRange("threads", threads, 0, 1024);
}

FrameCamera::FrameCamera(int width, int height, const Options& options, std::uint64_t seed)
    : width_(width), height_(height), options_(options) {
  options_.validate();
  requireField(width > 0 && height > 0, "width/height", "must be > 0");
  const double p = options_.pixel_pitch_um * 1e-6;
  const double lambda = options_.wavelength_nm * 1e-9;
  k_ = std::numbers::pi * options_.lens_transmission * p * p * options_.fill_factor * options_.quantum_efficiency *
       lambda / (4.0 * options_.f_number * options_.f_number * kPlanck * kLightSpeed);
  row_time_s_ = options_.shutter == "rolling" ? options_.readout_s / height_ : 0.0;
  exposure_s_ = options_.auto_exposure
                    ? std::clamp(options_.exposure_s, options_.auto_exposure_min_s, options_.auto_exposure_max_s)
                    : options_.exposure_s;
  key_shot_ = counterKey(seed, "frame_shot_noise");
  key_read_ = counterKey(seed, "frame_read_noise");
  const std::size_t n = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  gain_ = fixedPattern(seed, "frame_gain_fpn", options_.gain_fpn_sigma, 1.0, n);
  offset_ = fixedPattern(seed, "frame_offset_fpn", options_.offset_fpn_sigma_dn, 0.0, n);
}

double FrameCamera::digitalNumber(double e, std::size_t pixel) const {
  const double x = e / options_.full_well_e;
  const double r = options_.gamma == 1.0 ? x : std::pow(std::clamp(x, 0.0, 1.0), 1.0 / options_.gamma);
  const double g = gain_.empty() ? 1.0 : static_cast<double>(gain_[pixel]);
  const double o = offset_.empty() ? 0.0 : static_cast<double>(offset_[pixel]);
  return std::clamp(o + options_.dark_offset_dn + g * options_.saturation_dn * r, 0.0, 255.0);
}

double FrameCamera::idealDn(double radiance_w_m2_sr, double exposure_s) const {
  const double e = k_ * std::max(0.0, radiance_w_m2_sr) * exposure_s + options_.dark_current_e_per_s * exposure_s;
  const double x = std::min(e, options_.full_well_e) / options_.full_well_e;
  const double r = options_.gamma == 1.0 ? x : std::pow(x, 1.0 / options_.gamma);
  return std::clamp(options_.dark_offset_dn + options_.saturation_dn * r, 0.0, 255.0);
}

void FrameCamera::rowWeights(int y, std::size_t n_sub, double exposure, std::vector<double>* weight) const {
  weight->assign(n_sub, 1.0);
  if (n_sub == 1) return;
  if (row_time_s_ == 0.0) {  // global shutter: the trapezoid rule over the exposure
    for (auto& w : *weight) w = 1.0 / static_cast<double>(n_sub - 1);
    weight->front() *= 0.5;
    weight->back() *= 0.5;
    return;
  }
  // Row y's window [a, b] on the sample axis u = t / h, h the sample spacing;
  // the weight of sample j is ∫_a^b hat(u − j) du / (b − a).
  const double h = frameSpanS(exposure) / static_cast<double>(n_sub - 1);
  const double a = y * row_time_s_ / h;
  const double b = (y * row_time_s_ + exposure) / h;
  for (std::size_t j = 0; j < n_sub; ++j) {
    const double u = static_cast<double>(j);
    (*weight)[j] = (hatIntegral(b - u) - hatIntegral(a - u)) / (b - a);
  }
}

Frame FrameCamera::capture(TimeNs t_start_ns, const std::vector<cv::Mat>& sub_samples) {
  require(!sub_samples.empty(), "FrameCamera::capture: no radiance sub-sample");
  for (const auto& s : sub_samples)
    require(s.type() == CV_32FC1 && s.rows == height_ && s.cols == width_,
            "FrameCamera::capture: sub-samples must be CV_32FC1 images of " + std::to_string(width_) + "x" +
                std::to_string(height_));
  const std::size_t n_sub = sub_samples.size();
  const double exposure = exposure_s_;
  const double e_per_radiance = k_ * exposure;
  const double dark_e = options_.dark_current_e_per_s * exposure;
  const double full_well = options_.full_well_e;
  const std::uint64_t frame = frame_index_;
  Frame out;
  out.image.create(height_, width_, CV_8UC1);
  std::vector<double> row_sum(static_cast<std::size_t>(height_), 0.0);
  std::vector<std::size_t> row_saturated(static_cast<std::size_t>(height_), 0);
  const auto rows = [&](int y0, int y1) {
    std::vector<double> weight;
    for (int y = y0; y < y1; ++y) {
      rowWeights(y, n_sub, exposure, &weight);
      std::uint8_t* o = out.image.ptr<std::uint8_t>(y);
      double sum = 0.0;
      std::size_t saturated = 0;
      for (int x = 0; x < width_; ++x) {
        double radiance = 0.0;
        for (std::size_t j = 0; j < n_sub; ++j) {
          const float v = sub_samples[j].ptr<float>(y)[x];
          radiance += weight[j] * (v > 0.0f ? static_cast<double>(v) : 0.0);  // NaN counts as 0
        }
        const std::size_t pixel = index(x, y);
        const double mu = e_per_radiance * radiance + dark_e;
        double e = options_.shot_noise ? poisson(mu, key_shot_, pixel, frame << 20) : mu;
        if (e >= full_well) {
          e = full_well;
          ++saturated;
        }
        if (options_.read_noise_e > 0.0) e += options_.read_noise_e * counterNormal(key_read_, pixel, frame);
        const double dn = std::round(digitalNumber(e, pixel));
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
    sharedArena(options_.threads).execute([&] {
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
  out.t_ns = t_start_ns + secondsToNs(0.5 * frameSpanS(exposure));
  out.mean_dn = sum / pixels;
  out.saturated_fraction = static_cast<double>(saturated) / pixels;
  updateExposure(out.image, out.mean_dn);
  ++frame_index_;
  return out;
}

void FrameCamera::updateExposure(const cv::Mat& image, double mean_dn) {
  if (!options_.auto_exposure) return;
  double next = exposure_s_;
  if (options_.auto_exposure_method == "davis") {
    const auto exposure_us = static_cast<std::int64_t>(std::llround(exposure_s_ * 1e6));
    next = 1e-6 * static_cast<double>(davisNextExposureUs(davisExposureStatistics(image), exposure_us));
  } else {
    const double mean = std::max(mean_dn / 255.0, 1.0 / 255.0);
    next = exposure_s_ *
           std::pow(options_.auto_exposure_target / mean, options_.gamma * options_.auto_exposure_gain);
  }
  exposure_s_ = std::clamp(next, options_.auto_exposure_min_s, options_.auto_exposure_max_s);
}

}  // namespace evio::simulator
