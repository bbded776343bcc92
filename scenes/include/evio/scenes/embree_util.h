#pragma once
/// @file embree_util.h
/// Small helpers to fill Embree 3 ray structures.

#include <embree3/rtcore.h>

#include <Eigen/Core>
#include <limits>

namespace evio::scenes {

/// A ray org + t·dir, t ∈ [t_near, t_far]; mask -1, no motion blur.
inline void setRay(RTCRay& ray, const Eigen::Vector3f& org, const Eigen::Vector3f& dir,
                   float t_near = 0.0f, float t_far = std::numeric_limits<float>::infinity()) {
  ray.org_x = org.x();
  ray.org_y = org.y();
  ray.org_z = org.z();
  ray.dir_x = dir.x();
  ray.dir_y = dir.y();
  ray.dir_z = dir.z();
  ray.tnear = t_near;
  ray.tfar = t_far;
  ray.time = 0.0f;
  ray.mask = 0xFFFFFFFFU;
  ray.id = 0;
  ray.flags = 0;
}

/// A ray plus an empty hit record.
inline void setRayHit(RTCRayHit& rh, const Eigen::Vector3f& org, const Eigen::Vector3f& dir,
                      float t_near = 0.0f, float t_far = std::numeric_limits<float>::infinity()) {
  setRay(rh.ray, org, dir, t_near, t_far);
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
}

/// An intersect context with the coherent flag (for camera rays) or not.
inline RTCIntersectContext intersectContext(bool coherent) {
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  ctx.flags = coherent ? RTC_INTERSECT_CONTEXT_FLAG_COHERENT : RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
  return ctx;
}

}  // namespace evio::scenes
