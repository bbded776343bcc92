#pragma once
/// @file lava_tube.h
/// A lava tube: an irregular, flat-floored tunnel with a roof collapse (the
/// entrance through which sunlight enters). Its faces point inwards (the
/// rock is outside the tunnel), its ends are closed.
///
/// In the tube's local frame (axis along +x from `position_m`, rotated by
/// yaw about z) the cross-section at distance s along the axis is the ellipse
///   q(θ) = c(s) + f(s, θ) · (W/2 · sin θ, −H/2 · cos θ)      (θ = 0 at the bottom)
/// with c(s) = (s, meander · noise(s), 0) and f = 1 + roughness · fbm3(·/λ),
/// cut flat at the floor z = −floor_depth_m + 3 cm · fbm (rubbly floor).
/// The collapse removes the wall cells whose centre satisfies
///   ((s − s_c) / (L_c/2))² + (a / (W_c/2))² + 0.35 · fbm < 1,
/// a the arc length from the top of the section: an irregular opening.

#include <cstdint>
#include <string>

#include "evio/core/eigen_types.h"
#include "evio/core/triangle_mesh.h"
#include "evio/scenes/source_options.h"

namespace evio::scenes {

class LavaTube {
 public:
  LavaTube(const TubeParams& params, std::uint64_t seed, const std::string& name);

  /// The tube mesh in W (faces inwards), uv = (s, arc length) in metres.
  TriangleMesh mesh() const;

  /// Floor height z (m, world) at world (x, y) (rocks rest on it).
  double floorHeight(double x, double y) const;

  /// World point on the axis at distance s (m) from the start, at floor + h.
  Vec3 pointAboveFloor(double s, double h) const;

 private:
  Vec3 toWorld(const Vec3& local) const;
  double floorLocal(double s, double y) const;
  double meander(double s) const;

  TubeParams p_;
  std::uint32_t seed_;
  Mat3 R_;
};

}  // namespace evio::scenes
