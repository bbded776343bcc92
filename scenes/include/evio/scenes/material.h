#pragma once
/// @file material.h
/// Materials: a reflectance model and an albedo texture.
///
/// Lambertian:   f(ω_i, ω_o) = ρ / π.
/// Oren–Nayar (M. Oren and S. K. Nayar, "Generalization of Lambert's
/// reflectance model", SIGGRAPH 1994, eq. 30, the "qualitative" model), for a
/// rough surface of V-cavities with slope deviation σ (regolith, sand):
///   f = ρ/π · (A + B · max(0, cos(φ_i − φ_o)) · sin α · tan β),
///   A = 1 − 0.5 σ² / (σ² + 0.33),   B = 0.45 σ² / (σ² + 0.09),
///   α = max(θ_i, θ_o),  β = min(θ_i, θ_o).
/// With unit vectors n, ω_i, ω_o this is evaluated without trigonometry:
///   cos(φ_i − φ_o) sin θ_i sin θ_o = ω_i·ω_o − cos θ_i cos θ_o and
///   sin α tan β = sin θ_i sin θ_o / max(cos θ_i, cos θ_o),
/// so f = ρ/π · (A + B · max(0, ω_i·ω_o − c_i c_o) / max(c_i, c_o)).
/// σ = 0 gives Lambert.

#include <string>

#include "evio/core/options.h"
#include "evio/scenes/texture.h"

namespace evio::scenes {

struct MaterialOptions {
  std::string name;                 ///< referenced by sources' `material`
  std::string model = "lambertian"; ///< lambertian | oren_nayar
  double roughness_deg = 20.0;      ///< Oren–Nayar σ, the slope standard deviation (deg)
  TextureOptions albedo;            ///< the albedo ρ (a texture)

  template <class V>
  void fields(V& v) {
    v("name", name, "material name");
    v("model", model, "lambertian | oren_nayar");
    if (model == "oren_nayar") v("roughness_deg", roughness_deg, "slope deviation sigma (deg)");
    v("albedo", albedo, "albedo texture");
  }
  void validate() const;
};

/// The BRDF of a material without its albedo: f = ρ · brdfOverAlbedo(...).
class Reflectance {
 public:
  Reflectance() = default;
  explicit Reflectance(const MaterialOptions& options);

  /// f(ω_i, ω_o) / ρ in 1/sr. n, wi (towards the light) and wo (towards the
  /// viewer) are unit vectors; c_i = n·ω_i > 0 and c_o = n·ω_o are passed in
  /// because the caller has them. Returns 0 when c_o <= 0.
  float brdfOverAlbedo(const Eigen::Vector3f& wi, const Eigen::Vector3f& wo, float c_i,
                       float c_o) const {
    constexpr float kInvPi = 0.318309886183790671538f;
    if (!oren_nayar_) return kInvPi;
    if (c_o <= 0.0f) return a_ * kInvPi;
    const float s = wi.dot(wo) - c_i * c_o;
    const float m = c_i > c_o ? c_i : c_o;
    return kInvPi * (a_ + (s > 0.0f ? b_ * s / m : 0.0f));
  }

  bool orenNayar() const { return oren_nayar_; }
  float a() const { return a_; }
  float b() const { return b_; }

 private:
  bool oren_nayar_ = false;
  float a_ = 1.0f;
  float b_ = 0.0f;
};

}  // namespace evio::scenes
