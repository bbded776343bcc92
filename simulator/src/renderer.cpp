#include "evio/simulator/renderer.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "evio/core/error.h"
#include "evio/scenes/embree_util.h"

namespace evio::simulator {

namespace {
constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

Eigen::Vector3f unprojectOrNan(const Camera& camera, const Vec2& uv) {
  Vec3 b;
  if (!camera.unproject(uv, &b) || !b.allFinite() || !(b.norm() > 0.0)) return Eigen::Vector3f::Constant(kNaN);
  return b.normalized().cast<float>();
}
}  // namespace

Renderer::Renderer(const scenes::Scene& scene, const Camera& camera, const RendererOptions& options)
    : scene_(scene), camera_(camera), options_(options) {
  options_.validate();
  const int w = camera_.width(), h = camera_.height();
  const int n = options_.supersampling;
  bearings_.resize(static_cast<std::size_t>(w) * static_cast<std::size_t>(h));
  if (n > 1) sub_bearings_.resize(bearings_.size() * static_cast<std::size_t>(n * n));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::size_t p = static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x);
      bearings_[p] = unprojectOrNan(camera_, Vec2(x, y));
      for (int j = 0; j < n && n > 1; ++j)
        for (int i = 0; i < n; ++i)
          sub_bearings_[p * static_cast<std::size_t>(n * n) + static_cast<std::size_t>(j * n + i)] =
              unprojectOrNan(camera_, Vec2(x + (i + 0.5) / n - 0.5, y + (j + 0.5) / n - 0.5));
    }
  pixel_angle_rad_ = static_cast<float>(1.0 / camera_.intrinsics()[0]);
}

RenderOutput Renderer::render(const Pose& T_W_C, const CameraVelocity* velocity) const {
  if (options_.check_viewpoint) scene_.checkViewpoint(T_W_C.translation());
  const int w = camera_.width(), h = camera_.height();
  RenderOutput out;
  out.radiance.create(h, w, CV_32FC1);
  out.depth.create(h, w, CV_32FC1);
  out.normal.create(h, w, CV_32FC3);
  if (velocity) out.flow.create(h, w, CV_32FC2);
  const int t = options_.tile_px;
  const int tiles = ((w + t - 1) / t) * ((h + t - 1) / t);
  tbb::task_arena arena = options_.threads > 0 ? tbb::task_arena(options_.threads) : tbb::task_arena();
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<int>(0, tiles, 1), [&](const tbb::blocked_range<int>& r) {
      for (int k = r.begin(); k != r.end(); ++k) renderTile(k, T_W_C, velocity, &out);
    });
  });
  return out;
}

void Renderer::renderTile(int tile, const Pose& T_W_C, const CameraVelocity* velocity, RenderOutput* out) const {
  const int w = camera_.width(), h = camera_.height(), t = options_.tile_px;
  const int tiles_x = (w + t - 1) / t;
  const int x0 = (tile % tiles_x) * t, y0 = (tile / tiles_x) * t;
  const int x1 = std::min(x0 + t, w), y1 = std::min(y0 + t, h);
  const int n = options_.supersampling;
  const int nn = n * n;
  const bool super = n > 1;
  const int per_pixel = super ? 1 + nn : 1;  // centre ray (+ radiance rays)
  const int pixels = (x1 - x0) * (y1 - y0);
  const int rays = pixels * per_pixel;
  const int lights = scene_.shadowLightCount();

  const Eigen::Matrix3f R = T_W_C.rotation().cast<float>();
  const Eigen::Vector3f org = T_W_C.translation().cast<float>();

  std::vector<RTCRayHit> rh(static_cast<std::size_t>(rays));
  std::vector<Eigen::Vector3f> dirs(static_cast<std::size_t>(rays));
  for (int y = y0, r = 0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) {
      const std::size_t p = static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x);
      for (int s = 0; s < per_pixel; ++s, ++r) {
        const Eigen::Vector3f& b = s == 0 ? bearings_[p] : sub_bearings_[p * static_cast<std::size_t>(nn) + static_cast<std::size_t>(s - 1)];
        const auto ri = static_cast<std::size_t>(r);
        if (std::isnan(b.x())) {
          dirs[ri] = Eigen::Vector3f::UnitZ();
          scenes::setRayHit(rh[ri], org, dirs[ri], 1.0f, 0.0f);  // tnear > tfar: inactive
          continue;
        }
        dirs[ri] = R * b;
        scenes::setRayHit(rh[ri], org, dirs[ri]);
      }
    }
  RTCIntersectContext coherent = scenes::intersectContext(true);
  rtcIntersect1M(scene_.embree(), &coherent, rh.data(), static_cast<unsigned>(rays), sizeof(RTCRayHit));

  // Shading inputs and occlusion rays.
  std::vector<scenes::SurfaceHit> hits(static_cast<std::size_t>(rays));
  std::vector<float> albedo(static_cast<std::size_t>(rays), 0.0f);
  std::vector<unsigned char> visible(static_cast<std::size_t>(rays) * static_cast<std::size_t>(std::max(lights, 1)), 0);
  std::vector<RTCRay> shadow;
  std::vector<std::size_t> shadow_slot;
  shadow.reserve(static_cast<std::size_t>(rays) * static_cast<std::size_t>(lights));
  shadow_slot.reserve(shadow.capacity());
  for (int r = 0; r < rays; ++r) {
    const auto ri = static_cast<std::size_t>(r);
    if (rh[ri].hit.geomID == RTC_INVALID_GEOMETRY_ID) continue;
    const bool shaded = !super || (r % per_pixel) != 0;
    hits[ri] = scene_.surfaceHit(rh[ri].hit.geomID, rh[ri].hit.primID, rh[ri].hit.u, rh[ri].hit.v, dirs[ri]);
    if (!shaded) continue;
    const float cos_view = std::max(std::abs(hits[ri].n.dot(dirs[ri])), 0.2f);
    const float footprint = rh[ri].ray.tfar * pixel_angle_rad_ / (cos_view * static_cast<float>(n));
    albedo[ri] = scene_.albedo(hits[ri], footprint);
    for (int k = 0; k < lights; ++k) {
      scenes::ShadowRay s;
      if (!scene_.shadowRay(k, hits[ri], &s)) continue;
      RTCRay ray;
      scenes::setRay(ray, s.origin, s.direction, 0.0f, s.t_far);
      shadow.push_back(ray);
      shadow_slot.push_back(ri * static_cast<std::size_t>(lights) + static_cast<std::size_t>(k));
    }
  }
  if (!shadow.empty())
    rtcOccluded1M(scene_.embree(), &coherent, shadow.data(), static_cast<unsigned>(shadow.size()), sizeof(RTCRay));
  for (std::size_t i = 0; i < shadow.size(); ++i)
    if (shadow[i].tfar >= 0.0f) visible[shadow_slot[i]] = 1;  // occluded rays get tfar = -inf

  // Outputs.
  for (int y = y0, r = 0; y < y1; ++y)
    for (int x = x0; x < x1; ++x, r += per_pixel) {
      const auto c = static_cast<std::size_t>(r);  // centre ray
      const Eigen::Vector3f& b = bearings_[static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x)];
      if (std::isnan(b.x())) {
        out->radiance.at<float>(y, x) = 0.0f;
        out->depth.at<float>(y, x) = kNaN;
        out->normal.at<cv::Vec3f>(y, x) = cv::Vec3f(0.0f, 0.0f, 0.0f);
        if (velocity) out->flow.at<cv::Vec2f>(y, x) = cv::Vec2f(kNaN, kNaN);
        continue;
      }
      // Radiance: the centre ray, or the mean of the n² sub-pixel rays.
      float sum = 0.0f;
      const int first = super ? 1 : 0;
      for (int s = first; s < per_pixel; ++s) {
        const auto ri = static_cast<std::size_t>(r + s);
        if (rh[ri].hit.geomID == RTC_INVALID_GEOMETRY_ID) {
          sum += rh[ri].ray.tnear <= rh[ri].ray.tfar ? scene_.background(dirs[ri]) : 0.0f;
          continue;
        }
        sum += scene_.radiance(hits[ri], -dirs[ri], albedo[ri], &visible[ri * static_cast<std::size_t>(lights)]);
      }
      out->radiance.at<float>(y, x) = sum / static_cast<float>(per_pixel - first);
      const bool hit = rh[c].hit.geomID != RTC_INVALID_GEOMETRY_ID;
      const float range = rh[c].ray.tfar;
      out->depth.at<float>(y, x) = hit ? range * b.z() : kInf;
      const Eigen::Vector3f nrm = hit ? hits[c].n : Eigen::Vector3f::Zero();
      out->normal.at<cv::Vec3f>(y, x) = cv::Vec3f(nrm.x(), nrm.y(), nrm.z());
      if (velocity) {
        Vec2 f;
        const Vec3 bd = b.cast<double>();
        const bool ok = hit ? pointFlow(camera_, bd * static_cast<double>(range), *velocity, &f)
                            : directionFlow(camera_, bd, *velocity, &f);
        out->flow.at<cv::Vec2f>(y, x) =
            ok ? cv::Vec2f(static_cast<float>(f.x()), static_cast<float>(f.y())) : cv::Vec2f(kNaN, kNaN);
      }
    }
}

}  // namespace evio::simulator
