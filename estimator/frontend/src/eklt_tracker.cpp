#include "evio/estimator/frontend/eklt_tracker.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>

#include <opencv2/video/tracking.hpp>

#include "evio/core/error.h"
#include "evio/core/stopwatch.h"
#include "evio/estimator/frontend/feature_detection.h"
#include "evio/estimator/frontend/log_image.h"
#include "evio/estimator/frontend/track_velocity.h"

namespace evio::estimator {

namespace {


double wrapAngle(double a) { return std::remainder(a, 2.0 * M_PI); }

/// A point EKLT took from a frame (a detection, a bootstrap), stamped at the
/// frame's time: it carries no event lag (TrackPoint::measured_on_frame).
TrackPoint framePoint(FeatureId id, TimeNs t_ns, const Vec2& uv, TrackStatus status) {
  TrackPoint p{id, t_ns, uv, 1.0, status};
  p.measured_on_frame = true;
  return p;
}

}  // namespace

void EkltOptions::validate() const {
  requireField(max_features >= 1 && max_features <= 10000, "max_features", "must be in [1, 10000]");
  requireField(min_features >= 0 && min_features <= max_features, "min_features",
               "must be in [0, max_features]");
  requirePositive("harris_quality_level", harris_quality_level);
  requirePositive("harris_k", harris_k);
  requireField(harris_block_size >= 1 && harris_block_size <= 101, "harris_block_size", "must be in [1, 101]");
  requireNonNegative("min_distance_px", min_distance_px);
  requireField(patch_size_px >= 3 && patch_size_px % 2 == 1 && patch_size_px <= 101, "patch_size_px",
               "must be odd and in [3, 101]");
  requirePositive("batch_displacement_px", batch_displacement_px);
  requireNonNegative("batch_contrast_threshold", batch_contrast_threshold);
  requireField(batch_min_events >= 1, "batch_min_events", "must be >= 1");
  requireField(batch_max_events >= batch_min_events, "batch_max_events", "must be >= batch_min_events");
  requireField(batch_max_events <= 1000000, "batch_max_events", "must be <= 1000000");
  parseEkltSolverKind(solver);
  requireField(max_iterations >= 1 && max_iterations <= 1000, "max_iterations", "must be in [1, 1000]");
  requireNonNegative("function_tolerance", function_tolerance);
  requireNonNegative("parameter_tolerance", parameter_tolerance);
  requireInRange("min_tracking_quality", min_tracking_quality, 0.0, 1.0);
  requireInRange("reversal_quality", reversal_quality, 0.0, 1.0);
  requireInRange("max_batch_shift_px", max_batch_shift_px, 1e-3, 1000.0);
  requireNonNegative("lost_border_px", lost_border_px);
  requireInRange("position_sigma_min_px", position_sigma_min_px, 1e-3, 100.0);
  requireInRange("position_sigma_cost_ref", position_sigma_cost_ref, 0.0, 2.0);  // the cost lies in [0, 2]
  requireField(position_sigma_max_px >= position_sigma_min_px && position_sigma_max_px <= 100.0,
               "position_sigma_max_px", "must be in [position_sigma_min_px, 100]");
  requireInRange("error_time_s", error_time_s, 0.0, 60.0);
  requireField(bootstrap_window_px >= 3 && bootstrap_window_px <= 255, "bootstrap_window_px", "must be in [3, 255]");
  requireField(bootstrap_pyramid_levels >= 1 && bootstrap_pyramid_levels <= 16, "bootstrap_pyramid_levels",
               "must be in [1, 16]");
  requireInRange("imu_prediction_min_shift_px", imu_prediction_min_shift_px, 0.0, 1000.0);
  requireInRange("imu_prediction_translation_window_s", imu_prediction_translation_window_s, 0.0, 1.0);
  requirePositive("log_offset", log_offset);
}

struct EkltTracker::Slot {
  enum class State : std::uint8_t { kFree, kPending, kActive };
  State state = State::kFree;
  FeatureId id = 0;
  Vec2 x0 = Vec2::Zero();      // template point (frame of initialisation)
  TimeNs t_detect_ns = 0;
  GradientTemplate templ;
  double theta = 0.0;          // warp rotation
  double flow_angle = 0.0;     // φ
  Vec2 centre = Vec2::Zero();  // current position = accumulation centre of the batch
  TimeNs t_centre_ns = 0;
  double offset_x = 0.0;       // h − centre: patch coordinate of an event = pixel + offset
  double offset_y = 0.0;
  std::vector<float> patch;    // P², polarity-weighted bilinear splats
  int n_events = 0;
  int batch_size = 0;
  TimeNs t_first_ns = 0;
  TimeNs t_last_ns = 0;
  double quality = 1.0;
  PixelRect rect;              // where the grid has this slot's bit
  /// imu_prediction_translation_window_s: the sum of the accepted steps less
  /// the gyro's rotation over each (px), and its fitted velocity (px/s).
  Vec2 derotated_path = Vec2::Zero();
  TrackVelocity translation;
};

/// One part of the feature partition (eklt_tracker.h): slots s with
/// s mod parts == its index.
struct EkltTracker::Part {
  Part(int width, int height, int num_slots, std::size_t patch_pixels)
      : grid(width, height, num_slots), measured(patch_pixels, 0.0f) {
    points.reserve(256);
  }
  FeatureGrid grid;                // the bits of this part's slots only
  std::vector<float> measured;     // normalised batch, P²
  std::vector<ChunkPoint> points;  // of the current chunk, in (event, slot) order
  EkltTiming timing;               // events_s, optimisation_s and counters of the current chunk
};

EkltTracker::EkltTracker(const EkltOptions& options, const Camera& camera, std::optional<Pose> T_B_C,
                         int threads)
    : options_(options),
      solver_(parseEkltSolverKind(options.solver)),
      camera_(camera),
      width_(camera.width()),
      height_(camera.height()),
      half_((options.patch_size_px - 1) / 2),
      // The warp rotates the patch (corner at h√2) and its centre t drifts
      // from x0 while a solve explores; 10 px more cover that and the
      // bicubic taps for all but a few evaluations (with 6 px, 18 % of them
      // needed the slower clamped lookup at the crop's border).
      template_radius_(static_cast<int>(std::ceil(half_ * std::sqrt(2.0))) + 10),
      slots_(static_cast<std::size_t>(options.max_features)) {
  options_.validate();
  require(threads >= 1 && threads <= 256, "EkltTracker: threads must be in [1, 256]");
  settings_.max_iterations = options_.max_iterations;
  settings_.function_tolerance = options_.function_tolerance;
  settings_.parameter_tolerance = options_.parameter_tolerance;
  if (options_.imu_prediction) {
    require(T_B_C.has_value(), "EkltTracker: imu_prediction needs T_B_C");
    predictor_ = std::make_unique<GyroPredictor>(camera_, *T_B_C);
  }
  const std::size_t n = static_cast<std::size_t>(options_.patch_size_px) * static_cast<std::size_t>(options_.patch_size_px);
  for (Slot& s : slots_) s.patch.assign(n, 0.0f);
  const int num_parts = std::min(threads, options_.max_features);
  for (int k = 0; k < num_parts; ++k)
    parts_.push_back(std::make_unique<Part>(width_, height_, options_.max_features, n));
  for (auto& part : parts_) part_points_.push_back(&part->points);
  if (num_parts > 1) pool_ = std::make_unique<WorkerPool>(num_parts);
  out_.reserve(1024);
}

EkltTracker::~EkltTracker() = default;

PixelRect EkltTracker::patchRect(const Vec2& c) const {
  // Pixels e with |e − c| < h + 1 on both axes splat into the patch.
  const double r = half_ + 1.0;
  return PixelRect{static_cast<int>(std::floor(c.x() - r)) + 1, static_cast<int>(std::floor(c.y() - r)) + 1,
                   static_cast<int>(std::ceil(c.x() + r)) - 1, static_cast<int>(std::ceil(c.y() + r)) - 1};
}

int EkltTracker::freeSlot() const {
  for (std::size_t i = 0; i < slots_.size(); ++i)
    if (slots_[i].state == Slot::State::kFree) return static_cast<int>(i);
  return -1;
}

std::size_t EkltTracker::numAlive() const {
  return static_cast<std::size_t>(std::count_if(slots_.begin(), slots_.end(),
                                                [](const Slot& s) { return s.state != Slot::State::kFree; }));
}

int EkltTracker::batchSize(double abs_sum) const {
  const double C = options_.batch_contrast_threshold > 0.0 ? options_.batch_contrast_threshold
                                                           : kDavis240cContrastThreshold;
  const double n = options_.batch_displacement_px * abs_sum / C;
  if (!std::isfinite(n)) return options_.batch_max_events;
  return static_cast<int>(std::clamp(std::lround(n), static_cast<long>(options_.batch_min_events),
                                     static_cast<long>(options_.batch_max_events)));
}

void EkltTracker::assignTemplate(Slot& s, const cv::Mat& gx, const cv::Mat& gy, const Vec2& x0) {
  s.x0 = x0;
  s.templ.assign(gx, gy, x0, template_radius_);
}

void EkltTracker::resetPatch(Slot& s) {
  std::fill(s.patch.begin(), s.patch.end(), 0.0f);
  s.n_events = 0;
  s.offset_x = half_ - s.centre.x();
  s.offset_y = half_ - s.centre.y();
}

void EkltTracker::activate(int index, const Vec2& uv, TimeNs t_ns, double flow_angle) {
  Slot& s = slots_[static_cast<std::size_t>(index)];
  s.state = Slot::State::kActive;
  s.centre = uv;
  s.t_centre_ns = t_ns;
  s.flow_angle = wrapAngle(flow_angle);
  s.quality = 1.0;
  s.derotated_path = Vec2::Zero();
  s.translation = TrackVelocity(options_.imu_prediction_translation_window_s);
  s.translation.add(t_ns, s.derotated_path);
  resetPatch(s);
  // Initial batch size from the template seen along the initial flow.
  Part& part = partOf(index);
  std::fill(part.measured.begin(), part.measured.end(), 0.0f);
  const EkltBatch batch{&s.templ, part.measured.data(), options_.patch_size_px};
  EkltEvaluation eval;
  const Vec4 p(s.theta, s.x0.x(), s.x0.y(), s.flow_angle);
  s.batch_size = evaluateEklt(batch, p, false, &eval) ? batchSize(eval.abs_sum) : options_.batch_max_events;
  const PixelRect rect = patchRect(s.centre);
  part.grid.move(index, s.rect, rect);
  s.rect = rect;
}

void EkltTracker::free(int index) {
  Slot& s = slots_[static_cast<std::size_t>(index)];
  partOf(index).grid.move(index, s.rect, PixelRect{});
  s.rect = PixelRect{};
  s.state = Slot::State::kFree;
}

void EkltTracker::lose(Part& part, int index, std::size_t event_index) {
  const Slot& s = slots_[static_cast<std::size_t>(index)];
  part.points.push_back(
      ChunkPoint{event_index, index, TrackPoint{s.id, s.t_centre_ns, s.centre, s.quality, TrackStatus::kLost}});
  free(index);
}

FeatureId EkltTracker::addFeature(const cv::Mat& log_image, const Vec2& x0, const Vec2& uv, TimeNs t_ns,
                                  double flow_angle_rad, double theta_rad) {
  const int index = freeSlot();
  require(index >= 0, "EkltTracker::addFeature: all max_features slots are in use");
  cv::Mat gx, gy;
  imageGradient(toLogImage(log_image, options_.log_offset), &gx, &gy);
  Slot& s = slots_[static_cast<std::size_t>(index)];
  s.id = next_id_++;
  s.t_detect_ns = t_ns;
  s.theta = theta_rad;
  assignTemplate(s, gx, gy, x0);
  activate(index, uv, t_ns, flow_angle_rad);
  out_.push_back(framePoint(s.id, t_ns, uv, TrackStatus::kNew));
  return s.id;
}

std::optional<EkltTracker::FeatureState> EkltTracker::feature(FeatureId id) const {
  for (const Slot& s : slots_)
    if (s.state == Slot::State::kActive && s.id == id)
      return FeatureState{s.centre, s.theta, s.flow_angle, s.batch_size, s.quality};
  return std::nullopt;
}

void EkltTracker::addImu(const ImuSample& sample) {
  if (predictor_) predictor_->addImu(sample);
}

void EkltTracker::drainTrackPoints(TrackPoints& out) {
  out.insert(out.end(), out_.begin(), out_.end());
  out_.clear();
}

void EkltTracker::splat(Slot& s, double x, double y, bool positive, TimeNs t_ns) {
  const int P = options_.patch_size_px;
  const double lx = x + s.offset_x;
  const double ly = y + s.offset_y;
  const double fx0 = std::floor(lx);
  const double fy0 = std::floor(ly);
  const int ix = static_cast<int>(fx0);
  const int iy = static_cast<int>(fy0);
  const float fx = static_cast<float>(lx - fx0);
  const float fy = static_cast<float>(ly - fy0);
  const float pol = positive ? 1.0f : -1.0f;
  const float w00 = pol * (1.0f - fx) * (1.0f - fy);
  const float w10 = pol * fx * (1.0f - fy);
  const float w01 = pol * (1.0f - fx) * fy;
  const float w11 = pol * fx * fy;
  float* patch = s.patch.data();
  const bool x0_in = ix >= 0 && ix < P;
  const bool x1_in = ix + 1 >= 0 && ix + 1 < P;
  if (iy >= 0 && iy < P) {
    float* row = patch + iy * P;
    if (x0_in) row[ix] += w00;
    if (x1_in) row[ix + 1] += w10;
  }
  if (iy + 1 >= 0 && iy + 1 < P) {
    float* row = patch + (iy + 1) * P;
    if (x0_in) row[ix] += w01;
    if (x1_in) row[ix + 1] += w11;
  }
  if (s.n_events == 0) s.t_first_ns = t_ns;
  s.t_last_ns = t_ns;
  ++s.n_events;
}

void EkltTracker::addEvents(const EventArray& events, std::size_t begin, std::size_t end) {
  trackInParts(events, begin, end);
  mergeChunkPoints();
}

void EkltTracker::addEventChunks(const EventArray& events, const std::vector<std::size_t>& chunk_ends,
                                 TrackPoints& out, std::vector<std::size_t>& point_ends) {
  drainTrackPoints(out);
  trackInParts(events, 0, chunk_ends.empty() ? 0 : chunk_ends.back());
  estimator::mergeChunkPoints(part_points_, chunk_ends, out, point_ends);
}

void EkltTracker::trackInParts(const EventArray& events, std::size_t begin, std::size_t end) {
  const auto& x = events.x();
  const auto& y = events.y();
  for (std::size_t i = begin; i < end; ++i)
    if (x[i] >= width_ || y[i] >= height_) throw Error("EkltTracker: event outside the sensor");
  if (pool_) {
    auto task = [&](int k) { trackChunk(*parts_[static_cast<std::size_t>(k)], events, begin, end); };
    pool_->run(task);
  } else {
    trackChunk(*parts_.front(), events, begin, end);
  }
  timing_.events += end - begin;
  for (auto& part : parts_) {
    timing_.events_s += part->timing.events_s;
    timing_.optimisation_s += part->timing.optimisation_s;
    timing_.events_in_patches += part->timing.events_in_patches;
    timing_.optimisations += part->timing.optimisations;
    timing_.solver_iterations += part->timing.solver_iterations;
    timing_.reversal_solves += part->timing.reversal_solves;
    timing_.batches_dropped += part->timing.batches_dropped;
    part->timing = EkltTiming{};
  }
}

void EkltTracker::trackChunk(Part& part, const EventArray& events, std::size_t begin, std::size_t end) {
  const Stopwatch start;
  const auto& t = events.t();
  const auto& x = events.x();
  const auto& y = events.y();
  const auto& p = events.p();
  const int words = part.grid.words();
  std::uint64_t splats = 0;
  for (std::size_t i = begin; i < end; ++i) {
    const int ex = x[i];
    const int ey = y[i];
    const std::uint64_t* cell = part.grid.at(ex, ey);
    for (int w = 0; w < words; ++w) {
      std::uint64_t bits = cell[w];  // a copy: optimise() may rewrite the grid
      while (bits != 0) {
        const int slot = 64 * w + std::countr_zero(bits);
        bits &= bits - 1;
        Slot& s = slots_[static_cast<std::size_t>(slot)];
        splat(s, ex, ey, p[i] != 0, t[i]);
        ++splats;
        if (s.n_events >= s.batch_size) optimise(part, slot, i);
      }
    }
  }
  part.timing.events_in_patches += splats;
  part.timing.events_s += start.seconds();
}

std::optional<EkltSolution> EkltTracker::solveBatch(const Slot& s, const EkltBatch& batch, const Vec4& p0,
                                                    const Vec2& predicted, EkltTiming& timing) const {
  // A solution is plausible when it moves the feature at most
  // max_batch_shift_px from its prediction: the batch holds the events of
  // about batch_displacement_px of motion (batchSize), so a longer jump is a
  // wrong minimum of the cost, not the motion.
  const auto shift = [&](const EkltSolution& sol) {
    return sol.valid ? (ekltFeaturePosition(sol.p, s.centre, s.x0) - predicted).norm()
                     : std::numeric_limits<double>::infinity();
  };
  const auto solve = [&](const Vec4& start) {
    EkltSolution sol = solveEklt(solver_, batch, start, settings_);
    ++timing.optimisations;
    timing.solver_iterations += static_cast<std::uint64_t>(sol.iterations);
    return sol;
  };
  EkltSolution sol = solve(p0);
  const double max_shift = options_.max_batch_shift_px;
  if (!sol.valid || sol.quality() < options_.reversal_quality || shift(sol) > max_shift) {
    // The motion may have reversed: the increment −∇L·v changed sign, a
    // minimum the optimiser cannot reach from the old φ. Start from φ + π.
    ++timing.reversal_solves;
    const EkltSolution reversed = solve(Vec4(p0[0], p0[1], p0[2], p0[3] + M_PI));
    const bool sol_ok = shift(sol) <= max_shift;
    const bool reversed_ok = shift(reversed) <= max_shift;
    if (reversed_ok && (!sol_ok || reversed.cost < sol.cost)) sol = reversed;
  }
  if (!sol.valid) return sol;  // nothing could be evaluated: the caller loses the feature, as before
  if (shift(sol) > max_shift) return std::nullopt;
  return sol;
}

std::optional<Vec2> EkltTracker::rotatedCentre(const Slot& s, TimeNs t) const {
  if (!predictor_ || predictor_->empty()) return std::nullopt;
  return predictor_->predict(s.centre, s.t_centre_ns, t);
}

Vec2 EkltTracker::predictedCentre(const Slot& s, const std::optional<Vec2>& rotated, TimeNs t) const {
  if (!rotated) return s.centre;
  Vec2 uv = *rotated;
  if (options_.imu_prediction_translation_window_s > 0.0) {
    if (const std::optional<Vec2> v = s.translation.velocity()) uv += *v * nsToSeconds(t - s.t_centre_ns);
  }
  if ((uv - s.centre).norm() < options_.imu_prediction_min_shift_px) return s.centre;
  return uv;
}

void EkltTracker::addDerotatedStep(Slot& s, const Vec2& uv, const std::optional<Vec2>& rotated, TimeNs t) const {
  if (!predictor_ || !(options_.imu_prediction_translation_window_s > 0.0)) return;
  s.derotated_path += uv - rotated.value_or(s.centre);
  s.translation.add(t, s.derotated_path);
}

void EkltTracker::mergeChunkPoints() { estimator::mergeChunkPoints(part_points_, out_); }

void EkltTracker::optimise(Part& part, int index, std::size_t event_index) {
  const Stopwatch start;
  Slot& s = slots_[static_cast<std::size_t>(index)];
  const TimeNs t_mid = s.t_first_ns + (s.t_last_ns - s.t_first_ns) / 2;
  double norm2 = 0.0;
  for (float v : s.patch) norm2 += static_cast<double>(v) * static_cast<double>(v);
  if (!(norm2 > 0.0)) {  // the events cancelled out: nothing to align
    resetPatch(s);
    part.timing.optimisation_s += start.seconds();
    return;
  }
  const float inv = static_cast<float>(1.0 / std::sqrt(norm2));
  std::vector<float>& measured = part.measured;
  for (std::size_t k = 0; k < s.patch.size(); ++k) measured[k] = s.patch[k] * inv;

  // Initial guess: the previous warp, with the centre moved to the gyro
  // prediction when enabled: t = x0 − R(θ)(c_pred − c).
  const std::optional<Vec2> rotated = rotatedCentre(s, t_mid);  // once per batch: the start and the derotated step
  const Vec2 predicted = predictedCentre(s, rotated, t_mid);
  const double c = std::cos(s.theta);
  const double sn = std::sin(s.theta);
  const Vec2 d = predicted - s.centre;
  const Vec4 p0(s.theta, s.x0.x() - (c * d.x() - sn * d.y()), s.x0.y() - (sn * d.x() + c * d.y()), s.flow_angle);
  EkltBatch batch{&s.templ, measured.data(), options_.patch_size_px};
  batch.single_precision = options_.single_precision;
  const std::optional<EkltSolution> solved = solveBatch(s, batch, p0, predicted, part.timing);
  if (!solved) {  // no solution the batch supports: drop its events, keep the feature where it was
    ++part.timing.batches_dropped;
    resetPatch(s);
    part.timing.optimisation_s += start.seconds();
    return;
  }
  const EkltSolution& sol = *solved;
  const Vec2 uv = ekltFeaturePosition(sol.p, s.centre, s.x0);
  if (!sol.valid || !uv.allFinite() || sol.quality() < options_.min_tracking_quality ||
      !camera_.isInside(uv, options_.lost_border_px)) {
    if (sol.valid) s.quality = sol.quality();
    lose(part, index, event_index);
    part.timing.optimisation_s += start.seconds();
    return;
  }
  addDerotatedStep(s, uv, rotated, t_mid);
  s.theta = sol.p[0];
  s.flow_angle = wrapAngle(sol.p[3]);
  s.quality = sol.quality();
  s.centre = uv;
  s.t_centre_ns = t_mid;
  s.batch_size = batchSize(sol.abs_sum);
  TrackPoint point{s.id, t_mid, uv, s.quality, TrackStatus::kTracked};
  if (options_.position_covariance) {
    EkltEvaluation at_solution;
    at_solution.cost = sol.cost;
    at_solution.jtj = sol.jtj;
    const double sigma_floor = ekltSigmaFloor(sol.cost, options_.position_sigma_min_px,
                                              options_.position_sigma_max_px, options_.position_sigma_cost_ref);
    point.cov_px = ekltPositionCovariance(at_solution, sol.p, s.x0, options_.patch_size_px, sigma_floor,
                                          options_.position_sigma_max_px);
  }
  part.points.push_back(ChunkPoint{event_index, index, point});
  resetPatch(s);
  const PixelRect rect = patchRect(uv);
  if (rect.x0 != s.rect.x0 || rect.y0 != s.rect.y0 || rect.x1 != s.rect.x1 || rect.y1 != s.rect.y1) {
    part.grid.move(index, s.rect, rect);
    s.rect = rect;
  }
  part.timing.optimisation_s += start.seconds();
}

void EkltTracker::addFrame(TimeNs t_ns, const cv::Mat& image) {
  const Stopwatch start;
  require(image.cols == width_ && image.rows == height_, "EkltTracker: frame size differs from the camera's");
  const cv::Mat log_image = toLogImage(image, options_.log_offset);
  const cv::Mat image8 = toEightBit(image);
  cv::Mat gx, gy;
  imageGradient(log_image, &gx, &gy);

  // 1. Bootstrap the features detected on the previous frame.
  const Stopwatch t_boot;
  std::vector<int> pending;
  std::vector<cv::Point2f> p0, p1;
  for (std::size_t i = 0; i < slots_.size(); ++i)
    if (slots_[i].state == Slot::State::kPending) {
      pending.push_back(static_cast<int>(i));
      p0.emplace_back(static_cast<float>(slots_[i].x0.x()), static_cast<float>(slots_[i].x0.y()));
    }
  if (!pending.empty()) {
    std::vector<std::uint8_t> status;
    std::vector<float> err;
    if (!previous_frame8_.empty() && t_ns > previous_frame_t_ns_) {
      cv::calcOpticalFlowPyrLK(previous_frame8_, image8, p0, p1, status, err,
                               cv::Size(options_.bootstrap_window_px, options_.bootstrap_window_px),
                               options_.bootstrap_pyramid_levels - 1);
    }
    for (std::size_t k = 0; k < pending.size(); ++k) {
      const int index = pending[k];
      Slot& s = slots_[static_cast<std::size_t>(index)];
      const bool ok = k < status.size() && status[k] != 0;
      const Vec2 uv = ok ? Vec2(p1[k].x, p1[k].y) : Vec2::Zero();
      if (!ok || !camera_.isInside(uv, std::max<double>(options_.lost_border_px, 0.0))) {
        free(index);
        continue;
      }
      const Vec2 flow = uv - s.x0;
      s.theta = 0.0;
      out_.push_back(framePoint(s.id, s.t_detect_ns, s.x0, TrackStatus::kNew));
      activate(index, uv, t_ns, std::atan2(flow.y(), flow.x()));
      out_.push_back(framePoint(s.id, t_ns, uv, TrackStatus::kTracked));
    }
  }
  timing_.bootstrap_s += t_boot.seconds();

  // 2. Re-detect when too few features are alive.
  const Stopwatch t_detect;
  const std::size_t alive = numAlive();
  if (alive < static_cast<std::size_t>(options_.min_features)) {
    std::vector<Vec2> existing;
    for (const Slot& s : slots_)
      if (s.state == Slot::State::kActive) existing.push_back(s.centre);
    HarrisSettings hs;
    hs.max_corners = options_.max_features - static_cast<int>(alive);
    hs.quality_level = options_.harris_quality_level;
    hs.min_distance_px = options_.min_distance_px;
    hs.block_size = options_.harris_block_size;
    hs.k = options_.harris_k;
    hs.border_px = half_;
    for (const Vec2& corner : detectHarris(image8, existing, hs)) {
      const int index = freeSlot();
      if (index < 0) break;
      Slot& s = slots_[static_cast<std::size_t>(index)];
      s.state = Slot::State::kPending;
      s.id = next_id_++;
      s.t_detect_ns = t_ns;
      assignTemplate(s, gx, gy, corner);
    }
  }
  timing_.detection_s += t_detect.seconds();
  previous_frame8_ = image8.clone();
  previous_frame_t_ns_ = t_ns;
  timing_.frame_s += start.seconds();
}

}  // namespace evio::estimator
