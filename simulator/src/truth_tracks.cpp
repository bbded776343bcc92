#include "evio/simulator/truth_tracks.h"

#include <algorithm>
#include <cmath>

namespace evio::simulator {

std::vector<io::TrackPoint> pickTrackPoints(const Camera& camera, const Pose& T_W_E, const cv::Mat& depth, int count,
                                            double border_px) {
  std::vector<io::TrackPoint> points;
  if (count <= 0) return points;
  const double x0 = border_px, y0 = border_px;
  const double w = camera.width() - 1 - 2.0 * border_px, h = camera.height() - 1 - 2.0 * border_px;
  if (!(w > 0.0 && h > 0.0)) return points;
  // cols / rows ≈ w / h with cols · rows ≈ count.
  const int cols = std::max(1, static_cast<int>(std::lround(std::sqrt(count * w / h))));
  const int rows = std::max(1, (count + cols - 1) / cols);
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) {
      if (static_cast<int>(points.size()) >= count) return points;
      const int x = static_cast<int>(std::lround(x0 + (c + 0.5) * w / cols));
      const int y = static_cast<int>(std::lround(y0 + (r + 0.5) * h / rows));
      const float z = depth.at<float>(y, x);
      if (!std::isfinite(z) || !(z > 0.0f)) continue;
      Vec3 b;
      if (!camera.unproject(Vec2(x, y), &b) || !(b.z() > 0.0)) continue;
      io::TrackPoint p;
      p.id = static_cast<std::int64_t>(points.size());
      p.p_W = T_W_E * (b * (static_cast<double>(z) / b.z()));
      points.push_back(p);
    }
  return points;
}

TrackObservation observeTrackPoint(const Camera& camera, const Pose& T_W_E, const Vec3& p_W,
                                   const RangeFinder::RayCast& cast) {
  TrackObservation o;
  const Vec3 p_E = T_W_E.inverse() * p_W;
  if (!(p_E.z() > 0.0) || !camera.project(p_E, &o.uv) || !camera.isInside(o.uv)) return o;
  o.projects = true;
  const Vec3 d = p_W - T_W_E.translation();
  const double dist = d.norm();
  const double hit = cast(T_W_E.translation(), d / dist);
  o.occluded = hit < dist * (1.0 - kTrackOcclusionTolerance);
  return o;
}

}  // namespace evio::simulator
