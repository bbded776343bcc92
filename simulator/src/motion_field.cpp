#include "evio/simulator/motion_field.h"

#include <cmath>
#include <limits>

#include "evio/core/error.h"

namespace evio::simulator {

bool pointFlow(const Camera& camera, const Vec3& p_C, const CameraVelocity& velocity, Vec2* uv_dot) {
  Vec2 uv;
  Mat23 d_uv_d_p;
  if (!camera.project(p_C, &uv, &d_uv_d_p)) return false;
  const Vec3 p_dot = -velocity.v_C - velocity.omega_C.cross(p_C);
  *uv_dot = d_uv_d_p * p_dot;
  return uv_dot->allFinite();
}

bool directionFlow(const Camera& camera, const Vec3& b_C, const CameraVelocity& velocity, Vec2* uv_dot) {
  Vec2 uv;
  Mat23 d_uv_d_p;
  if (!camera.project(b_C, &uv, &d_uv_d_p)) return false;
  *uv_dot = d_uv_d_p * (-velocity.omega_C.cross(b_C));
  return uv_dot->allFinite();
}

cv::Mat motionFieldFromDepth(const Camera& camera, const cv::Mat& depth, const CameraVelocity& velocity) {
  require(depth.type() == CV_32FC1 && depth.cols == camera.width() && depth.rows == camera.height(),
          "motionFieldFromDepth: depth must be CV_32FC1 of the camera's size");
  const float nan = std::numeric_limits<float>::quiet_NaN();
  cv::Mat flow(depth.size(), CV_32FC2, cv::Scalar(nan, nan));
  for (int y = 0; y < depth.rows; ++y)
    for (int x = 0; x < depth.cols; ++x) {
      const float z = depth.at<float>(y, x);
      Vec3 b;
      if (std::isnan(z) || !camera.unproject(Vec2(x, y), &b)) continue;
      Vec2 f;
      bool ok;
      if (std::isinf(z)) ok = directionFlow(camera, b, velocity, &f);
      else ok = b.z() > 0.0 && pointFlow(camera, b * (static_cast<double>(z) / b.z()), velocity, &f);
      if (ok) flow.at<cv::Vec2f>(y, x) = cv::Vec2f(static_cast<float>(f.x()), static_cast<float>(f.y()));
    }
  return flow;
}

}  // namespace evio::simulator
