#include "evio/scenes/material.h"

#include <numbers>

namespace evio::scenes {

void MaterialOptions::validate() const {
  requireField(!name.empty(), "name", "a material needs a name");
  requireField(model == "lambertian" || model == "oren_nayar", "model",
               "unknown reflectance model '" + model + "' (known: lambertian, oren_nayar)");
  if (model == "oren_nayar") requireInRange("roughness_deg", roughness_deg, 0.0, 60.0);
  try {
    albedo.validate();
  } catch (const Error& e) {
    throw Error(std::string("albedo.") + e.what());
  }
}

Reflectance::Reflectance(const MaterialOptions& options) {
  if (options.model != "oren_nayar") return;
  oren_nayar_ = true;
  const double sigma = options.roughness_deg * std::numbers::pi / 180.0;
  const double s2 = sigma * sigma;
  a_ = static_cast<float>(1.0 - 0.5 * s2 / (s2 + 0.33));
  b_ = static_cast<float>(0.45 * s2 / (s2 + 0.09));
}

}  // namespace evio::scenes
