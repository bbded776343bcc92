#pragma once
/// @file frame_camera.h
/// A frame camera turning HDR radiance into 8-bit frames the way an active
/// pixel sensor (APS) does: motion blur over the exposure, global or rolling
/// shutter, photon and dark-current shot noise, saturation at full well,
/// per-pixel gain and offset (fixed-pattern noise), read noise, a dark
/// offset, clipping to the 8-bit ADC range, and two exposure controls
/// (auto-exposure toward a mean, or the DAVIS driver's). It only models the
/// sensor: co-located with the event camera (DAVIS frames) or a separate
/// camera, the caller renders the radiance with that camera's own
/// intrinsics and pose. The presets in simulator/presets/aps_*.yaml give the
/// DAVIS240C, the DAVIS346 and the old model (`aps_legacy.yaml`).
///
/// Radiometric chain per pixel (on-axis camera equation, cos⁴ fall-off and
/// vignetting ignored; all light taken as photons of one wavelength λ; the
/// scene's radiance is the radiance in the camera's band, docs/simulation.md):
///   image irradiance   E = L̄ · π T / (4 N²)                        W/m²
///   signal electrons   μ_s = FF · QE · E · p² · t_exp · λ / (h c)
///                          = K · L̄ · t_exp,   K = π T p² FF QE λ / (4 N² h c)
///   dark electrons     μ_d = I_d · t_exp
/// with f-number N, lens transmission T, pixel pitch p, fill factor FF,
/// quantum efficiency QE and dark current I_d (e⁻/s).
///
///   L̄    = the pixel's mean radiance over its own exposure window
///   n    = Poisson(μ_s + μ_d)  (exact for μ < 30; N(μ, μ) rounded above)
///   x    = (min(n, full_well) + σ_read · N(0, 1)) / full_well
///   v    = o_px + dark_offset_dn + g_px · saturation_dn · r(x)   r(x) = x, or
///                                                  clamp(x, 0, 1)^(1/γ) if γ ≠ 1
///   DN   = round(clamp(v, 0, 255))
/// g_px ~ N(1, σ_g²) and o_px ~ N(0, σ_o²) are drawn once per pixel from the
/// seed ("frame_gain_fpn", "frame_offset_fpn"). A saturated pixel therefore
/// reads dark_offset_dn + saturation_dn (± its FPN), below the ADC's 255
/// when saturation_dn is smaller; a dark pixel reads the dark offset, and 0
/// when the offset is negative (the black pile of the DAVIS frames).
///
/// Readout. Global shutter: every row integrates [t0, t0 + t_exp]. Rolling
/// shutter: row y integrates [t0 + y·t_row, t0 + y·t_row + t_exp] with
/// t_row = readout_s / height. The caller renders N ≥ 1 images evenly over
/// the frame's span [t0, t0 + (height − 1)·t_row + t_exp] (frameSpanS(),
/// both ends included; N = 1: one image held over the span); each row
/// averages the piecewise-linear interpolation of those images over its own
/// window (global shutter: the trapezoid rule).
///
/// Exposure control, after each frame (auto_exposure on):
///  - `mean_target` (the old model): t_next = clamp(t · (m*/max(m, 1/255))^(γk)),
///    m the frame's mean DN/255, m* the target, k the fraction of the correction;
///  - `davis`: the rule of iniVation's libcaer driver (davis_auto_exposure.h).
/// Both within [auto_exposure_min_s, auto_exposure_max_s]. With auto-exposure
/// off the exposure stays exposure_s (the Event-Camera Dataset recordings:
/// 5 ms).
///
/// Noise draws are counter-based per (frame, pixel) ("frame_shot_noise",
/// "frame_read_noise"), so frames do not depend on the thread count.

#include <cstdint>
#include <opencv2/core/mat.hpp>
#include <string>
#include <vector>

#include "evio/core/options.h"
#include "evio/core/time.h"

namespace evio::simulator {

/// One captured frame.
struct Frame {
  cv::Mat image;                  ///< CV_8UC1
  TimeNs t_ns = 0;                ///< stamp: middle of the frame's span (global shutter: mid-exposure)
  TimeNs t_start_ns = 0;          ///< start of the first row's exposure
  double exposure_s = 0.0;        ///< exposure time of every row
  double mean_dn = 0.0;           ///< mean of the image, DN
  double saturated_fraction = 0.0;///< fraction of pixels whose electrons reached full well
};

class FrameCamera {
 public:
  struct Options {
    double exposure_s = 0.005;           ///< fixed exposure, or the first one with auto-exposure, s
    bool auto_exposure = true;           ///< adapt the exposure after each frame
    std::string auto_exposure_method = "mean_target";  ///< mean_target or davis
    double auto_exposure_target = 0.5;   ///< mean_target: m*, target mean of DN / 255
    double auto_exposure_min_s = 1e-5;   ///< shortest exposure, s
    double auto_exposure_max_s = 0.03;   ///< longest exposure, s
    double auto_exposure_gain = 1.0;     ///< mean_target: k ∈ (0, 1], fraction of the correction per frame
    std::string shutter = "global";      ///< global or rolling
    double readout_s = 0.0;              ///< time to read the whole frame, s (rolling: row time × height)
    double f_number = 4.0;               ///< N of the lens
    double lens_transmission = 0.9;      ///< T
    double pixel_pitch_um = 6.0;         ///< p, µm
    double fill_factor = 1.0;            ///< FF: photosensitive fraction of the pixel
    double quantum_efficiency = 0.5;     ///< QE, band average
    double wavelength_nm = 550.0;        ///< λ of the photons, nm
    double full_well_e = 10000.0;        ///< saturation of the pixel, electrons
    double dark_current_e_per_s = 0.0;   ///< I_d, electrons per second
    double read_noise_e = 10.0;          ///< σ_read, electrons
    bool shot_noise = true;              ///< Poisson photon and dark-current noise
    double dark_offset_dn = 0.0;         ///< DN of an unexposed pixel before clipping (may be negative)
    double saturation_dn = 255.0;        ///< DN swing from the dark offset to full well
    double gain_fpn_sigma = 0.0;         ///< σ_g: per-pixel gain spread (relative)
    double offset_fpn_sigma_dn = 0.0;    ///< σ_o: per-pixel offset spread, DN
    double gamma = 1.0;                  ///< response curve r(x) = x^(1/γ); 1 = linear
    int threads = 1;                     ///< threads, 0 = all cores (output does not depend on it)

    template <class V>
    void fields(V& v) {
      v("exposure_s", exposure_s, "exposure (first exposure with auto-exposure), s");
      v("auto_exposure", auto_exposure, "adapt the exposure after each frame");
      v("auto_exposure_method", auto_exposure_method, "mean_target or davis (libcaer's rule)");
      v("auto_exposure_target", auto_exposure_target, "mean_target: target mean of DN/255");
      v("auto_exposure_min_s", auto_exposure_min_s, "shortest exposure, s");
      v("auto_exposure_max_s", auto_exposure_max_s, "longest exposure, s");
      v("auto_exposure_gain", auto_exposure_gain, "mean_target: fraction of the correction per frame");
      v("shutter", shutter, "global or rolling");
      v("readout_s", readout_s, "readout time of the whole frame, s");
      v("f_number", f_number, "lens f-number");
      v("lens_transmission", lens_transmission, "lens transmission");
      v("pixel_pitch_um", pixel_pitch_um, "pixel pitch, um");
      v("fill_factor", fill_factor, "photosensitive fraction of the pixel");
      v("quantum_efficiency", quantum_efficiency, "quantum efficiency (band average)");
      v("wavelength_nm", wavelength_nm, "photon wavelength, nm");
      v("full_well_e", full_well_e, "full-well capacity, electrons");
      v("dark_current_e_per_s", dark_current_e_per_s, "dark current, electrons per second");
      v("read_noise_e", read_noise_e, "read noise, electrons");
      v("shot_noise", shot_noise, "Poisson photon and dark-current noise");
      v("dark_offset_dn", dark_offset_dn, "DN of an unexposed pixel before clipping");
      v("saturation_dn", saturation_dn, "DN swing from the dark offset to full well");
      v("gain_fpn_sigma", gain_fpn_sigma, "per-pixel gain spread, relative sigma");
      v("offset_fpn_sigma_dn", offset_fpn_sigma_dn, "per-pixel offset spread, DN sigma");
      v("gamma", gamma, "response curve exponent, 1 = linear");
      v("threads", threads, "threads, 0 = all cores");
    }
    void validate() const;
  };

  FrameCamera(int width, int height, const Options& options, std::uint64_t seed);

  /// Exposure of the next frame, s.
  double exposureS() const { return exposure_s_; }
  /// Time between the first row's exposure start and the last row's
  /// exposure end for an exposure: t_exp + (height − 1)·t_row (global: t_exp).
  double frameSpanS(double exposure_s) const { return exposure_s + (height_ - 1) * row_time_s_; }
  /// Rolling shutter: delay of each row's window after the previous, s (global: 0).
  double rowTimeS() const { return row_time_s_; }

  /// Captures a frame whose first row starts exposing at t_start_ns, from
  /// N ≥ 1 CV_32FC1 radiance images (W/(m²·sr)) evenly spaced over
  /// [t_start, t_start + frameSpanS(exposureS())], both ends included.
  /// Updates the auto-exposure.
  Frame capture(TimeNs t_start_ns, const std::vector<cv::Mat>& sub_samples);

  /// K: signal electrons per (W/(m²·sr)) per second of exposure.
  double electronsPerRadianceSecond() const { return k_; }

  /// The noise-free DN (no rounding, no FPN, clamped to [0, 255]) of a mean
  /// radiance over an exposure, dark current included.
  double idealDn(double radiance_w_m2_sr, double exposure_s) const;

  /// The fixed-pattern gain g_px and offset o_px (DN) of a pixel.
  double pixelGain(int x, int y) const { return gain_.empty() ? 1.0 : static_cast<double>(gain_[index(x, y)]); }
  double pixelOffsetDn(int x, int y) const { return offset_.empty() ? 0.0 : static_cast<double>(offset_[index(x, y)]); }

  int width() const { return width_; }
  int height() const { return height_; }
  const Options& options() const { return options_; }
  std::uint64_t frameCount() const { return frame_index_; }

 private:
  std::size_t index(int x, int y) const {
    return static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) + static_cast<std::size_t>(x);
  }
  /// Weights of the N sub-samples in row y's mean radiance.
  void rowWeights(int y, std::size_t n_sub, double exposure, std::vector<double>* weight) const;
  /// The digital number of `e` electrons (read noise included) at a pixel.
  double digitalNumber(double e, std::size_t pixel) const;
  void updateExposure(const cv::Mat& image, double mean_dn);

  int width_ = 0, height_ = 0;
  Options options_;
  double k_ = 0.0;
  double row_time_s_ = 0.0;
  double exposure_s_ = 0.0;
  std::vector<float> gain_, offset_;   ///< per-pixel FPN; empty when its σ is 0
  std::uint64_t key_shot_ = 0, key_read_ = 0;
  std::uint64_t frame_index_ = 0;
};

}  // namespace evio::simulator
