#pragma once
/// @file frontend_dataset.h
/// The data set both frontend benchmarks run on (frontend_bench.cpp for
/// EKLT, haste_bench.cpp for HASTE), so their figures compare: a synthetic
/// poster_6dof analogue at 240×180, Gaussian-blob texture moving rigidly
/// (50, −33) px/s plus 0.6 rad/s about the image centre, events from
/// log-intensity thresholding with C = 0.2, frames at 20 Hz, 1 s.

#include <time.h>

#include <opencv2/core/mat.hpp>
#include <vector>

#include "evio/core/event.h"
#include "evio/core/time.h"
#include "synthetic_events.h"

namespace evio::bench {

constexpr int kWidth = 240;
constexpr int kHeight = 180;
constexpr double kDurationS = 1.0;
constexpr double kFrameDtS = 0.05;
constexpr double kContrast = 0.2;

struct FrontendDataset {
  EventArray events;
  std::vector<TimeNs> frame_t_ns;
  std::vector<cv::Mat> frames;
};

/// Built once per process.
inline const FrontendDataset& frontendDataset() {
  static const FrontendDataset data = [] {
    FrontendDataset d;
    const auto tex = test::BlobTexture::random(2022, kWidth, kHeight, 1800, 60.0);
    test::RigidMotion m;
    m.velocity_px_s = Vec2(50.0, -33.0);
    m.omega_rad_s = 0.6;
    m.centre = Vec2(0.5 * (kWidth - 1), 0.5 * (kHeight - 1));
    d.events = test::generateEvents(tex, m, test::Roi{0, 0, kWidth, kHeight}, 0.0, kDurationS, 1e-3, kContrast);
    for (double t = 0.0; t <= kDurationS + 1e-9; t += kFrameDtS) {
      d.frame_t_ns.push_back(secondsToNs(t));
      d.frames.push_back(test::render8(tex, m, t, kWidth, kHeight));
    }
    return d;
  }();
  return data;
}

/// CPU time of the calling thread, s.
inline double threadCpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

}  // namespace evio::bench
