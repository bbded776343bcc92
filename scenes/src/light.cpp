#include "evio/scenes/light.h"

#include <cmath>
#include <numbers>

namespace evio::scenes {

void LightOptions::validate() const {
  if (type == "sun") {
    requireInRange("azimuth_deg", azimuth_deg, -360.0, 360.0);
    requireInRange("elevation_deg", elevation_deg, -90.0, 90.0);
    requirePositive("irradiance_w_m2", irradiance_w_m2);
  } else if (type == "sky") {
    requirePositive("radiance_w_m2_sr", radiance_w_m2_sr);
  } else if (type == "point" || type == "spot") {
    requireField(position_m.allFinite(), "position_m", "must be finite");
    requirePositive("intensity_w_sr", intensity_w_sr);
    if (type == "spot") {
      requireField(target_m.allFinite() && (target_m - position_m).norm() > 0.0, "target_m",
                   "must be finite and differ from position_m");
      requireInRange("inner_angle_deg", inner_angle_deg, 0.0, 90.0);
      requireInRange("outer_angle_deg", outer_angle_deg, 0.0, 90.0);
      requireField(outer_angle_deg > inner_angle_deg, "outer_angle_deg",
                   "must be larger than inner_angle_deg");
    }
  } else {
    requireField(false, "type", "unknown light type '" + type + "' (known: " + knownTypes() + ")");
  }
}

Vec3 sunDirection(double azimuth_deg, double elevation_deg) {
  const double a = azimuth_deg * std::numbers::pi / 180.0;
  const double h = elevation_deg * std::numbers::pi / 180.0;
  return Vec3(std::sin(a) * std::cos(h), std::cos(a) * std::cos(h), std::sin(h));
}

}  // namespace evio::scenes
