#pragma once
/// @file lava_tube.h
/// A lava tube entered from a collapse pit: the rock is an implicit solid,
/// free space the union of the air above the ground surface, the pit and the
/// tunnel, extracted as one closed surface (isosurface.h) whose faces point
/// into the free space. Sunlight reaches the inside only through the pit and
/// the mouth.
///
/// Local frame: x along the tube axis (x = 0 at the mouth, the pit at
/// x ∈ [−pit_length, 0]), z up from the mouth's floor; world = Rz(yaw) · local
/// + position_m. Free space is where any of these is positive (m):
///   air    z − (S + A_s fbm2(x/12, y/12))                      (S surface height)
///   pit    min((1 − r) · W_p/2 + 0.8 fbm2 + 0.12 z,  z − f_p(x, y)),
///          r = (|2(x + L_p/2)/L_p|⁴ + |2y/W_p|⁴)^¼   (rounded rectangle in plan)
///   tube   min((g − ρ) · min(a, b),  z − f_t(x, y),  L − x,  x + 3),
///          ρ = √(((y − m(x))/a)² + ((z − d)/b)²),  g = 1 + 1.4 k fbm3(p/λ)
/// with a, b the half width and height, d = floor_depth_m, k = roughness,
/// m(x) the meander (m(0) = 0) and f_p, f_t rubbly floors near z = 0.

#include <cstdint>
#include <string>

#include "evio/core/eigen_types.h"
#include "evio/core/triangle_mesh.h"
#include "evio/scenes/source_options.h"

namespace evio::scenes {

class LavaTube {
 public:
  LavaTube(const TubeParams& params, std::uint64_t seed, const std::string& name);

  /// The closed rock surface in W (faces towards free space), uv = world (x, y).
  TriangleMesh mesh() const;

  /// Free-space value at a local point (> 0 in the air, pit or tube; m).
  double freeSpace(const Vec3& local) const;

  /// Floor height z (m, world) at world (x, y): the pit floor inside the
  /// pit's plan, else the tube floor (rocks rest on it).
  double floorHeight(double x, double y) const;

  /// World point on the tube axis at distance s (m) from the mouth, h above the floor.
  Vec3 pointAboveFloor(double s, double h) const;

 private:
  Vec3 toWorld(const Vec3& local) const { return R_ * local + p_.position_m; }
  double meander(double x) const;
  double pitPlan(double x, double y) const;
  double pitFloor(double x, double y) const;
  double tubeFloor(double x, double y) const;

  TubeParams p_;
  std::uint32_t seed_;
  Mat3 R_;
};

}  // namespace evio::scenes
