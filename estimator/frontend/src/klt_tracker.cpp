#include "evio/estimator/frontend/klt_tracker.h"

#include <opencv2/calib3d.hpp>
#include <opencv2/video/tracking.hpp>

#include "evio/core/error.h"
#include "evio/estimator/frontend/feature_detection.h"
#include "evio/estimator/frontend/log_image.h"

namespace evio::estimator {

void KltOptions::validate() const {
  requireField(max_features >= 1 && max_features <= 10000, "max_features", "must be in [1, 10000]");
  requireField(min_features >= 0 && min_features <= max_features, "min_features",
               "must be in [0, max_features]");
  requireField(fast_threshold >= 1 && fast_threshold <= 255, "fast_threshold", "must be in [1, 255]");
  requireNonNegative("min_distance_px", min_distance_px);
  requireField(border_px >= 0 && border_px <= 65536, "border_px", "must be in [0, 65536]");
  requireField(window_px >= 3 && window_px <= 255, "window_px", "must be in [3, 255]");
  requireField(pyramid_levels >= 1 && pyramid_levels <= 16, "pyramid_levels", "must be in [1, 16]");
  requireField(max_iterations >= 1 && max_iterations <= 1000, "max_iterations", "must be in [1, 1000]");
  requirePositive("lk_epsilon", lk_epsilon);
  requirePositive("ransac_threshold_px", ransac_threshold_px);
  requireField(ransac_confidence > 0.0 && ransac_confidence < 1.0, "ransac_confidence", "must be in (0, 1)");
  requireInRange("error_time_s", error_time_s, 0.0, 60.0);
  requireInRange("position_sigma_px", position_sigma_px, 0.0, 100.0);
  requireInRange("backward_check_px", backward_check_px, 0.0, 1000.0);
}

KltTracker::KltTracker(const KltOptions& options, const Camera& camera, std::optional<Pose> T_B_C)
    : options_(options), camera_(camera) {
  options_.validate();
  if (options_.imu_prediction) {
    require(T_B_C.has_value(), "KltTracker: imu_prediction needs T_B_C");
    predictor_ = std::make_unique<GyroPredictor>(camera_, *T_B_C);
  }
}

void KltTracker::addImu(const ImuSample& sample) {
  if (predictor_) predictor_->addImu(sample);
}

std::vector<cv::Point2f> KltTracker::searchStarts(TimeNs t_ns) const {
  std::vector<cv::Point2f> starts;
  starts.reserve(points_.size());
  for (const Vec2& p : points_) {
    // A feature predicted outside the image starts there too: Lucas–Kanade
    // loses it, instead of searching from its old place and finding another.
    // Only where no prediction exists (a bearing the camera model cannot
    // project) does the search start from the old place.
    Vec2 start = p;
    if (predictor_ && !predictor_->empty())
      if (const std::optional<Vec2> uv = predictor_->predict(p, previous_t_ns_, t_ns)) start = *uv;
    starts.emplace_back(static_cast<float>(start.x()), static_cast<float>(start.y()));
  }
  return starts;
}

void KltTracker::drainTrackPoints(TrackPoints& out) {
  out.insert(out.end(), out_.begin(), out_.end());
  out_.clear();
}

void KltTracker::addFrame(TimeNs t_ns, const cv::Mat& image) {
  require(image.cols == camera_.width() && image.rows == camera_.height(),
          "KltTracker: frame size differs from the camera's");
  const cv::Mat image8 = toEightBit(image);

  // 1. Track the live features into this frame.
  if (!points_.empty() && !previous_.empty()) {
    std::vector<cv::Point2f> p0;
    for (const Vec2& p : points_) p0.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()));
    // Without a prediction p1 starts at p0, as OpenCV does by itself.
    std::vector<cv::Point2f> p1 = predictor_ ? searchStarts(t_ns) : p0;
    const std::vector<cv::Point2f> starts = p1;
    std::vector<std::uint8_t> status;
    std::vector<float> err;
    const cv::Size window(options_.window_px, options_.window_px);
    const cv::TermCriteria stop(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, options_.max_iterations,
                                options_.lk_epsilon);
    cv::calcOpticalFlowPyrLK(previous_, image8, p0, p1, status, err, window, options_.pyramid_levels - 1, stop,
                             predictor_ ? cv::OPTFLOW_USE_INITIAL_FLOW : 0);
    if (options_.backward_check_px > 0.0) {
      // Back from p1, started as far from it as the forward search started
      // from p0 (at p1 itself without a prediction).
      std::vector<cv::Point2f> back(p1.size());
      for (std::size_t k = 0; k < p1.size(); ++k) back[k] = p1[k] - (starts[k] - p0[k]);
      std::vector<std::uint8_t> back_status;
      std::vector<float> back_err;
      cv::calcOpticalFlowPyrLK(image8, previous_, p1, back, back_status, back_err, window, options_.pyramid_levels - 1,
                               stop, cv::OPTFLOW_USE_INITIAL_FLOW);
      const double max_sq = options_.backward_check_px * options_.backward_check_px;
      for (std::size_t k = 0; k < p1.size(); ++k) {
        const double dx = static_cast<double>(back[k].x) - static_cast<double>(p0[k].x);
        const double dy = static_cast<double>(back[k].y) - static_cast<double>(p0[k].y);
        if (back_status[k] == 0 || !(dx * dx + dy * dy <= max_sq)) status[k] = 0;
      }
    }
    std::vector<bool> keep(points_.size(), false);
    std::vector<std::size_t> candidates;
    for (std::size_t k = 0; k < points_.size(); ++k) {
      const Vec2 uv(p1[k].x, p1[k].y);
      if (status[k] != 0 && camera_.isInside(uv)) {
        keep[k] = true;
        candidates.push_back(k);
      }
    }
    // 2. RANSAC on undistorted, fx-scaled normalised coordinates.
    if (options_.ransac && candidates.size() >= 8) {
      const double fx = camera_.intrinsics()[0];
      std::vector<cv::Point2f> a, b;
      std::vector<std::size_t> used;
      for (std::size_t k : candidates) {
        Vec3 fa, fb;
        if (!camera_.unproject(points_[k], &fa) || !camera_.unproject(Vec2(p1[k].x, p1[k].y), &fb)) {
          keep[k] = false;
          continue;
        }
        a.emplace_back(static_cast<float>(fx * fa.x() / fa.z()), static_cast<float>(fx * fa.y() / fa.z()));
        b.emplace_back(static_cast<float>(fx * fb.x() / fb.z()), static_cast<float>(fx * fb.y() / fb.z()));
        used.push_back(k);
      }
      if (used.size() >= 8) {
        std::vector<std::uint8_t> inliers;
        const cv::Mat F = cv::findFundamentalMat(a, b, cv::FM_RANSAC, options_.ransac_threshold_px,
                                                 options_.ransac_confidence, inliers);
        if (!F.empty() && inliers.size() == used.size())
          for (std::size_t j = 0; j < used.size(); ++j)
            if (inliers[j] == 0) keep[used[j]] = false;
      }
    }
    std::vector<FeatureId> ids;
    std::vector<Vec2> points;
    for (std::size_t k = 0; k < points_.size(); ++k) {
      if (keep[k]) {
        const Vec2 uv(p1[k].x, p1[k].y);
        ids.push_back(ids_[k]);
        points.push_back(uv);
        out_.push_back(TrackPoint{ids_[k], t_ns, uv, 1.0, TrackStatus::kTracked});
      } else {
        out_.push_back(TrackPoint{ids_[k], previous_t_ns_, points_[k], 1.0, TrackStatus::kLost});
      }
    }
    ids_ = std::move(ids);
    points_ = std::move(points);
  }

  // 3. Re-detect.
  if (static_cast<int>(points_.size()) < options_.min_features) {
    FastSettings fs;
    fs.max_corners = options_.max_features - static_cast<int>(points_.size());
    fs.threshold = options_.fast_threshold;
    fs.nonmax_suppression = options_.fast_nonmax_suppression;
    fs.min_distance_px = options_.min_distance_px;
    fs.border_px = options_.border_px;
    for (const Vec2& corner : detectFast(image8, points_, fs)) {
      ids_.push_back(next_id_);
      points_.push_back(corner);
      out_.push_back(TrackPoint{next_id_, t_ns, corner, 1.0, TrackStatus::kNew});
      ++next_id_;
    }
  }
  previous_ = image8.clone();
  previous_t_ns_ = t_ns;
}

}  // namespace evio::estimator
