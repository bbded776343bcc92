#pragma once
/// @file event_camera.h
/// The event camera: a per-pixel state machine over radiance samples
/// (ESIM, Rebecq et al. CoRL 2018; noise after v2e, Hu, Liu & Delbruck,
/// CVPRW 2021), with every event labelled signal or noise.
///
/// Per pixel i, for a sample (t, I) with I the radiance in W/(m²·sr):
///
///  1. Log input. bandwidth_model "radiance" (the legacy model):
///       L_in = log(ε + max(I, 0))     (NaN radiance counts as 0).
///     bandwidth_model "photocurrent": the photodiode current through the
///     optics (on-axis camera equation, one wavelength λ, as frame_camera.h),
///       I_ph = k · I,   k = q · QE · A_pd · λ/(h c) · π T / (4 N²)   [A per W/(m²·sr)]
///     (N the f-number, T the lens transmission, A_pd the photodiode area,
///     QE the quantum efficiency), and the log of photo plus dark current,
///       L_in = log(I_ph + I_dark) = log k + log(ε + I),   ε = I_dark / k;
///     the constant log k cancels in every threshold comparison, so the
///     pixel runs on log(ε + I) with that physical ε.
///  2. Bandwidth: the photoreceptor is a first-order low-pass
///       τ dL_p/dt = L_in(t) − L_p,   τ = 1 / (2π f_c(I)),
///     solved exactly for L_in linear between the two samples and f_c held at
///     the newer sample's value over the interval (x = Δt/τ):
///       L_p(t1) = L_in(t1) + (L_p(t0) − L_in(t0)) e^(−x) − ΔL_in (1 − e^(−x)) / x.
///     "radiance": f_c(I) = f_min + (f_max − f_min) · I / (I + I_ref), the
///     legacy knob (none when cutoff_max_hz = 0: L_p = L_in).
///     "photocurrent": f_c = κ · (I_ph + I_dark), the adaptive photoreceptor's
///     pole proportional to the photocurrent (Delbruck & Mead 1994;
///     Lichtsteiner, Posch & Delbruck, IEEE JSSC 2008: bandwidth rises with
///     illumination, 3 kHz at 1 klux), κ = photoreceptor_hz_per_pa. So
///     lag grows as 1/I in the dark.
///     Then, when source_follower_hz > 0, the source-follower buffer: a second
///     first-order low-pass of fixed cut-off f_sf (set by its bias, not by the
///     light) from L_p to L_f, by the same formula with L_p taken linear
///     between samples. Without it L_f = L_p.
///  3. Events: the pixel stores a reference r. While L_f(t1) ≥ r + C⁺_k:
///     r += C⁺_k and an ON event is timed where the straight line from
///     (t0, L_f(t0)) to (t1, L_f(t1)) crosses r (rounded to ns, kept in
///     (t0, t1]); OFF alike with r −= C⁻_k. So after every sample
///     r − C⁻ < L_f < r + C⁺, and Σ polarity·threshold = r − r_0.
///  4. Thresholds: C^±_i = max(C_min, C^± + σ_m z^±_i), z fixed per pixel
///     (stream "event_threshold_mismatch"); with jitter σ_j > 0 the threshold
///     of crossing k is max(C_min, C^±_i + σ_j z^±_{i,k}) ("event_jitter").
///  5. Refractory period R_i = R · exp(σ_R z_i), z_i fixed per pixel
///     ("event_refractory_mismatch"; σ_R = 0: every pixel R), the spread of
///     the pixel's refractory transistor: a crossing less than R_i after the
///     pixel's last emitted signal event moves r but emits nothing.
///  6. Noise, independent of the pixel's reference (noise events do not move
///     r), each with its own label. Shot events reset the pixel like signal
///     events: none is emitted within refractory_period_s of the pixel's last
///     emitted event (either side), and an emitted one starts a refractory
///     period. Leak and hot-pixel events ignore the refractory period:
///     - leak: ON events, Poisson at leak_rate_hz per pixel ("event_leak");
///     - shot: ON or OFF with equal probability, Poisson per pixel at
///         r_shot(I) = R_shot (1 − (1 − b) · I / (I + I_ref)),
///       R_shot in the dark, b·R_shot in bright light (v2e's linear
///       intensity dependence, its b = 0.25), the rate held at the newer
///       sample's value over each interval ("event_shot_noise"); with the
///       "photocurrent" model I_ref = shot_noise_reference_pa / k;
///     - hot pixels: round(fraction · N) pixels chosen once emit ON events,
///       Poisson at hot_pixel_rate_hz each ("event_hot_pixels").
///
///  7. Background-activity filter (ba_filter_window_s > 0): every event,
///     in output order, passes the DAVIS hardware filter of
///     background_activity_filter.h (support from one of the 8 neighbours
///     within the window) or is dropped with its label.
///
/// Determinism: every per-pixel draw is counterHash(stream key, pixel,
/// counter) (counter_rng.h), so it does not depend on the order pixels are
/// processed in or on the thread count. Leak and hot-pixel events depend on
/// time alone: the superposition of N Poisson processes of rate r is one of
/// rate N·r with a uniformly drawn pixel, drawn from a sequential stream.
/// Memory is flat: 48 bytes of state per pixel (+4 with the source
/// follower, +8 with the BA filter, +8 with a refractory spread) plus the
/// events pending.
///
/// How to drive it from a render loop:
///  - Whole frames: `update(t, radiance, &events, &labels)` once per render
///    (the first call only sets the references and emits nothing). Every
///    event up to t is emitted, time-sorted, appended to `events`.
///  - Adaptive, per pixel: after one whole-frame `update` (or `initialize`),
///    feed the pixels of each render with `updatePixels(t, indices, I, n)` or
///    `updatePixel(i, t, I)`, or whole tiles with `updateRects(t, rects, I)`
///    (each pixel's times strictly increasing; the same result any way),
///    then call `emit(&events, &labels)` once per render: it appends, time-sorted, every event at or before the watermark
///    = the earliest last-sample time over all pixels, and keeps the rest
///    pending. Events after the watermark can still be preceded by events of
///    pixels not yet sampled that far, so they wait. To end a sequence at
///    t_end, sample every pixel at t_end (e.g. one `update`) and `emit`.
///  Output order: by time, then pixel (y·width + x), then label, then polarity;
///  a total order, so the stream does not depend on the thread count.

#include <cstdint>
#include <memory>
#include <opencv2/core/mat.hpp>
#include <string>
#include <utility>
#include <vector>

#include "evio/core/event.h"
#include "evio/core/options.h"
#include "evio/core/random_stream.h"
#include "evio/core/time.h"
#include "evio/simulator/background_activity_filter.h"

namespace evio::simulator {

/// Why an event exists (truth/ labels).
enum class EventLabel : std::uint8_t {
  kSignal = 0,  ///< a contrast-threshold crossing of the (filtered) log radiance
  kLeak = 1,    ///< leak (background activity) noise
  kShot = 2,    ///< shot noise, rising in the dark
  kHot = 3,     ///< a hot pixel
};

/// "signal", "leak", "shot", "hot".
const char* eventLabelName(EventLabel label);

class EventCamera {
 public:
  struct Options {
    double threshold_pos = 0.2;             ///< C⁺, nominal ON threshold, log units
    double threshold_neg = 0.2;             ///< C⁻, nominal OFF threshold, log units
    double threshold_mismatch_sigma = 0.03; ///< σ_m of the fixed per-pixel threshold offset, log units
    double threshold_jitter_sigma = 0.0;    ///< σ_j of the per-crossing threshold noise, log units
    double threshold_min = 0.01;            ///< C_min, lower clamp of every threshold, log units
    double refractory_period_s = 0.0;       ///< dead time after an emitted signal or shot event, s
    double refractory_mismatch_sigma = 0.0; ///< σ_R of the per-pixel log refractory period
    double log_eps_w_m2_sr = 1e-3;          ///< ε of L = log(ε + I), W/(m²·sr)
    double cutoff_max_hz = 0.0;             ///< photoreceptor cut-off in bright light, Hz; 0 = ideal (no filter)
    double cutoff_min_hz = 1.0;             ///< cut-off floor in the dark, Hz
    double reference_radiance_w_m2_sr = 1.0;///< I_ref: where bandwidth and shot noise are half-way to bright ("radiance")
    std::string bandwidth_model = "radiance"; ///< "radiance" (legacy f_c(I)) or "photocurrent" (f_c ∝ I_ph)
    double f_number = 2.0;                  ///< N of the lens ("photocurrent")
    double lens_transmission = 0.9;         ///< T of the lens ("photocurrent")
    double photodiode_area_um2 = 75.0;      ///< A_pd: photosensitive area of one pixel, µm² ("photocurrent")
    double quantum_efficiency = 0.3;        ///< QE of the photodiode ("photocurrent")
    double wavelength_nm = 550.0;           ///< λ of the one-wavelength photon model, nm ("photocurrent")
    double dark_current_fa = 4.0;           ///< I_dark of the photodiode, fA ("photocurrent")
    double photoreceptor_hz_per_pa = 800.0; ///< κ: photoreceptor cut-off per pA of photocurrent ("photocurrent")
    double shot_noise_reference_pa = 1.0;   ///< photocurrent where shot noise is half-way to bright ("photocurrent")
    double source_follower_hz = 0.0;        ///< f_sf: fixed cut-off of the source-follower buffer, Hz; 0 = none
    double ba_filter_window_s = 0.0;        ///< T of the background-activity filter, s; 0 = off
    double leak_rate_hz = 0.0;              ///< leak events per pixel per second
    double shot_noise_rate_hz = 0.0;        ///< R_shot: shot-noise events per pixel per second in the dark
    double shot_noise_bright_factor = 0.25; ///< b: rate in bright light as a fraction of R_shot
    double hot_pixel_fraction = 0.0;        ///< fraction of pixels that are hot
    double hot_pixel_rate_hz = 100.0;       ///< events per second of each hot pixel
    int threads = 1;                        ///< threads of update(), 0 = all cores (output does not depend on it)

    template <class V>
    void fields(V& v) {
      v("threshold_pos", threshold_pos, "ON contrast threshold, log units");
      v("threshold_neg", threshold_neg, "OFF contrast threshold, log units");
      v("threshold_mismatch_sigma", threshold_mismatch_sigma, "per-pixel threshold sigma, log units");
      v("threshold_jitter_sigma", threshold_jitter_sigma, "per-crossing threshold sigma, log units");
      v("threshold_min", threshold_min, "lower clamp of thresholds, log units");
      v("refractory_period_s", refractory_period_s, "refractory period, s");
      v("refractory_mismatch_sigma", refractory_mismatch_sigma, "per-pixel sigma of log refractory period");
      v("log_eps_w_m2_sr", log_eps_w_m2_sr, "epsilon of log(eps + I), W/(m^2 sr)");
      v("cutoff_max_hz", cutoff_max_hz, "photoreceptor cut-off in bright light, Hz (0 = ideal)");
      v("cutoff_min_hz", cutoff_min_hz, "photoreceptor cut-off floor in the dark, Hz");
      v("reference_radiance_w_m2_sr", reference_radiance_w_m2_sr, "half-way radiance I_ref, W/(m^2 sr)");
      v("bandwidth_model", bandwidth_model, "radiance (legacy) or photocurrent");
      v("f_number", f_number, "lens f-number (photocurrent model)");
      v("lens_transmission", lens_transmission, "lens transmission (photocurrent model)");
      v("photodiode_area_um2", photodiode_area_um2, "photodiode area, um^2 (photocurrent model)");
      v("quantum_efficiency", quantum_efficiency, "quantum efficiency (photocurrent model)");
      v("wavelength_nm", wavelength_nm, "photon wavelength, nm (photocurrent model)");
      v("dark_current_fa", dark_current_fa, "photodiode dark current, fA (photocurrent model)");
      v("photoreceptor_hz_per_pa", photoreceptor_hz_per_pa, "photoreceptor cut-off per pA, Hz/pA");
      v("shot_noise_reference_pa", shot_noise_reference_pa, "half-way photocurrent of shot noise, pA");
      v("source_follower_hz", source_follower_hz, "source-follower cut-off, Hz (0 = none)");
      v("ba_filter_window_s", ba_filter_window_s, "background-activity filter window, s (0 = off)");
      v("leak_rate_hz", leak_rate_hz, "leak events per pixel per second");
      v("shot_noise_rate_hz", shot_noise_rate_hz, "shot noise per pixel per second in the dark");
      v("shot_noise_bright_factor", shot_noise_bright_factor, "bright/dark shot noise rate ratio");
      v("hot_pixel_fraction", hot_pixel_fraction, "fraction of hot pixels");
      v("hot_pixel_rate_hz", hot_pixel_rate_hz, "events per second of a hot pixel");
      v("threads", threads, "threads, 0 = all cores");
    }
    void validate() const;
    bool photocurrentModel() const { return bandwidth_model == "photocurrent"; }
    /// k: photocurrent per unit radiance, pA per W/(m²·sr) ("photocurrent").
    double photocurrentPerRadiancePa() const;
    /// ε of L = log(ε + I), W/(m²·sr): log_eps_w_m2_sr, or I_dark / k ("photocurrent").
    double logEpsilon() const;
    /// Photoreceptor cut-off at radiance I, Hz (before the source follower); 0 = no filter.
    double photoreceptorCutoffHz(double radiance_w_m2_sr) const;
  };

  /// A camera of width × height pixels (pixel index i = y·width + x).
  EventCamera(int width, int height, const Options& options, std::uint64_t seed);

  /// Sets every pixel from a first image at t_ns (CV_32FC1 W/(m²·sr), or a
  /// row-major array of width·height floats): r = L_f = L_in, no events.
  void initialize(TimeNs t_ns, const float* radiance);
  void initialize(TimeNs t_ns, const cv::Mat& radiance);
  bool initialized() const { return initialized_; }

  /// A sample of every pixel at t_ns (after every pixel's last sample; the
  /// first call initialises). Appends all events up to t_ns, time-sorted, to
  /// `events` and their labels to `labels` (may be null).
  void update(TimeNs t_ns, const float* radiance, EventArray* events, std::vector<EventLabel>* labels);
  void update(TimeNs t_ns, const cv::Mat& radiance, EventArray* events, std::vector<EventLabel>* labels);

  /// A sample of pixel `index` at t_ns (> that pixel's last sample; throws
  /// otherwise). Its events wait in the pending buffer until emit().
  void updatePixel(std::size_t index, TimeNs t_ns, float radiance);

  /// The pixels indices[0 … count) all sampled at t_ns with radiance[k]
  /// (e.g. the pixels one render re-traced): the same as updatePixel for
  /// each, faster; every sample is checked before any pixel changes.
  void updatePixels(TimeNs t_ns, const std::uint32_t* indices, const float* radiance, std::size_t count);

  /// The pixels of the image rectangles `rects` (inside the image, not
  /// overlapping) all sampled at t_ns, their radiance read from the whole
  /// image `radiance` (CV_32FC1, continuous, width × height; other pixels are
  /// not read): the same as updatePixel for each pixel, run by run of a row
  /// through the vectorised path of update(), blocks in parallel (the result
  /// does not depend on the thread count). Every sample is checked before
  /// any pixel changes. Events wait in the pending buffer until emit().
  void updateRects(TimeNs t_ns, const std::vector<cv::Rect>& rects, const cv::Mat& radiance);

  /// Appends, time-sorted, the pending events at or before the watermark
  /// (min over pixels of the last sample time) plus the leak and hot-pixel
  /// noise up to it; returns the watermark. O(pixels + pending events).
  TimeNs emit(EventArray* events, std::vector<EventLabel>* labels);

  int width() const { return width_; }
  int height() const { return height_; }
  std::size_t pixelCount() const { return n_; }
  const Options& options() const { return options_; }

  /// Time of the last sample of pixel i.
  TimeNs lastSampleTime(std::size_t i) const { return uniform_ ? uniform_t_ : t_prev_[i]; }
  /// Reference level r of pixel i (log units).
  float reference(std::size_t i) const { return ref_[i]; }
  /// Log input L_p after the photoreceptor (before the source follower) at the last sample of pixel i.
  float photoreceptorLog(std::size_t i) const { return follower_ ? lpr_prev_[i] : lf_prev_[i]; }
  /// Events the background-activity filter dropped so far.
  std::uint64_t baDropped() const { return ba_dropped_; }
  /// Filtered log radiance L_f at the last sample of pixel i.
  float filteredLog(std::size_t i) const { return lf_prev_[i]; }
  /// The pixel's fixed thresholds C^±_i (before per-crossing jitter).
  float thresholdPos(std::size_t i) const;
  float thresholdNeg(std::size_t i) const;
  /// The refractory period of pixel i, ns.
  TimeNs refractoryNs(std::size_t i) const { return refractory_px_.empty() ? refractory_ns_ : refractory_px_[i]; }
  /// Whether pixel i is hot.
  bool isHot(std::size_t i) const;
  /// Events waiting in the pending buffer.
  std::size_t pendingCount() const { return pending_.size(); }
  /// Total pixel samples processed (whole-frame pixels plus updatePixel calls).
  std::uint64_t pixelUpdates() const { return pixel_updates_; }

  /// One event before it is emitted (pixel index, not x/y).
  struct Pending {
    TimeNs t_ns;
    std::uint32_t pixel;
    std::uint8_t positive;
    EventLabel label;
  };

 private:
  void beginPerPixel(std::size_t i, TimeNs t_ns);
  void stepPixel(std::size_t i, TimeNs t_ns, float radiance);
  void processBlock(std::size_t begin, std::size_t end, TimeNs t_ns, const float* radiance,
                    std::vector<Pending>* out);
  void crossings(std::size_t i, TimeNs t0, TimeNs t1, float l0, float l1, std::vector<Pending>* out);
  void shotNoise(std::size_t i, TimeNs t0, TimeNs t1, float hazard, float rate_hz,
                 std::vector<Pending>* out);
  void generateTimedNoise(TimeNs up_to);
  void appendSorted(TimeNs watermark, EventArray* events, std::vector<EventLabel>* labels);

  int width_ = 0, height_ = 0;
  std::size_t n_ = 0;
  Options options_;
  std::uint64_t key_mismatch_ = 0, key_jitter_ = 0, key_shot_ = 0;
  bool initialized_ = false;
  bool bandwidth_ = false, follower_ = false, shot_ = false, jitter_ = false;
  TimeNs refractory_ns_ = 0;
  std::vector<TimeNs> refractory_px_;   ///< per-pixel refractory period (empty when σ_R = 0)
  TimeNs t_init_ = 0;

  // Per-pixel state (structure of arrays).
  std::vector<TimeNs> t_prev_;          ///< last sample time
  std::vector<TimeNs> t_last_event_;    ///< last emitted signal or shot event (refractory)
  std::vector<float> lin_prev_;         ///< L_in at the last sample
  std::vector<float> lf_prev_;          ///< L_f at the last sample
  std::vector<float> lpr_prev_;         ///< L_p at the last sample (source follower only)
  std::vector<float> ref_;              ///< reference r
  std::vector<float> th_pos_, th_neg_;  ///< thresholds of the next crossing
  std::vector<float> shot_budget_;      ///< remaining Exp(1) hazard to the next shot event
  std::vector<std::uint32_t> crossing_count_, shot_count_;

  // While every pixel was last sampled by update()/initialize() at the same
  // time, t_prev_ is not written: uniform_t_ holds that time.
  bool uniform_ = true;
  TimeNs uniform_t_ = 0;
  TimeNs t_max_sample_ = 0;             ///< latest sample time of any pixel

  // Leak and hot pixels: time-only Poisson processes.
  RandomStream leak_rng_, hot_rng_;
  double next_leak_ns_ = 0.0, next_hot_ns_ = 0.0;
  std::vector<std::uint32_t> hot_pixels_;   ///< sorted indices of hot pixels
  TimeNs noise_done_ns_ = 0;                ///< timed noise generated up to here

  std::unique_ptr<BackgroundActivityFilter> ba_filter_;  ///< null when off
  std::uint64_t ba_dropped_ = 0;

  std::vector<Pending> pending_;
  std::vector<std::uint64_t> sort_keys_, sort_scratch_;
  std::vector<std::vector<Pending>> block_events_;
  std::vector<std::pair<std::size_t, std::size_t>> runs_;  ///< updateRects: [begin, end) of each row run
  std::vector<std::size_t> block_starts_;                   ///< updateRects: first run of each block (+ the end)
  std::uint64_t pixel_updates_ = 0;
};

}  // namespace evio::simulator
