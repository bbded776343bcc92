#include "evio/simulator/range_finder.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <cmath>

#include "evio/scenes/embree_util.h"

namespace evio::simulator {

RangeFinder::RayCast RangeFinder::sceneRayCast(const scenes::Scene& scene) {
  return [&scene](const Vec3& origin_W, const Vec3& dir_W) {
    RTCRayHit rh;
    scenes::setRayHit(rh, origin_W.cast<float>(), dir_W.normalized().cast<float>());
    RTCIntersectContext ctx = scenes::intersectContext(false);
    rtcIntersect1(scene.embree(), &ctx, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return std::numeric_limits<double>::infinity();
    return static_cast<double>(rh.ray.tfar);
  };
}

RangeFinder::RangeFinder(const RangeFinderSensor& sensor, RayCast cast, std::uint64_t seed)
    : sensor_(sensor), cast_(std::move(cast)), noise_(seed, "range_finder") {
  sensor_.validate();
  require(static_cast<bool>(cast_), "RangeFinder: no ray cast given");
}

RangeMeasurement RangeFinder::measure(TimeNs t_ns, const Pose& T_W_B) {
  const Pose T_W_L = T_W_B * sensor_.T_B_L;
  const Vec3 dir = T_W_L.rotation().col(2);
  RangeMeasurement m;
  m.reading.t_ns = t_ns;
  m.true_range_m = cast_(T_W_L.translation(), dir);
  const double n = noise_.normal();  // drawn for every measurement: the stream does not depend on returns
  m.reading.valid = std::isfinite(m.true_range_m) && m.true_range_m >= sensor_.min_range_m &&
                    m.true_range_m <= sensor_.max_range_m;
  m.reading.range_m = m.reading.valid ? std::max(0.0, m.true_range_m + sensor_.noise_sigma_m * n) : 0.0;
  return m;
}

}  // namespace evio::simulator
