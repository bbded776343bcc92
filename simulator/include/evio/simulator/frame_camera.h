#pragma once
/// @file frame_camera.h
/// A global-shutter frame camera turning HDR radiance into 8-bit frames the
/// way a real one does: motion blur over the exposure, auto-exposure, photon
/// shot noise, read noise, saturation at full well, response curve and
/// quantisation. It only models the sensor: co-located with the event camera
/// (DAVIS frames) or a separate camera (the Mars-yard rig's mvBlueFOX), the
/// caller renders the radiance with that camera's own intrinsics and pose.
///
/// Radiometric chain per pixel (on-axis camera equation, cos⁴ fall-off and
/// vignetting ignored; all light taken as photons of one wavelength λ):
///   image irradiance   E = L̄ · π T / (4 N²)          W/m²  (L̄ mean radiance)
///   electrons          μ = QE · E · p² · t_exp · λ / (h c)
///                        = K · L̄ · t_exp,   K = π T p² QE λ / (4 N² h c)
/// with f-number N, lens transmission T, pixel pitch p, quantum efficiency
/// QE. With the defaults K ≈ 2.2·10⁶ e⁻ per (W/(m²·sr)·s): 20 W/(m²·sr)
/// (Mars-yard sunlit sand) fills a 10 000 e⁻ well in 0.23 ms, the yard's
/// shadow (≈ 1.3) in 3.5 ms, and a lava-tube interior (≈ 0.01) gives
/// ≈ 660 e⁻ in 30 ms: dark and noisy.
///
///   L̄     = trapezoid mean of the sub-sample images over the exposure
///   n     = Poisson(μ)        (exact for μ < 30; N(μ, μ) rounded above, whose
///                               error is below the read noise for μ ≥ 30)
///   n'    = min(n, full_well) + N(0, σ_read²)
///   DN    = round(255 · clamp(n' / full_well, 0, 1)^(1/γ))     (γ = 1: linear)
///
/// Auto-exposure after each frame, toward a target mean m* of DN/255:
///   t_next = clamp(t · (m* / max(m, 1/255))^(γ·k), t_min, t_max),
/// k the fraction of the correction applied per frame.
/// Noise draws are counter-based per (frame, pixel) ("frame_shot_noise",
/// "frame_read_noise"), so frames do not depend on the thread count.
///
/// In a render loop, per frame: read exposureS() for the next frame, render
/// N ≥ 1 radiance images at t_start + j · exposure / (N − 1), j = 0 … N − 1
/// (N = 1: one image held over the exposure), and call capture(); it
/// returns the frame stamped at mid-exposure and sets the next exposure.

#include <cstdint>
#include <opencv2/core/mat.hpp>
#include <vector>

#include "evio/core/options.h"
#include "evio/core/time.h"

namespace evio::simulator {

/// One captured frame.
struct Frame {
  cv::Mat image;                  ///< CV_8UC1
  TimeNs t_ns = 0;                ///< stamp: middle of the exposure
  TimeNs t_start_ns = 0;          ///< start of the exposure
  double exposure_s = 0.0;        ///< exposure time
  double mean_dn = 0.0;           ///< mean of the image, DN
  double saturated_fraction = 0.0;///< fraction of pixels whose electrons reached full well
};

class FrameCamera {
 public:
  struct Options {
    double exposure_s = 0.005;           ///< fixed exposure, or the first one with auto-exposure, s
    bool auto_exposure = true;           ///< adapt the exposure after each frame
    double auto_exposure_target = 0.5;   ///< m*: target mean of DN / 255
    double auto_exposure_min_s = 1e-5;   ///< shortest exposure, s
    double auto_exposure_max_s = 0.03;   ///< longest exposure, s
    double auto_exposure_gain = 1.0;     ///< k ∈ (0, 1]: fraction of the correction per frame
    double f_number = 4.0;               ///< N of the lens
    double lens_transmission = 0.9;      ///< T
    double pixel_pitch_um = 6.0;         ///< p, µm (mvBlueFOX-MLC200w: 6 µm)
    double quantum_efficiency = 0.5;     ///< QE
    double wavelength_nm = 550.0;        ///< λ of the photons, nm
    double full_well_e = 10000.0;        ///< saturation, electrons (also the ADC full scale)
    double read_noise_e = 10.0;          ///< σ_read, electrons
    bool shot_noise = true;              ///< Poisson photon noise
    double gamma = 1.0;                  ///< response curve DN ∝ x^(1/γ); 1 = linear
    int threads = 1;                     ///< threads, 0 = all cores (output does not depend on it)

    template <class V>
    void fields(V& v) {
      v("exposure_s", exposure_s, "exposure (first exposure with auto-exposure), s");
      v("auto_exposure", auto_exposure, "adapt the exposure after each frame");
      v("auto_exposure_target", auto_exposure_target, "target mean of DN/255");
      v("auto_exposure_min_s", auto_exposure_min_s, "shortest exposure, s");
      v("auto_exposure_max_s", auto_exposure_max_s, "longest exposure, s");
      v("auto_exposure_gain", auto_exposure_gain, "fraction of the correction per frame");
      v("f_number", f_number, "lens f-number");
      v("lens_transmission", lens_transmission, "lens transmission");
      v("pixel_pitch_um", pixel_pitch_um, "pixel pitch, um");
      v("quantum_efficiency", quantum_efficiency, "quantum efficiency");
      v("wavelength_nm", wavelength_nm, "photon wavelength, nm");
      v("full_well_e", full_well_e, "full-well capacity, electrons");
      v("read_noise_e", read_noise_e, "read noise, electrons");
      v("shot_noise", shot_noise, "Poisson photon noise");
      v("gamma", gamma, "response curve exponent, 1 = linear");
      v("threads", threads, "threads, 0 = all cores");
    }
    void validate() const;
  };

  FrameCamera(int width, int height, const Options& options, std::uint64_t seed);

  /// Exposure of the next frame, s.
  double exposureS() const { return exposure_s_; }

  /// Captures a frame exposed from t_start_ns for exposureS(), from N ≥ 1
  /// CV_32FC1 radiance images (W/(m²·sr)) evenly spaced over the exposure,
  /// both ends included. Updates the auto-exposure.
  Frame capture(TimeNs t_start_ns, const std::vector<cv::Mat>& sub_samples);

  /// K: electrons per (W/(m²·sr)) per second of exposure.
  double electronsPerRadianceSecond() const { return k_; }

  /// The noise-free DN of a mean radiance over an exposure (no rounding).
  double idealDn(double radiance_w_m2_sr, double exposure_s) const;

  int width() const { return width_; }
  int height() const { return height_; }
  const Options& options() const { return options_; }
  std::uint64_t frameCount() const { return frame_index_; }

 private:
  int width_ = 0, height_ = 0;
  Options options_;
  double k_ = 0.0;
  double exposure_s_ = 0.0;
  std::uint64_t key_shot_ = 0, key_read_ = 0;
  std::uint64_t frame_index_ = 0;
};

}  // namespace evio::simulator
