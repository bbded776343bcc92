#pragma once
/// @file gt_tracks.h
/// Noisy ground-truth feature tracks for testing the backend in isolation (a
/// simulator-side generator does not exist yet): a static landmark cloud is
/// projected through the exact camera pose at each update time, pixel noise is
/// added, points outside the image or behind the camera end their track, and
/// track lengths are limited (each track draws its length in
/// [min_track_length, max_track_length]). At most max_features tracks live at
/// once; free slots are filled with visible untracked landmarks in random order.
/// Randomness: RandomStream(seed, "gt_tracks").

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "evio/core/camera/camera.h"
#include "evio/core/pose.h"
#include "evio/core/random_stream.h"
#include "evio/estimator/measurements.h"

namespace evio::test {

struct GtTrackOptions {
  double pixel_noise_px = 1.0;  ///< σ of the added Gaussian noise per axis, px
  int max_features = 40;        ///< live tracks at most
  int min_track_length = 15;    ///< per-track length drawn uniformly in [min, max] updates
  int max_track_length = 60;
  double border_px = 5.0;       ///< points this close to the image edge are not visible
  double min_depth_m = 0.3;     ///< nearer points are not visible
  /// Whether a landmark whose track ended may be tracked again under a new id.
  /// Re-tracking re-uses the same true depth under a fresh, independent depth
  /// prior in the filter (as a real tracker re-detecting a corner does), which a
  /// consistency test must avoid.
  bool retrack_landmarks = true;
  /// A correlated error per track on top of the white noise: a first-order
  /// Gauss–Markov process e (px per axis), stationary σ track_error_sigma_px,
  /// correlation time track_error_time_s, drawn from its stationary law when
  /// the track starts (0: none).
  double track_error_sigma_px = 0.0;
  double track_error_time_s = 0.5;
  /// An error every point of one set shares (all tracks at once): a
  /// first-order Gauss–Markov image shift s (px per axis), stationary σ
  /// shared_error_sigma_px, correlation time shared_error_time_s, drawn from
  /// its own stream ("gt_tracks_shared"), so the other draws stay as they
  /// were (0: none).
  double shared_error_sigma_px = 0.0;
  double shared_error_time_s = 0.05;
};

/// Landmarks uniformly in the box [lo, hi].
inline std::vector<Vec3> landmarksInBox(const Vec3& lo, const Vec3& hi, int n, RandomStream& rng) {
  std::vector<Vec3> out;
  for (int i = 0; i < n; ++i)
    out.emplace_back(rng.uniform(lo.x(), hi.x()), rng.uniform(lo.y(), hi.y()), rng.uniform(lo.z(), hi.z()));
  return out;
}

/// Landmarks in the spherical shell r_min <= |p − center| <= r_max, uniform in direction.
inline std::vector<Vec3> landmarksOnShell(const Vec3& center, double r_min, double r_max, int n, RandomStream& rng) {
  std::vector<Vec3> out;
  while (static_cast<int>(out.size()) < n) {
    const Vec3 d(rng.normal(), rng.normal(), rng.normal());
    if (d.norm() < 1e-6) continue;
    out.push_back(center + rng.uniform(r_min, r_max) * d.normalized());
  }
  return out;
}

/// Landmarks in front of a camera at the origin looking along +x of W: the
/// direction uniform within ±half_angle_x/y (rad) about it (x sideways in the
/// horizontal plane, y vertical), the inverse depth along +x of W
/// drawn from N(rho_mean, rho_sigma²) truncated to [rho_min, rho_max] — a scene
/// whose depths follow the backend's depth prior (ρ0, σ_ρ0) as seen from the origin.
inline std::vector<Vec3> landmarksWithInverseDepth(double rho_mean, double rho_sigma, double rho_min,
                                                   double rho_max, double half_angle_x, double half_angle_y,
                                                   int n, RandomStream& rng) {
  std::vector<Vec3> out;
  while (static_cast<int>(out.size()) < n) {
    const double rho = rng.normal(rho_mean, rho_sigma);
    if (rho < rho_min || rho > rho_max) continue;
    const double ax = rng.uniform(-half_angle_x, half_angle_x), ay = rng.uniform(-half_angle_y, half_angle_y);
    out.push_back(Vec3(1.0, std::tan(ax), std::tan(ay)) / rho);
  }
  return out;
}

/// Landmarks around the origin, uniform in direction, with the inverse distance
/// drawn from N(rho_mean, rho_sigma²) truncated to [rho_min, rho_max] (a scene
/// around a rotating camera whose depths follow the backend's depth prior).
inline std::vector<Vec3> landmarksAroundWithInverseDepth(double rho_mean, double rho_sigma, double rho_min,
                                                         double rho_max, int n, RandomStream& rng) {
  std::vector<Vec3> out;
  while (static_cast<int>(out.size()) < n) {
    const double rho = rng.normal(rho_mean, rho_sigma);
    const Vec3 d(rng.normal(), rng.normal(), rng.normal());
    if (rho < rho_min || rho > rho_max || d.norm() < 1e-6) continue;
    out.push_back(d.normalized() / rho);
  }
  return out;
}

class GroundTruthTracks {
 public:
  GroundTruthTracks(std::vector<Vec3> landmarks_W, Camera camera, const Pose& T_B_C, const GtTrackOptions& options,
                    std::uint64_t seed)
      : landmarks_(std::move(landmarks_W)),
        camera_(std::move(camera)),
        T_B_C_(T_B_C),
        options_(options),
        rng_(seed, "gt_tracks"),
        shared_rng_(seed, "gt_tracks_shared"),
        tracked_(landmarks_.size(), false) {}

  /// The measurement set at t_ns for the exact body pose T_W_B.
  estimator::MeasurementSet measure(TimeNs t_ns, const Pose& T_W_B) {
    const Pose T_C_W = (T_W_B * T_B_C_).inverse();
    estimator::MeasurementSet set;
    set.t_ns = t_ns;
    stepSharedError(t_ns);
    // Continue live tracks.
    for (auto it = live_.begin(); it != live_.end();) {
      Track& tr = *it;
      Vec2 uv;
      if (tr.length >= tr.max_length || !visible(T_C_W * landmarks_[tr.landmark], &uv)) {
        tracked_[tr.landmark] = !options_.retrack_landmarks;  // consumed unless re-tracking
        it = live_.erase(it);
        continue;
      }
      stepTrackError(tr, t_ns);
      const Vec2 noisy = uv + noise() + tr.error + shared_;
      set.features.push_back({tr.id, noisy, tr.last_uv, true});
      tr.last_uv = noisy;
      ++tr.length;
      ++it;
    }
    // Start new tracks on visible, untracked landmarks in random order.
    if (static_cast<int>(live_.size()) < options_.max_features) {
      std::vector<std::size_t> order(landmarks_.size());
      for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
      for (std::size_t i = order.size(); i > 1; --i) std::swap(order[i - 1], order[rng_.uniformInt(i)]);
      for (const std::size_t l : order) {
        if (static_cast<int>(live_.size()) >= options_.max_features) break;
        if (tracked_[l]) continue;
        Vec2 uv;
        if (!visible(T_C_W * landmarks_[l], &uv)) continue;
        Track tr;
        tr.id = next_id_++;
        tr.landmark = l;
        tr.max_length = options_.min_track_length +
                        static_cast<int>(rng_.uniformInt(static_cast<std::uint64_t>(
                            options_.max_track_length - options_.min_track_length + 1)));
        if (options_.track_error_sigma_px > 0.0)  // no draw without it: the white-noise streams stay as they were
          tr.error = Vec2(rng_.normal(), rng_.normal()) * options_.track_error_sigma_px;
        tr.error_t_ns = t_ns;
        tr.last_uv = uv + noise() + tr.error + shared_;
        tr.length = 1;
        set.features.push_back({tr.id, tr.last_uv, tr.last_uv, false});
        tracked_[l] = true;
        live_.push_back(tr);
      }
    }
    return set;
  }

  /// The landmark of feature id (for tests that need the true point).
  const Vec3* landmarkOf(estimator::FeatureId id) const {
    for (const Track& tr : live_)
      if (tr.id == id) return &landmarks_[tr.landmark];
    return nullptr;
  }

 private:
  struct Track {
    estimator::FeatureId id = 0;
    std::size_t landmark = 0;
    int length = 0;
    int max_length = 0;
    Vec2 last_uv = Vec2::Zero();
    Vec2 error = Vec2::Zero();  ///< the correlated error, px
    TimeNs error_t_ns = 0;
  };

  // e(t) = φ e(t0) + sqrt(1 − φ²) σ w, φ = exp(−(t − t0)/τ): exact for any step.
  void stepTrackError(Track& tr, TimeNs t_ns) {
    if (!(options_.track_error_sigma_px > 0.0)) return;
    const double phi = std::exp(-nsToSeconds(t_ns - tr.error_t_ns) / options_.track_error_time_s);
    tr.error = phi * tr.error +
               std::sqrt(1.0 - phi * phi) * options_.track_error_sigma_px * Vec2(rng_.normal(), rng_.normal());
    tr.error_t_ns = t_ns;
  }

  // The shared shift, the same exact step; drawn from its stationary law at the first set.
  void stepSharedError(TimeNs t_ns) {
    if (!(options_.shared_error_sigma_px > 0.0)) return;
    const double sigma = options_.shared_error_sigma_px;
    const Vec2 w(shared_rng_.normal(), shared_rng_.normal());
    if (!shared_started_) {
      shared_ = sigma * w;
      shared_started_ = true;
    } else {
      const double phi = std::exp(-nsToSeconds(t_ns - shared_t_ns_) / options_.shared_error_time_s);
      shared_ = phi * shared_ + std::sqrt(1.0 - phi * phi) * sigma * w;
    }
    shared_t_ns_ = t_ns;
  }

  bool visible(const Vec3& p_C, Vec2* uv) const {
    return p_C.z() > options_.min_depth_m && camera_.project(p_C, uv) && camera_.isInside(*uv, options_.border_px);
  }
  Vec2 noise() { return Vec2(rng_.normal(), rng_.normal()) * options_.pixel_noise_px; }

  std::vector<Vec3> landmarks_;
  Camera camera_;
  Pose T_B_C_;
  GtTrackOptions options_;
  RandomStream rng_;
  RandomStream shared_rng_;
  Vec2 shared_ = Vec2::Zero();  ///< the shared shift, px
  bool shared_started_ = false;
  TimeNs shared_t_ns_ = 0;
  std::vector<bool> tracked_;
  std::vector<Track> live_;
  estimator::FeatureId next_id_ = 0;
};

}  // namespace evio::test
