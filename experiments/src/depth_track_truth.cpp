#include "evio/experiments/depth_track_truth.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <string_view>
#include <utility>

#include "evio/core/error.h"
#include "evio/core/io/exr_file.h"
#include "evio/core/io/sensors_yaml.h"
#include "evio/core/io/text_scanner.h"
#include "evio/core/io/tum.h"
#include "evio/experiments/trajectory_association.h"

namespace evio::experiments {

namespace {

/// Depth at integer pixel (x, y); +inf outside the map or for no surface.
double depthAt(const cv::Mat& d, int x, int y) {
  if (x < 0 || y < 0 || x >= d.cols || y >= d.rows) return std::numeric_limits<double>::infinity();
  const double z = d.at<float>(y, x);
  return (std::isfinite(z) && z > 0.0) ? z : std::numeric_limits<double>::infinity();
}

/// Bilinear depth at uv (pixel centres at integers); +inf when a corner is
/// outside the map or has no surface.
double bilinear(const cv::Mat& d, const Vec2& uv) {
  if (!uv.allFinite()) return std::numeric_limits<double>::infinity();
  const int x0 = static_cast<int>(std::floor(uv.x()));
  const int y0 = static_cast<int>(std::floor(uv.y()));
  const double ax = uv.x() - x0, ay = uv.y() - y0;
  return (1 - ay) * ((1 - ax) * depthAt(d, x0, y0) + ax * depthAt(d, x0 + 1, y0)) +
         ay * ((1 - ax) * depthAt(d, x0, y0 + 1) + ax * depthAt(d, x0 + 1, y0 + 1));
}

}  // namespace

void DepthTruthOptions::validate() const {
  requirePositive("max_depth_time_offset_s", max_depth_time_offset_s);
  requirePositive("max_depth_curvature", max_depth_curvature);
  requirePositive("occlusion_tolerance", occlusion_tolerance);
  requirePositive("max_pose_gap_s", max_pose_gap_s);
}

DepthTrackTruth::DepthTrackTruth(Camera camera, Trajectory T_W_E, std::vector<DepthStamp> depth,
                                 DepthTruthOptions options)
    : camera_(std::move(camera)), T_W_E_(std::move(T_W_E)), depth_(std::move(depth)), options_(options) {
  options_.validate();
  require(!T_W_E_.empty(), "depth truth: no ground-truth poses");
  require(!depth_.empty(), "depth truth: no depth maps");
  for (std::size_t i = 1; i < T_W_E_.size(); ++i)
    require(T_W_E_[i].t_ns > T_W_E_[i - 1].t_ns, "depth truth: ground-truth poses not in increasing time");
  std::vector<TimeNs> gaps;
  for (std::size_t i = 1; i < depth_.size(); ++i) {
    require(depth_[i].t_ns > depth_[i - 1].t_ns, "depth truth: depth maps not in increasing time");
    gaps.push_back(depth_[i].t_ns - depth_[i - 1].t_ns);
  }
  if (!gaps.empty()) {
    std::nth_element(gaps.begin(), gaps.begin() + static_cast<std::ptrdiff_t>(gaps.size() / 2), gaps.end());
    depth_period_ns_ = gaps[gaps.size() / 2];
  }
  cache_.resize(depth_.size());
}

std::size_t DepthTrackTruth::nearestDepth(TimeNs t_ns) const {
  const auto it = std::lower_bound(depth_.begin(), depth_.end(), t_ns,
                                   [](const DepthStamp& d, TimeNs t) { return d.t_ns < t; });
  if (it == depth_.end()) return depth_.size() - 1;
  const auto i = static_cast<std::size_t>(it - depth_.begin());
  if (i > 0 && t_ns - depth_[i - 1].t_ns < it->t_ns - t_ns) return i - 1;
  return i;
}

const cv::Mat& DepthTrackTruth::depthMap(std::size_t index) const {
  cv::Mat& m = cache_[index];
  if (m.empty()) {
    const std::string& path = depth_[index].path;
    cv::Mat z = io::readExrChannel(path, "Z");
    if (z.type() != CV_32FC1 || z.cols != camera_.width() || z.rows != camera_.height())
      throw Error(path + ": depth map is " + std::to_string(z.cols) + "x" + std::to_string(z.rows) +
                  ", the camera " + std::to_string(camera_.width()) + "x" + std::to_string(camera_.height()));
    m = z;
  }
  return m;
}

bool DepthTrackTruth::pose(TimeNs t_ns, Pose* T_W_E) const {
  if (t_ns < T_W_E_.front().t_ns || t_ns > T_W_E_.back().t_ns) return false;  // never extrapolate
  return interpolatePose(T_W_E_, t_ns, secondsToNs(options_.max_pose_gap_s), T_W_E);
}

bool DepthTrackTruth::occluded(const Vec3& p_W, std::size_t depth_index) const {
  Pose T_W_E;
  if (!pose(depth_[depth_index].t_ns, &T_W_E)) return false;
  const Vec3 p_E = T_W_E.inverse() * p_W;
  Vec2 uv;
  if (!isInFrontOfCamera(p_E) || !camera_.project(p_E, &uv) || !camera_.isInside(uv)) return false;
  const cv::Mat& d = depthMap(depth_index);
  const int x0 = static_cast<int>(std::floor(uv.x()));
  const int y0 = static_cast<int>(std::floor(uv.y()));
  // The deepest of the (up to) four pixels around uv: a point on a smooth
  // surface is never deeper than all four; +inf (no surface) never occludes.
  double deepest = 0.0;
  for (int dy = 0; dy <= 1; ++dy)
    for (int dx = 0; dx <= 1; ++dx) {
      const int x = std::clamp(x0 + dx, 0, d.cols - 1);
      const int y = std::clamp(y0 + dy, 0, d.rows - 1);
      deepest = std::max(deepest, depthAt(d, x, y));
    }
  return p_E.z() > (1.0 + options_.occlusion_tolerance) * deepest;
}

TrackTruth DepthTrackTruth::truthOf(const std::vector<io::TrackSample>& track) const {
  require(!track.empty(), "depth truth: empty track");
  TrackTruth out;
  const io::TrackSample& first = track.front();
  const std::size_t f0 = nearestDepth(first.t_ns);
  if (std::abs(depth_[f0].t_ns - first.t_ns) > secondsToNs(options_.max_depth_time_offset_s)) {
    out.status = TrackTruthStatus::kNoDepthFrame;
    return out;
  }
  const cv::Mat& d = depthMap(f0);
  const Vec2 u0 = first.uv;
  Vec3 b;
  Pose T_W_E0, T_W_Ef;
  out.status = TrackTruthStatus::kNoSurface;
  if (!u0.allFinite() || !camera_.unproject(u0, &b) || b.z() <= 0.0 || !pose(first.t_ns, &T_W_E0) ||
      !pose(depth_[f0].t_ns, &T_W_Ef))
    return out;
  // Depth z along the ray r of u0 in E(t0) such that the point lies on the
  // surface of the depth map taken at t_f: p_Ef = T_W_Ef⁻¹ T_W_E0 (r z) has
  // z(p_Ef) = D_f(π(p_Ef)). Newton on z with ∂z(p_Ef)/∂z = (R_Ef_E0 r)_z
  // (D_f's slope neglected); at t0 = t_f it is z = D_f(u0) at once.
  const Vec3 r = b / b.z();
  const Pose T_Ef_E0 = T_W_Ef.inverse() * T_W_E0;
  const double dzf_dz = (T_Ef_E0.rotation() * r).z();
  double z = bilinear(d, u0);
  Vec2 uv_f = u0;
  bool converged = false;
  for (int it = 0; it < 20 && std::isfinite(z) && dzf_dz > 0.0; ++it) {
    const Vec3 p_Ef = T_Ef_E0 * Vec3(r * z);
    if (!isInFrontOfCamera(p_Ef) || !camera_.project(p_Ef, &uv_f)) break;
    const double d_f = bilinear(d, uv_f);
    if (!std::isfinite(d_f)) break;
    const double residual = p_Ef.z() - d_f;
    if (std::abs(residual) <= 1e-9 * d_f) {
      converged = true;
      break;
    }
    z -= residual / dzf_dz;
  }
  if (!converged || !(z > 0.0)) return out;
  const int xc = static_cast<int>(std::lround(uv_f.x()));
  const int yc = static_cast<int>(std::lround(uv_f.y()));
  if (xc < 1 || yc < 1 || xc > d.cols - 2 || yc > d.rows - 2) return out;
  double n[3][3];
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i) {
      n[j][i] = depthAt(d, xc + i - 1, yc + j - 1);
      if (!std::isfinite(n[j][i])) return out;
    }
  double curvature = 0.0;
  for (int k = 0; k < 3; ++k) {
    curvature = std::max(curvature, std::abs(n[k][0] - 2 * n[k][1] + n[k][2]));
    curvature = std::max(curvature, std::abs(n[0][k] - 2 * n[1][k] + n[2][k]));
  }
  if (curvature > options_.max_depth_curvature * n[1][1]) {
    out.status = TrackTruthStatus::kDiscontinuity;
    return out;
  }
  out.status = TrackTruthStatus::kOk;
  const Vec3 p_W = T_W_E0 * Vec3(r * z);

  std::size_t checked = f0;  // depth map of the last occlusion test (none needed at the start)
  out.uv.reserve(track.size());
  for (const auto& s : track) {
    Pose T_W_E;
    if (!pose(s.t_ns, &T_W_E)) break;
    const Vec3 p_E = T_W_E.inverse() * p_W;
    Vec2 uv;
    if (!isInFrontOfCamera(p_E) || !camera_.project(p_E, &uv) || !camera_.isInside(uv)) break;
    const std::size_t f = nearestDepth(s.t_ns);
    if (f != checked && depth_period_ns_ > 0 && std::abs(depth_[f].t_ns - s.t_ns) <= depth_period_ns_) {
      checked = f;
      if (occluded(p_W, f)) break;
    }
    out.uv.push_back(uv);
  }
  return out;
}

DepthTrackTruth loadDepthTrackTruth(const std::string& folder, const std::string& camera_name,
                                    const DepthTruthOptions& options) {
  namespace fs = std::filesystem;
  const fs::path root(folder);
  const SensorRig rig = io::readSensorsYaml((root / "sensors.yaml").string());
  const CameraSensor* event = rig.firstCamera(CameraRole::kEvent);
  require(event != nullptr, (root / "sensors.yaml").string() + ": no event camera (the depth maps are its)");
  const CameraSensor* cam = camera_name.empty() ? event : rig.findCamera(camera_name);
  require(cam != nullptr, (root / "sensors.yaml").string() + ": no camera named '" + camera_name + "'");
  if (cam != event) {
    const bool twin = cam->camera == event->camera &&
                      (cam->T_B_C.matrix() - event->T_B_C.matrix()).cwiseAbs().maxCoeff() < 1e-9;
    require(twin, "depth truth: camera '" + cam->name + "' is not co-located with the event camera '" +
                      event->name + "' with the same model; its tracks cannot be scored on the event camera's depth");
  }
  const Trajectory gt = io::readTum((root / "groundtruth.txt").string());

  const std::string list = (root / "truth" / "depth.txt").string();
  io::LineReader lines(list);
  std::vector<DepthStamp> depth;
  std::string_view line;
  while (lines.next(line)) {
    if (io::isBlankOrComment(line)) continue;
    const std::string where = list + ":" + std::to_string(lines.lineNumber()) + ": ";
    std::string_view f[2];
    bool more = false;
    const std::size_t n = io::splitFields(line, f, 2, &more);
    if (n != 2 || more) throw Error(where + "expected 2 columns (t path)");
    DepthStamp s;
    if (!io::parseSecondsToNs(f[0], &s.t_ns)) throw Error(where + "t: not a time in seconds");
    if (!depth.empty() && s.t_ns <= depth.back().t_ns) throw Error(where + "t: time does not increase");
    s.path = (root / "truth" / std::string(f[1])).string();
    depth.push_back(std::move(s));
  }
  require(!depth.empty(), list + ": no depth maps listed");
  return DepthTrackTruth(cam->camera, gt, std::move(depth), options);
}

}  // namespace evio::experiments
