#pragma once
/// @file image_reconstructor.h
/// HDR frames from events: the per-pixel complementary filter of Scheerlinck,
/// Barnes and Mahony, "Continuous-time intensity estimation using event
/// cameras" (ACCV 2018), our CPU substitute for E2VID in events-only mode.
///
/// Each pixel keeps a log-intensity estimate L̂ and, where frames are fused,
/// the log intensity L_F of the latest usable frame. Between events L̂ relaxes
/// to L_F with gain α (rad/s):
///   L̂(t) = L_F + (L̂(t₀) − L_F) e^{−α (t − t₀)},
/// and each event steps it by ±C (C: contrast threshold). Without frames
/// (L_F = 0) this is the high-pass filter of the same paper: static scene
/// content fades with time constant 1/α and edges that moved recently stay.
/// A frame pixel is fused only when it is not saturated; saturated pixels keep
/// the previous L_F, so events carry the dynamic range the frame lost. The
/// first fused frame also sets L̂ (where unsaturated), so the output does not
/// start from a uniform grey that fades in at rate α.
/// Frames are emitted as CV_32FC1 log images (to feed EkltTracker directly)
/// at a configurable rate.

#include <cstdint>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "evio/core/event.h"
#include "evio/core/options.h"

namespace evio::estimator {

struct ImageReconstructorOptions {
  double cutoff_frequency_rad_s = 5.0;   ///< α, filter gain
  /// C, the log step per event; 0 (default): the sensor's own,
  /// per polarity, as FrontendOptions resolves it (frontend.h):
  /// contrast_threshold_pos / _neg of the camera's calibration, else the
  /// DAVIS240C's 0.5 / 0.38.
  double contrast_threshold = 0.0;
  double contrast_threshold_neg = 0.0;   ///< C of OFF events; 0: as contrast_threshold
  bool fuse_frames = true;               ///< fuse unsaturated frame pixels (false: events only)
  int saturation_low = 5;                ///< frame pixels ≤ this are not fused
  int saturation_high = 250;             ///< frame pixels ≥ this are not fused
  double log_offset = 0.01;              ///< L_F = log(I/255 + offset)
  /// Emit a frame every this many events (0: off). The paper reconstructs
  /// every 15 000 events.
  int output_every_events = 15000;
  /// Emit frames at this rate in Hz of event time (0: off).
  double output_rate_hz = 0.0;

  template <class V>
  void fields(V& v) {
    v("cutoff_frequency_rad_s", cutoff_frequency_rad_s, "filter gain alpha, rad/s");
    v("contrast_threshold", contrast_threshold, "log step per (ON) event (0: the sensor's)");
    v("contrast_threshold_neg", contrast_threshold_neg, "log step per OFF event (0: as contrast_threshold)");
    v("fuse_frames", fuse_frames, "fuse unsaturated frame pixels");
    v("saturation_low", saturation_low, "frame pixels <= this are not fused");
    v("saturation_high", saturation_high, "frame pixels >= this are not fused");
    v("log_offset", log_offset, "offset in log(I/255 + offset)");
    v("output_every_events", output_every_events, "emit a frame every this many events (0: off)");
    v("output_rate_hz", output_rate_hz, "emit frames at this rate, Hz (0: off)");
  }
  void validate() const;
};

class ImageReconstructor {
 public:
  ImageReconstructor(const ImageReconstructorOptions& options, int width, int height);

  /// Integrates events [begin, end) and returns the index just after the
  /// first event at which an output frame is due (end when none): the caller
  /// then takes the frame with image() at time dueTime() and calls again
  /// from the returned index.
  std::size_t addEvents(const EventArray& events, std::size_t begin, std::size_t end);

  /// True when addEvents stopped because a frame is due; image() clears it.
  bool frameDue() const { return due_; }
  /// Time of the due frame (the event that triggered it).
  TimeNs dueTime() const { return due_t_ns_; }

  /// Fuses a frame (CV_8UC1) taken at t_ns (when fuse_frames).
  void addFrame(TimeNs t_ns, const cv::Mat& image);

  /// The log-intensity estimate at t_ns (≥ every integrated event), CV_32FC1.
  cv::Mat image(TimeNs t_ns);

 private:
  ImageReconstructorOptions options_;
  int width_;
  int height_;
  std::vector<float> state_;      // L̂ at last_t_
  std::vector<float> frame_log_;  // L_F
  std::vector<TimeNs> last_t_ns_;
  std::uint64_t events_since_output_ = 0;
  TimeNs next_output_t_ns_ = -1;
  bool due_ = false;
  bool any_frame_ = false;
  TimeNs due_t_ns_ = 0;
};

}  // namespace evio::estimator
