#pragma once
/// @file truth_tracks.h
/// Ground-truth feature tracks (truth/tracks.txt): surface points seen by the
/// event camera at the start of the sequence, projected exactly over time.
///
/// Picking: a grid of about `count` integer pixels (cells of equal size over
/// the image shrunk by `border_px`, one pixel at each cell centre); each pixel
/// with a surface (finite depth z) gives the world point
///   p_W = T_W_E · (b · z / b_z),   b = camera.unproject(uv)   (uv = (x, y)).
/// Observing at time t with the event camera at T_W_E(t):
///   p_E = T_W_E⁻¹ · p_W,   uv = π(p_E)   (the camera model, distortion included),
/// visible when p_E is in front (z > 0), uv is inside the image (Camera::isInside)
/// and nothing lies on the segment from the camera centre to p_W: the first
/// surface along it is no closer than |p_W − p_W_E| · (1 − 1e-3) (the point
/// itself lies on a surface, so the tolerance absorbs the ray's float error).

#include <vector>

#include <opencv2/core/mat.hpp>

#include "evio/core/camera/camera.h"
#include "evio/core/io/track_points_txt.h"
#include "evio/core/pose.h"
#include "evio/simulator/range_finder.h"

namespace evio::simulator {

/// Relative tolerance of the occlusion test (see the file comment).
constexpr double kTrackOcclusionTolerance = 1e-3;

/// The track points of a depth image (CV_32FC1, z in E, m) rendered at T_W_E;
/// ids 0, 1, … in row-major grid order. Pixels without a surface are skipped.
std::vector<io::TrackPoint> pickTrackPoints(const Camera& camera, const Pose& T_W_E, const cv::Mat& depth, int count,
                                            double border_px);

/// One observation of a track point.
struct TrackObservation {
  bool projects = false;  ///< in front of the camera and uv inside the image
  bool occluded = false;  ///< projects, but a surface lies in between
  Vec2 uv = Vec2::Zero(); ///< the projection (valid when projects)
  bool visible() const { return projects && !occluded; }
};

/// Observes p_W from the event camera at T_W_E; `cast` finds the first
/// surface along a ray (RangeFinder::sceneRayCast).
TrackObservation observeTrackPoint(const Camera& camera, const Pose& T_W_E, const Vec3& p_W,
                                   const RangeFinder::RayCast& cast);

}  // namespace evio::simulator
