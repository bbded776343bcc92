#pragma once
/// @file depth_track_truth.h
/// Ground truth for any estimated feature track, from the sequence's
/// event-camera depth maps (truth/depth.txt, channel Z: z along the optical
/// axis of E, m; +inf where no surface) and the ground-truth poses T_W_E
/// (groundtruth.txt, docs/architecture.md#the-sequence-folder).
///
/// A track's first sample (t0, u0) must lie within max_depth_time_offset_s of
/// a depth-map stamp t_f, the nearest one (otherwise the track is
/// unevaluable). The tracked surface point lies on the ray of u0 from E(t0),
///   p_E0(z) = r · z,   r = b / b_z,   b = camera.unproject(u0),
/// at the depth z where it meets the surface of that depth map D_f (bilinear
/// between pixel centres): z(p_Ef) = D_f(π(p_Ef)) with
/// p_Ef = T_W_E(t_f)⁻¹ · T_W_E(t0) · p_E0(z), solved by Newton steps on z
/// (when t0 = t_f this is simply z = D_f(u0)). D_f must be finite and > 0 on
/// the 3×3 pixels around π(p_Ef), and the surface must be smooth there:
/// every second difference along the rows and columns of that 3×3
/// neighbourhood, |d[k−1] − 2 d[k] + d[k+1]|, at most max_depth_curvature
/// times the centre depth (a depth discontinuity is a large second
/// difference; a tilted plane, whose depth varies by more than a few %
/// across 3 pixels at grazing angles, is not). Then
///   p_W = T_W_E(t0) · p_E0(z),
/// and the true pixel at time t is
///   u(t) = π(T_W_E(t)⁻¹ · p_W)   (the camera model, distortion included),
/// with T_W_E(t) interpolated linearly in position and by slerp in rotation
/// (trajectory_association.h). By construction u(t0) = u0: the start is taken
/// as exact.
///
/// The truth ends (for good) at the first sample where the point is behind
/// the camera or outside the image, where no ground-truth pose lies within
/// max_pose_gap_s, or where it is occluded: at the depth-map stamp t_f
/// nearest the sample, when |t − t_f| ≤ the median depth-map period, the
/// point seen from T_W_E(t_f) has depth z_f > (1 + occlusion_tolerance) ·
/// max(depth of the 2×2 pixels around its projection).
///
/// The tracks must be in pixels of the event camera or of a camera co-located
/// with it with the same model (the DAVIS frames); others are an error.

#include <cstdint>
#include <string>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "evio/core/camera/camera.h"
#include "evio/core/io/tracks_txt.h"
#include "evio/core/options.h"
#include "evio/core/pose.h"

namespace evio::experiments {

struct DepthTruthOptions {
  double max_depth_time_offset_s = 1e-3;  ///< a track's first sample must be this close to a depth stamp, s
  double max_depth_curvature = 0.02;      ///< largest |second difference| of depth around u0, relative to z
  double occlusion_tolerance = 0.01;      ///< occluded when deeper than the depth map by this fraction
  double max_pose_gap_s = 0.05;           ///< nearest ground-truth pose must be this close, s

  template <class V>
  void fields(V& v) {
    v("max_depth_time_offset_s", max_depth_time_offset_s, "first sample to depth-map stamp, largest offset, s");
    v("max_depth_curvature", max_depth_curvature, "largest relative second difference of depth around u0");
    v("occlusion_tolerance", occlusion_tolerance, "relative depth excess that counts as occluded");
    v("max_pose_gap_s", max_pose_gap_s, "largest distance to the nearest ground-truth pose, s");
  }
  void validate() const;
};

/// Why a track has no truth.
enum class TrackTruthStatus {
  kOk,
  kNoDepthFrame,  ///< first sample not within max_depth_time_offset_s of a depth stamp
  kNoSurface,     ///< no finite depth at u0, at the image border, no pose, or no depth solution
  kDiscontinuity, ///< depth around the start not smooth (an occluding edge)
};

/// The truth of one track: uv[k] is the true pixel of the track's k-th
/// sample, for the samples before the truth ends (uv.size() ≤ samples).
struct TrackTruth {
  TrackTruthStatus status = TrackTruthStatus::kOk;
  std::vector<Vec2> uv;
};

/// One depth map of truth/depth.txt.
struct DepthStamp {
  TimeNs t_ns = 0;
  std::string path;  ///< EXR file (absolute, or relative to the working directory)
};

/// Ground truth of feature tracks from depth maps and poses. Depth maps are
/// read on first use and kept (so one object is not for concurrent use).
class DepthTrackTruth {
 public:
  /// `camera` the event camera (or one identical and co-located),
  /// `T_W_E` sorted by time, `depth` sorted by time (not empty).
  /// Throws evio::Error for bad options, empty or unsorted inputs.
  DepthTrackTruth(Camera camera, Trajectory T_W_E, std::vector<DepthStamp> depth, DepthTruthOptions options);

  /// The truth of one track (samples sorted by time, not empty). Throws
  /// evio::Error naming the file when a depth map is unreadable, has no Z
  /// channel or is not of the camera's size.
  TrackTruth truthOf(const std::vector<io::TrackSample>& track) const;

  const Camera& camera() const { return camera_; }

 private:
  /// Index of the depth stamp nearest t_ns.
  std::size_t nearestDepth(TimeNs t_ns) const;
  const cv::Mat& depthMap(std::size_t index) const;
  bool pose(TimeNs t_ns, Pose* T_W_E) const;
  bool occluded(const Vec3& p_W, std::size_t depth_index) const;

  Camera camera_;
  Trajectory T_W_E_;
  std::vector<DepthStamp> depth_;
  DepthTruthOptions options_;
  TimeNs depth_period_ns_ = 0;  ///< median spacing of the depth stamps
  mutable std::vector<cv::Mat> cache_;
};

/// Reads a sequence folder's truth for tracks in pixels of `camera_name`
/// (empty: the event camera): sensors.yaml, groundtruth.txt and
/// truth/depth.txt (`t depth/depth_XXXXXXXX.exr`, paths relative to truth/).
/// Throws evio::Error naming the file and line for missing or malformed
/// input, and when the camera is not the event camera's twin (same model and
/// parameters, same T_B_C).
DepthTrackTruth loadDepthTrackTruth(const std::string& folder, const std::string& camera_name,
                                    const DepthTruthOptions& options);

}  // namespace evio::experiments
