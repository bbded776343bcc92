#include "evio/simulator/event_camera.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <numbers>
#include <string>

#include "evio/core/error.h"
#include "evio/simulator/counter_rng.h"
#include "evio/simulator/fast_math.h"
#include "parallel_for.h"
#include "pending_sort.h"

namespace evio::simulator {

namespace {

constexpr std::size_t kChunk = 256;      // pixels per vectorised chunk
constexpr std::size_t kBlock = 16384;    // pixels per parallel block
constexpr float kTwoPi = 2.0f * std::numbers::pi_v<float>;

/// (1 − e^(−x)) / x for x ≥ 0, given e = e^(−x); its series below 10⁻³.
/// Both branches are computed so that loops over pixels vectorise.
inline float phiOf(float x, float e) {
  const float series = 1.0f - x * (0.5f - x * (1.0f / 6.0f));
  const float direct = (1.0f - e) / (x + 1e-30f);
  return x < 1e-3f ? series : direct;
}

/// Constants of the per-pixel arithmetic, shared by the block and the
/// per-pixel paths so that both give bit-identical results. The
/// photoreceptor cut-off is f_c(v) = fmin + fspan · v/(v + iref) + fslope · v:
/// the legacy hyperbola (fslope = 0) or κ·k·(ε + v) (fspan = 0).
struct PixelMath {
  float eps, fmin, fspan, fslope, iref, rshot, bshot, xsf;

  explicit PixelMath(const EventCamera::Options& o)
      : eps(static_cast<float>(o.logEpsilon())),
        rshot(static_cast<float>(o.shot_noise_rate_hz)),
        bshot(1.0f - static_cast<float>(o.shot_noise_bright_factor)),
        xsf(kTwoPi * static_cast<float>(o.source_follower_hz)) {
    if (o.photocurrentModel()) {
      const double k = o.photocurrentPerRadiancePa();  // pA per W/(m² sr)
      fmin = static_cast<float>(o.photoreceptor_hz_per_pa * o.dark_current_fa * 1e-3);
      fspan = 0.0f;
      fslope = static_cast<float>(o.photoreceptor_hz_per_pa * k);
      iref = static_cast<float>(o.shot_noise_reference_pa / k);
    } else {
      fmin = static_cast<float>(o.cutoff_min_hz);
      fspan = static_cast<float>(o.cutoff_max_hz - o.cutoff_min_hz);
      fslope = 0.0f;
      iref = static_cast<float>(o.reference_radiance_w_m2_sr);
    }
  }

  /// max(I, 0), NaN → 0.
  static float clampRadiance(float v) { return v > 0.0f ? v : 0.0f; }
  float logOf(float v) const { return fastLog(eps + v); }
  /// Exact first-order step over dt for an input linear from in0 to in:
  /// the output at the new sample, from out0, with x = 2π f_c dt.
  static float lowPass(float x, float in, float in0, float out0) {
    const float e = fastExpNonPositive(-x);
    return in + (out0 - in0) * e - (in - in0) * phiOf(x, e);
  }
  /// L_p at the new sample (photoreceptor).
  float photoreceptor(float v, float dt_s, float lin, float lin0, float lp0) const {
    const float fc = fmin + fspan * (v / (v + iref)) + fslope * v;
    return lowPass(kTwoPi * fc * dt_s, lin, lin0, lp0);
  }
  /// L_f at the new sample (source follower of fixed cut-off).
  float follower(float dt_s, float lp, float lp0, float lf0) const { return lowPass(xsf * dt_s, lp, lp0, lf0); }
  float shotRate(float v) const { return rshot * (1.0f - bshot * (v / (v + iref))); }
};

}  // namespace

const char* eventLabelName(EventLabel label) {
  switch (label) {
    case EventLabel::kSignal: return "signal";
    case EventLabel::kLeak: return "leak";
    case EventLabel::kShot: return "shot";
    case EventLabel::kHot: return "hot";
  }
  return "unknown";
}

void EventCamera::Options::validate() const {
  requirePositive("threshold_pos", threshold_pos);
  requirePositive("threshold_neg", threshold_neg);
  requireNonNegative("threshold_mismatch_sigma", threshold_mismatch_sigma);
  requireNonNegative("threshold_jitter_sigma", threshold_jitter_sigma);
  requirePositive("threshold_min", threshold_min);
  requireNonNegative("refractory_period_s", refractory_period_s);
  requireInRange("refractory_mismatch_sigma", refractory_mismatch_sigma, 0.0, 1.0);
  requirePositive("log_eps_w_m2_sr", log_eps_w_m2_sr);
  requireInRange("cutoff_max_hz", cutoff_max_hz, 0.0, 1e6);
  requirePositive("cutoff_min_hz", cutoff_min_hz);
  requireField(cutoff_max_hz == 0.0 || cutoff_min_hz <= cutoff_max_hz, "cutoff_min_hz",
               "must be <= cutoff_max_hz");
  requirePositive("reference_radiance_w_m2_sr", reference_radiance_w_m2_sr);
  requireField(bandwidth_model == "radiance" || bandwidth_model == "photocurrent", "bandwidth_model",
               "must be radiance or photocurrent");
  requireInRange("f_number", f_number, 0.5, 64.0);
  requireInRange("lens_transmission", lens_transmission, 1e-3, 1.0);
  requireInRange("photodiode_area_um2", photodiode_area_um2, 1e-3, 1e4);
  requireInRange("quantum_efficiency", quantum_efficiency, 1e-3, 1.0);
  requireInRange("wavelength_nm", wavelength_nm, 200.0, 2000.0);
  requireInRange("dark_current_fa", dark_current_fa, 1e-3, 1e6);
  requireInRange("photoreceptor_hz_per_pa", photoreceptor_hz_per_pa, 1e-3, 1e7);
  requireInRange("shot_noise_reference_pa", shot_noise_reference_pa, 1e-6, 1e6);
  requireInRange("source_follower_hz", source_follower_hz, 0.0, 1e7);
  requireInRange("ba_filter_window_s", ba_filter_window_s, 0.0, 10.0);
  // Noise rates are per pixel; real sensors stay below ~1 Hz. The bounds keep
  // a typo from turning a short sequence into an endless event stream.
  requireInRange("leak_rate_hz", leak_rate_hz, 0.0, 1e4);
  requireInRange("shot_noise_rate_hz", shot_noise_rate_hz, 0.0, 1e4);
  requireInRange("shot_noise_bright_factor", shot_noise_bright_factor, 0.0, 1e3);
  requireInRange("hot_pixel_fraction", hot_pixel_fraction, 0.0, 1.0);
  requireInRange("hot_pixel_rate_hz", hot_pixel_rate_hz, 0.0, 1e4);
  requireInRange("threads", threads, 0, 1024);
}

double EventCamera::Options::photocurrentPerRadiancePa() const {
  constexpr double kPlanck = 6.62607015e-34;      // J s
  constexpr double kLight = 2.99792458e8;         // m/s
  constexpr double kElectron = 1.602176634e-19;   // C
  const double photons_per_joule = wavelength_nm * 1e-9 / (kPlanck * kLight);
  const double etendue = std::numbers::pi * lens_transmission / (4.0 * f_number * f_number);  // (W/m²)/(W/(m² sr))
  return kElectron * quantum_efficiency * photodiode_area_um2 * 1e-12 * photons_per_joule * etendue * 1e12;
}

double EventCamera::Options::logEpsilon() const {
  return photocurrentModel() ? dark_current_fa * 1e-3 / photocurrentPerRadiancePa() : log_eps_w_m2_sr;
}

double EventCamera::Options::photoreceptorCutoffHz(double radiance) const {
  const double v = std::max(radiance, 0.0);
  if (photocurrentModel()) return photoreceptor_hz_per_pa * (photocurrentPerRadiancePa() * v + dark_current_fa * 1e-3);
  if (cutoff_max_hz == 0.0) return 0.0;
  return cutoff_min_hz + (cutoff_max_hz - cutoff_min_hz) * v / (v + reference_radiance_w_m2_sr);
}

EventCamera::EventCamera(int width, int height, const Options& options, std::uint64_t seed)
    : width_(width),
      height_(height),
      options_(options),
      leak_rng_(seed, "event_leak"),
      hot_rng_(seed, "event_hot_pixels") {
  options_.validate();
  requireField(width > 0 && height > 0 && width <= 65536 && height <= 65536, "width/height",
               "must be in [1, 65536]");
  n_ = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  key_mismatch_ = counterKey(seed, "event_threshold_mismatch");
  key_jitter_ = counterKey(seed, "event_jitter");
  key_shot_ = counterKey(seed, "event_shot_noise");
  bandwidth_ = options_.photocurrentModel() || options_.cutoff_max_hz > 0.0;
  follower_ = options_.source_follower_hz > 0.0;
  if (options_.ba_filter_window_s > 0.0)
    ba_filter_ = std::make_unique<BackgroundActivityFilter>(width, height, secondsToNs(options_.ba_filter_window_s));
  shot_ = options_.shot_noise_rate_hz > 0.0;
  jitter_ = options_.threshold_jitter_sigma > 0.0;
  refractory_ns_ = secondsToNs(options_.refractory_period_s);
  if (options_.refractory_mismatch_sigma > 0.0) {
    const std::uint64_t key = counterKey(seed, "event_refractory_mismatch");
    refractory_px_.resize(static_cast<std::size_t>(width) * static_cast<std::size_t>(height));
    for (std::size_t i = 0; i < refractory_px_.size(); ++i)
      refractory_px_[i] = secondsToNs(options_.refractory_period_s *
                                      std::exp(options_.refractory_mismatch_sigma * counterNormal(key, i, 0)));
  }

  t_prev_.assign(n_, 0);
  t_last_event_.assign(n_, std::numeric_limits<TimeNs>::min() / 2);
  lin_prev_.assign(n_, 0.0f);
  lf_prev_.assign(n_, 0.0f);
  if (follower_) lpr_prev_.assign(n_, 0.0f);
  ref_.assign(n_, 0.0f);
  th_pos_.resize(n_);
  th_neg_.resize(n_);
  shot_budget_.resize(n_);
  crossing_count_.assign(n_, 0);
  shot_count_.assign(n_, 0);
  const float c_min = static_cast<float>(options_.threshold_min);
  for (std::size_t i = 0; i < n_; ++i) {
    th_pos_[i] = thresholdPos(i);
    th_neg_[i] = thresholdNeg(i);
    if (jitter_) {
      const double s = options_.threshold_jitter_sigma;
      th_pos_[i] = std::max(c_min, th_pos_[i] + static_cast<float>(s * counterNormal(key_jitter_, i, 0)));
      th_neg_[i] = std::max(c_min, th_neg_[i] + static_cast<float>(s * counterNormal(key_jitter_, i, 1)));
    }
    shot_budget_[i] = static_cast<float>(counterExponential(key_shot_, i, 0));
  }

  // Hot pixels: a partial Fisher–Yates shuffle draws round(fraction · N) distinct pixels.
  const auto hot_count = static_cast<std::size_t>(std::llround(options_.hot_pixel_fraction * static_cast<double>(n_)));
  if (hot_count > 0) {
    std::vector<std::uint32_t> index(n_);
    for (std::size_t i = 0; i < n_; ++i) index[i] = static_cast<std::uint32_t>(i);
    for (std::size_t k = 0; k < hot_count; ++k) {
      const std::size_t j = k + static_cast<std::size_t>(hot_rng_.uniformInt(n_ - k));
      std::swap(index[k], index[j]);
    }
    hot_pixels_.assign(index.begin(), index.begin() + static_cast<std::ptrdiff_t>(hot_count));
    std::sort(hot_pixels_.begin(), hot_pixels_.end());
  }
}

float EventCamera::thresholdPos(std::size_t i) const {
  const double c = options_.threshold_pos + options_.threshold_mismatch_sigma * counterNormal(key_mismatch_, i, 0);
  return static_cast<float>(std::max(options_.threshold_min, c));
}

float EventCamera::thresholdNeg(std::size_t i) const {
  const double c = options_.threshold_neg + options_.threshold_mismatch_sigma * counterNormal(key_mismatch_, i, 1);
  return static_cast<float>(std::max(options_.threshold_min, c));
}

bool EventCamera::isHot(std::size_t i) const {
  return std::binary_search(hot_pixels_.begin(), hot_pixels_.end(), static_cast<std::uint32_t>(i));
}

void EventCamera::initialize(TimeNs t_ns, const cv::Mat& radiance) {
  require(radiance.type() == CV_32FC1 && radiance.rows == height_ && radiance.cols == width_ &&
              radiance.isContinuous(),
          "EventCamera: radiance must be a continuous CV_32FC1 image of " + std::to_string(width_) + "x" +
              std::to_string(height_));
  initialize(t_ns, radiance.ptr<float>());
}

void EventCamera::initialize(TimeNs t_ns, const float* radiance) {
  require(!initialized_, "EventCamera::initialize: already initialised");
  const PixelMath pm(options_);
  for (std::size_t i = 0; i < n_; ++i) {
    const float l = pm.logOf(PixelMath::clampRadiance(radiance[i]));
    lin_prev_[i] = l;
    lf_prev_[i] = l;
    if (follower_) lpr_prev_[i] = l;
    ref_[i] = l;
  }
  uniform_ = true;
  uniform_t_ = t_ns;
  t_max_sample_ = t_ns;
  t_init_ = t_ns;
  noise_done_ns_ = t_ns;
  const double n = static_cast<double>(n_);
  if (options_.leak_rate_hz > 0.0)
    next_leak_ns_ = static_cast<double>(t_ns) + 1e9 * leak_rng_.exponential(options_.leak_rate_hz * n);
  if (!hot_pixels_.empty() && options_.hot_pixel_rate_hz > 0.0)
    next_hot_ns_ = static_cast<double>(t_ns) +
                   1e9 * hot_rng_.exponential(options_.hot_pixel_rate_hz * static_cast<double>(hot_pixels_.size()));
  pixel_updates_ += n_;
  initialized_ = true;
}

void EventCamera::update(TimeNs t_ns, const cv::Mat& radiance, EventArray* events,
                         std::vector<EventLabel>* labels) {
  require(radiance.type() == CV_32FC1 && radiance.rows == height_ && radiance.cols == width_ &&
              radiance.isContinuous(),
          "EventCamera: radiance must be a continuous CV_32FC1 image of " + std::to_string(width_) + "x" +
              std::to_string(height_));
  update(t_ns, radiance.ptr<float>(), events, labels);
}

void EventCamera::update(TimeNs t_ns, const float* radiance, EventArray* events,
                         std::vector<EventLabel>* labels) {
  if (!initialized_) {
    initialize(t_ns, radiance);
    return;
  }
  if (t_ns <= t_max_sample_)
    throw Error("EventCamera::update: time " + std::to_string(t_ns) +
                                    " ns is not after the last sample " + std::to_string(t_max_sample_) + " ns");
  const std::size_t blocks = (n_ + kBlock - 1) / kBlock;
  block_events_.resize(blocks);
  const auto run = [&](std::size_t b) {
    block_events_[b].clear();
    processBlock(b * kBlock, std::min(n_, (b + 1) * kBlock), t_ns, radiance, &block_events_[b]);
  };
  parallelFor(options_.threads, blocks, 1, run);
  for (const auto& block : block_events_) pending_.insert(pending_.end(), block.begin(), block.end());
  uniform_ = true;
  uniform_t_ = t_ns;
  t_max_sample_ = t_ns;
  pixel_updates_ += n_;
  generateTimedNoise(t_ns);
  appendSorted(t_ns, events, labels);
}

// Compiled twice, for the baseline x86-64 target and for AVX2 (chosen at
// load time): eight pixels per vector instead of four, the same float
// operations per pixel (no FMA: target "avx2" does not enable it and the
// project compiles with -ffp-contract=off), so the same events (test:
// EventCamera.UpdateRectsIsUpdatePixelsForEveryPixelOfTheRectangles, against
// the scalar per-pixel path).
#if defined(__GNUC__) && defined(__x86_64__) && !defined(__clang__)
__attribute__((target_clones("avx2", "default")))
#endif
void EventCamera::processBlock(std::size_t begin, std::size_t end, TimeNs t_ns, const float* radiance,
                               std::vector<Pending>* out) {
  const PixelMath pm(options_);
  float lin[kChunk], lp[kChunk], lf[kChunk], dt[kChunk], hazard[kChunk], rate[kChunk], v[kChunk];
  std::uint8_t cross[kChunk + 8] = {}, shot[kChunk + 8] = {};  // + 8: whole 8-byte words at the end
  const bool uniform = uniform_;
  const float dt_uniform = static_cast<float>(t_ns - uniform_t_) * 1e-9f;
  for (std::size_t c = begin; c < end; c += kChunk) {
    const std::size_t m = std::min(kChunk, end - c);
    const float* in = radiance + c;
    for (std::size_t j = 0; j < m; ++j) {
      v[j] = PixelMath::clampRadiance(in[j]);
      lin[j] = pm.logOf(v[j]);
    }
    if (uniform) {
      for (std::size_t j = 0; j < m; ++j) dt[j] = dt_uniform;
    } else {
      for (std::size_t j = 0; j < m; ++j) dt[j] = static_cast<float>(t_ns - t_prev_[c + j]) * 1e-9f;
    }
    const float* lp0 = (follower_ ? lpr_prev_.data() : lf_prev_.data()) + c;
    if (bandwidth_) {
      const float* lin0 = lin_prev_.data() + c;
      for (std::size_t j = 0; j < m; ++j) lp[j] = pm.photoreceptor(v[j], dt[j], lin[j], lin0[j], lp0[j]);
    } else {
      for (std::size_t j = 0; j < m; ++j) lp[j] = lin[j];
    }
    if (follower_) {
      const float* lf_old = lf_prev_.data() + c;
      for (std::size_t j = 0; j < m; ++j) lf[j] = pm.follower(dt[j], lp[j], lp0[j], lf_old[j]);
    } else {
      for (std::size_t j = 0; j < m; ++j) lf[j] = lp[j];
    }
    if (shot_) {
      for (std::size_t j = 0; j < m; ++j) {
        rate[j] = pm.shotRate(v[j]);
        hazard[j] = rate[j] * dt[j];
      }
    }
    // Flags first (vectorised), then the rare slow paths.
    const float* ref = ref_.data() + c;
    const float* thp = th_pos_.data() + c;
    const float* thn = th_neg_.data() + c;
    const float* lf0 = lf_prev_.data() + c;
    float* budget = shot_budget_.data() + c;
    for (std::size_t j = 0; j < m; ++j)
      cross[j] = static_cast<std::uint8_t>((lf[j] - ref[j] >= thp[j]) | (ref[j] - lf[j] >= thn[j]));
    if (shot_) {
      for (std::size_t j = 0; j < m; ++j) {
        const bool event = hazard[j] >= budget[j];
        shot[j] = static_cast<std::uint8_t>(event);
        budget[j] -= event ? 0.0f : hazard[j];
      }
    } else {
      std::fill(shot, shot + m, std::uint8_t{0});
    }
    for (std::size_t j = 0; j < m; j += 8) {
      std::uint64_t any_cross = 0, any_shot = 0;  // 8 flags at a time
      std::memcpy(&any_cross, cross + j, 8);
      std::memcpy(&any_shot, shot + j, 8);
      if ((any_cross | any_shot) == 0) continue;
      for (std::size_t q = j; q < std::min(m, j + 8); ++q) {
        const TimeNs t0 = uniform ? uniform_t_ : t_prev_[c + q];
        if (cross[q] != 0) crossings(c + q, t0, t_ns, lf0[q], lf[q], out);
        if (shot[q] != 0) shotNoise(c + q, t0, t_ns, hazard[q], rate[q], out);
      }
    }
    std::copy(lf, lf + m, lf_prev_.data() + c);
    if (follower_) std::copy(lp, lp + m, lpr_prev_.data() + c);
    if (bandwidth_) std::copy(lin, lin + m, lin_prev_.data() + c);
  }
}

void EventCamera::crossings(std::size_t i, TimeNs t0, TimeNs t1, float l0, float l1, std::vector<Pending>* out) {
  float r = ref_[i];
  float thp = th_pos_[i], thn = th_neg_[i];
  const double dl = static_cast<double>(l1) - static_cast<double>(l0);
  const double span = static_cast<double>(t1 - t0);
  const float c_min = static_cast<float>(options_.threshold_min);
  const TimeNs refractory = refractoryNs(i);
  float base_pos = 0.0f, base_neg = 0.0f;
  if (jitter_) {
    base_pos = thresholdPos(i);
    base_neg = thresholdNeg(i);
  }
  const auto cross = [&](bool positive) {
    double frac = dl != 0.0 ? (static_cast<double>(r) - static_cast<double>(l0)) / dl : 1.0;
    frac = std::clamp(frac, 0.0, 1.0);
    const TimeNs t = std::clamp<TimeNs>(t0 + static_cast<TimeNs>(frac * span + 0.5), t0 + 1, t1);
    if (t - t_last_event_[i] >= refractory) {
      out->push_back(Pending{t, static_cast<std::uint32_t>(i), static_cast<std::uint8_t>(positive ? 1 : 0),
                             EventLabel::kSignal});
      t_last_event_[i] = t;
    }
    const std::uint32_t k = ++crossing_count_[i];
    if (jitter_) {
      const double s = options_.threshold_jitter_sigma;
      thp = std::max(c_min, base_pos + static_cast<float>(s * counterNormal(key_jitter_, i, 2ull * k)));
      thn = std::max(c_min, base_neg + static_cast<float>(s * counterNormal(key_jitter_, i, 2ull * k + 1)));
    }
  };
  if (l1 - r >= thp) {
    while (l1 - r >= thp) {
      r += thp;
      cross(true);
    }
  } else {
    while (r - l1 >= thn) {
      r -= thn;
      cross(false);
    }
  }
  ref_[i] = r;
  th_pos_[i] = thp;
  th_neg_[i] = thn;
}

void EventCamera::shotNoise(std::size_t i, TimeNs t0, TimeNs t1, float hazard, float rate_hz,
                            std::vector<Pending>* out) {
  // Cumulative hazard rate·(t − t0) reaches the pending Exp(1) budget at each event.
  double acc = static_cast<double>(shot_budget_[i]);
  const double h = static_cast<double>(hazard);
  std::uint32_t k = shot_count_[i];
  const TimeNs refractory = refractoryNs(i);
  while (acc <= h) {
    const TimeNs t =
        std::clamp<TimeNs>(t0 + static_cast<TimeNs>(acc / static_cast<double>(rate_hz) * 1e9 + 0.5), t0 + 1, t1);
    const bool positive = counterUniform(key_shot_, i, 2ull * k + 1) < 0.5;
    // A shot event is a real reset of the pixel: none within the refractory
    // period of the pixel's last emitted event, on either side (the signal
    // crossings of this interval are placed first).
    const TimeNs gap = t - t_last_event_[i];
    if (gap >= refractory || -gap >= refractory) {
      out->push_back(Pending{t, static_cast<std::uint32_t>(i), static_cast<std::uint8_t>(positive ? 1 : 0),
                             EventLabel::kShot});
      t_last_event_[i] = std::max(t_last_event_[i], t);
    }
    ++k;
    acc += counterExponential(key_shot_, i, 2ull * k);
  }
  shot_count_[i] = k;
  shot_budget_[i] = static_cast<float>(acc - h);
}

void EventCamera::beginPerPixel(std::size_t i, TimeNs t_ns) {
  if (!initialized_) throw Error("EventCamera::updatePixel: call initialize() or update() first");
  if (i >= n_) throw Error("EventCamera::updatePixel: pixel index " + std::to_string(i) + " out of range");
  if (uniform_) {
    std::fill(t_prev_.begin(), t_prev_.end(), uniform_t_);
    uniform_ = false;
  }
  if (t_ns <= t_prev_[i])
    throw Error("EventCamera::updatePixel: time " + std::to_string(t_ns) + " ns of pixel " + std::to_string(i) +
                " is not after its last sample " + std::to_string(t_prev_[i]) + " ns");
}

void EventCamera::updatePixel(std::size_t i, TimeNs t_ns, float radiance) {
  beginPerPixel(i, t_ns);
  stepPixel(i, t_ns, radiance);
  t_max_sample_ = std::max(t_max_sample_, t_ns);
  ++pixel_updates_;
}

void EventCamera::updatePixels(TimeNs t_ns, const std::uint32_t* indices, const float* radiance, std::size_t count) {
  for (std::size_t k = 0; k < count; ++k) beginPerPixel(indices[k], t_ns);  // all checks before any change
  for (std::size_t k = 0; k < count; ++k) stepPixel(indices[k], t_ns, radiance[k]);
  if (count > 0) t_max_sample_ = std::max(t_max_sample_, t_ns);
  pixel_updates_ += count;
}

inline void EventCamera::stepPixel(std::size_t i, TimeNs t_ns, float radiance) {
  const TimeNs t0 = t_prev_[i];
  const PixelMath pm(options_);
  const float v = PixelMath::clampRadiance(radiance);
  const float lin = pm.logOf(v);
  const float dt = static_cast<float>(t_ns - t0) * 1e-9f;
  float lp = lin;
  const float lp0 = follower_ ? lpr_prev_[i] : lf_prev_[i];
  if (bandwidth_) {
    lp = pm.photoreceptor(v, dt, lin, lin_prev_[i], lp0);
    lin_prev_[i] = lin;
  }
  float lf = lp;
  if (follower_) {
    lf = pm.follower(dt, lp, lp0, lf_prev_[i]);
    lpr_prev_[i] = lp;
  }
  if (lf - ref_[i] >= th_pos_[i] || ref_[i] - lf >= th_neg_[i]) crossings(i, t0, t_ns, lf_prev_[i], lf, &pending_);
  if (shot_) {
    const float rate = pm.shotRate(v);
    const float hazard = rate * dt;
    if (hazard >= shot_budget_[i]) {
      shotNoise(i, t0, t_ns, hazard, rate, &pending_);
    } else {
      shot_budget_[i] -= hazard;
    }
  }
  lf_prev_[i] = lf;
  t_prev_[i] = t_ns;
}

TimeNs EventCamera::emit(EventArray* events, std::vector<EventLabel>* labels) {
  require(initialized_, "EventCamera::emit: call initialize() or update() first");
  const TimeNs watermark = uniform_ ? uniform_t_ : *std::min_element(t_prev_.begin(), t_prev_.end());
  generateTimedNoise(watermark);
  appendSorted(watermark, events, labels);
  return watermark;
}

void EventCamera::generateTimedNoise(TimeNs up_to) {
  if (up_to <= noise_done_ns_) return;
  const double limit = static_cast<double>(up_to) + 1.0;  // floor(t) <= up_to
  if (options_.leak_rate_hz > 0.0) {
    const double rate = options_.leak_rate_hz * static_cast<double>(n_);
    while (next_leak_ns_ < limit) {
      const auto pixel = static_cast<std::uint32_t>(leak_rng_.uniformInt(n_));
      pending_.push_back(Pending{static_cast<TimeNs>(next_leak_ns_), pixel, 1, EventLabel::kLeak});
      next_leak_ns_ += 1e9 * leak_rng_.exponential(rate);
    }
  }
  if (!hot_pixels_.empty() && options_.hot_pixel_rate_hz > 0.0) {
    const double rate = options_.hot_pixel_rate_hz * static_cast<double>(hot_pixels_.size());
    while (next_hot_ns_ < limit) {
      const std::uint32_t pixel = hot_pixels_[hot_rng_.uniformInt(hot_pixels_.size())];
      pending_.push_back(Pending{static_cast<TimeNs>(next_hot_ns_), pixel, 1, EventLabel::kHot});
      next_hot_ns_ += 1e9 * hot_rng_.exponential(rate);
    }
  }
  noise_done_ns_ = up_to;
}

void EventCamera::appendSorted(TimeNs watermark, EventArray* events, std::vector<EventLabel>* labels) {
  const auto ready_end = std::partition(pending_.begin(), pending_.end(),
                                        [watermark](const Pending& p) { return p.t_ns <= watermark; });
  sortPending(pending_.begin(), ready_end, n_, &sort_keys_, &sort_scratch_);
  const auto ready = static_cast<std::size_t>(ready_end - pending_.begin());
  const auto w = static_cast<std::uint32_t>(width_);
  std::size_t count = ready;
  if (ba_filter_) {  // in output order, as the camera's logic sees them; kept events move to the front
    count = 0;
    for (std::size_t j = 0; j < ready; ++j) {
      const Pending& e = pending_[j];
      if (ba_filter_->pass(static_cast<std::uint16_t>(e.pixel % w), static_cast<std::uint16_t>(e.pixel / w), e.t_ns))
        pending_[count++] = e;
    }
    ba_dropped_ += ready - count;
  }
  if (events != nullptr) {
    const std::size_t base = events->size();
    events->resize(base + count);
    TimeNs* t = events->t().data() + base;
    std::uint16_t* x = events->x().data() + base;
    std::uint16_t* y = events->y().data() + base;
    std::uint8_t* p = events->p().data() + base;
    for (std::size_t j = 0; j < count; ++j) {
      const Pending& e = pending_[j];
      t[j] = e.t_ns;
      x[j] = static_cast<std::uint16_t>(e.pixel % w);
      y[j] = static_cast<std::uint16_t>(e.pixel / w);
      p[j] = e.positive;
    }
  }
  if (labels != nullptr) {
    const std::size_t base = labels->size();
    labels->resize(base + count);
    for (std::size_t j = 0; j < count; ++j) (*labels)[base + j] = pending_[j].label;
  }
  pending_.erase(pending_.begin(), pending_.begin() + static_cast<std::ptrdiff_t>(ready));
}

}  // namespace evio::simulator
