#pragma once
/// @file light.h
/// Lights in physical units. World frame W: x east, y north, z up.
///
///   sun    a distant source: irradiance E (W/m²) on a surface facing it;
///          direction to the sun from azimuth A (clockwise from north, +y,
///          towards east, +x) and elevation h above the horizon:
///            s = (sin A cos h, cos A cos h, sin h).
///          A surface with normal n receives E · max(0, n·s) when unoccluded
///          (one occlusion ray). At Mars E ≈ 590 W/m² (top of atmosphere).
///   sky    uniform radiance L (W/(m²·sr)) from the upper hemisphere (z > 0).
///          Unoccluded, a surface with normal n receives
///            E_sky = π L (1 + n_z) / 2
///          (the upper hemisphere seen from a plane tilted by acos n_z). With
///          indirect light on (SceneOptions::indirect) the sky is instead
///          integrated with occlusion into the irradiance cache.
///          Camera rays that leave the scene upwards see L.
///   point  isotropic intensity I (W/sr) at position x_L: irradiance
///            E = I · max(0, n·ω) / d²,  ω = (x_L − x)/d, d = |x_L − x|.
///   spot   a point light restricted to a cone around its axis (towards
///          target_m): full intensity within inner_angle_deg, smooth fall-off
///          (smoothstep in cos) to zero at outer_angle_deg.

#include <string>

#include "evio/core/eigen_types.h"
#include "evio/core/options.h"

namespace evio::scenes {

struct LightOptions {
  std::string type = "sun";  ///< sun | sky | point | spot

  // sun
  double azimuth_deg = 135.0;     ///< clockwise from north (+y) towards east (+x)
  double elevation_deg = 30.0;    ///< above the horizon
  double irradiance_w_m2 = 590.0; ///< on a surface facing the sun

  // sky
  double radiance_w_m2_sr = 10.0; ///< uniform over the upper hemisphere

  // point, spot
  Vec3 position_m = Vec3(0.0, 0.0, 2.0);  ///< light position in W
  double intensity_w_sr = 10.0;           ///< radiant intensity

  // spot
  Vec3 target_m = Vec3(0.0, 0.0, 0.0);    ///< the cone axis points at this point
  double inner_angle_deg = 20.0;          ///< full intensity inside this half-angle
  double outer_angle_deg = 30.0;          ///< zero outside this half-angle

  template <class V>
  void fields(V& v) {
    v("type", type, "sun | sky | point | spot");
    if (type == "sun") {
      v("azimuth_deg", azimuth_deg, "clockwise from north (+y) towards east (+x), deg");
      v("elevation_deg", elevation_deg, "above the horizon, deg");
      v("irradiance_w_m2", irradiance_w_m2, "irradiance on a surface facing the sun, W/m^2");
    } else if (type == "sky") {
      v("radiance_w_m2_sr", radiance_w_m2_sr, "uniform sky radiance, W/(m^2 sr)");
    } else if (type == "point" || type == "spot") {
      v("position_m", position_m, "position in the world frame, m");
      v("intensity_w_sr", intensity_w_sr, "radiant intensity, W/sr");
      if (type == "spot") {
        v("target_m", target_m, "the cone axis points here, m");
        v("inner_angle_deg", inner_angle_deg, "full-intensity half-angle, deg");
        v("outer_angle_deg", outer_angle_deg, "cut-off half-angle, deg");
      }
    }
  }
  /// Throws Error naming the field: unknown type, zero or negative power,
  /// angles out of range.
  void validate() const;
  static std::string knownTypes() { return "sun, sky, point, spot"; }
};

/// Unit vector towards the sun in W (see the file comment).
Vec3 sunDirection(double azimuth_deg, double elevation_deg);

}  // namespace evio::scenes
