#pragma once
/// @file texture.h
/// Albedo textures: the scalar reflectance ρ ∈ [0, 1] at a surface point.
/// Texture detail is what gives an event camera something to see.
///
/// Procedural textures are pure functions of the world point p_W (m) or of
/// the surface coordinates uv (m; see each generator) and a seed, so a static
/// scene looks the same at every render. `footprint_m`, the size of one pixel
/// on the surface, drops noise octaves finer than about four pixels
/// (value_noise.h) and antialiases shape edges, so that sub-pixel detail does
/// not alias into flicker (false events).
///
/// image: mip-mapped (mip_map.h) with the footprint in texels.
/// shapes, collage: evaluated once at build on a grid of texels of 1/8 of the
/// smallest shape radius (at most 4096² texels over region_m, antialiased),
/// then looked up like an image; outside region_m: the background.
/// noise: a = d + r_w · (r − d) with the rock weight
///   r_w = smoothstep(θ − 0.08, θ + 0.08, n(p / λ_patch)) (one octave),
///   θ = 0.5 (0.5 − rock_fraction), then the detail
///   ρ = clamp(a · (1 + 1.6 c · fbm(p / λ_detail, octaves, gain 0.6)), 0, 1)
/// (d, r the dust and rock albedo, c the detail contrast).

#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "evio/core/eigen_types.h"
#include "evio/core/options.h"
#include "evio/scenes/mip_map.h"
#include "evio/scenes/value_noise.h"

namespace evio::scenes {

/// One YAML map `albedo: {type: ..., ...}`; only the fields of `type` are
/// accepted (the others are rejected as unknown keys).
struct TextureOptions {
  /// constant | noise | image | shapes | collage | checker
  std::string type = "constant";

  // constant, checker
  double value = 0.25;          ///< albedo (constant; first checker colour)
  double value_b = 0.05;        ///< second checker colour
  double square_m = 0.1;        ///< checker square size in uv metres

  // noise: patches of dust and rock with multi-octave detail
  double dust_albedo = 0.28;           ///< albedo of fine dust
  double rock_albedo = 0.14;           ///< albedo of exposed rock and coarse regolith
  double patch_wavelength_m = 3.0;     ///< size of dust/rock patches
  double rock_fraction = 0.4;          ///< share of the surface that is rock, [0, 1]
  double detail_wavelength_m = 0.5;    ///< largest wavelength of the fine detail
  double detail_contrast = 0.35;       ///< relative albedo variation of the detail
  int octaves = 7;                     ///< detail octaves (each halves the wavelength)

  // image
  std::string path;                    ///< PNG, JPEG or EXR (grayscale or colour → luminance)
  Vec2 size_m = Vec2(1.0, 1.0);        ///< uv extent covered by one copy of the image
  Vec2 offset_m = Vec2(0.0, 0.0);      ///< uv of the image's top-left corner
  bool repeat = true;                  ///< tile the image (else clamp to its border)
  double gain = 1.0;                   ///< albedo = gain · pixel value

  // shapes (black shapes on white) and collage (a poster of grey shapes on noise)
  double background = 0.85;            ///< albedo of the paper
  double foreground = 0.04;            ///< albedo of the shapes (collage: darkest grey)
  int count = 12;                      ///< number of shapes
  Vec2 region_m = Vec2(1.0, 1.0);      ///< uv rectangle [0, region] the shapes are placed in
  Vec2 shape_size_m = Vec2(0.05, 0.15);  ///< min and max shape radius

  template <class V>
  void fields(V& v) {
    v("type", type, "constant | noise | image | shapes | collage | checker");
    if (type == "constant") {
      v("value", value, "albedo");
    } else if (type == "checker") {
      v("value", value, "first colour");
      v("value_b", value_b, "second colour");
      v("square_m", square_m, "square size (m)");
    } else if (type == "noise") {
      v("dust_albedo", dust_albedo, "albedo of dust");
      v("rock_albedo", rock_albedo, "albedo of rock");
      v("patch_wavelength_m", patch_wavelength_m, "size of dust/rock patches (m)");
      v("rock_fraction", rock_fraction, "share of rock");
      v("detail_wavelength_m", detail_wavelength_m, "largest detail wavelength (m)");
      v("detail_contrast", detail_contrast, "relative detail contrast");
      v("octaves", octaves, "detail octaves");
    } else if (type == "image") {
      v("path", path, "image file, relative to the scene file");
      v("size_m", size_m, "uv extent of one image copy (m)");
      v("offset_m", offset_m, "uv of the top-left corner (m)");
      v("repeat", repeat, "tile the image");
      v("gain", gain, "albedo per pixel value");
    } else if (type == "shapes" || type == "collage") {
      v("background", background, "paper albedo");
      v("foreground", foreground, "shape albedo");
      v("count", count, "number of shapes");
      v("region_m", region_m, "uv region of the shapes (m)");
      v("shape_size_m", shape_size_m, "min and max shape radius (m)");
      if (type == "collage") v("octaves", octaves, "background noise octaves");
    }
  }
  /// Throws Error "<field>: ..." for an unknown type or an out-of-range value.
  void validate() const;
  /// "constant, noise, image, shapes, collage, checker".
  static std::string knownTypes();
};

/// A texture ready to evaluate (images loaded, shapes placed).
class Texture {
 public:
  /// `seed` makes procedural textures distinct per material; `base_dir` is
  /// where relative image paths are resolved; `field` names the option for
  /// messages (e.g. "scene.yaml:12: materials[1].albedo.path").
  Texture(const TextureOptions& options, std::uint64_t seed, const std::string& base_dir,
          const std::string& field);

  /// Albedo in [0, 1] at world point p_W (m) with surface coordinates uv_m (m)
  /// and a pixel footprint of footprint_m (m; 0 = full detail).
  float evaluate(const Eigen::Vector3f& p_W, const Eigen::Vector2f& uv_m, float footprint_m) const;

  /// evaluate() at eight points (p_W = (px, py, pz)[k], uv_m = (u, v)[k],
  /// footprint[k]) with AVX2 across the points (only on a CPU that has it):
  /// out[k] is evaluate()'s value bit for bit.
  void evaluate8Avx2(const float* px, const float* py, const float* pz, const float* u, const float* v,
                     const float* footprint, float* out) const;

  const TextureOptions& options() const { return options_; }

 private:
  struct Shape {
    Eigen::Vector2f centre;
    float radius;
    float angle;
    float value;
    int sides;  ///< 0 = circle, else regular polygon with this many sides
  };
  float noise(const Eigen::Vector3f& p, float footprint) const;
  float image(const Eigen::Vector2f& uv, float footprint) const;
  float shapes(const Eigen::Vector2f& uv, float footprint, float background) const;
  float collage(const Eigen::Vector2f& uv, float footprint) const;

  TextureOptions options_;
  std::uint32_t seed_;
  enum class Kind { kConstant, kChecker, kNoise, kImage, kShapes, kCollage } kind_;
  std::unique_ptr<noise::ValueLattice> lattice_;  ///< noise and collage
  struct NoiseConstants {  ///< the noise texture's options, as the inner loop uses them
    float inv_patch_wl = 1.0f, inv_detail_wl = 1.0f, threshold = 0.0f;
    float dust = 0.0f, rock_minus_dust = 0.0f, contrast = 0.0f;
  } noise_;
  cv::Mat image_;  ///< CV_32FC1
  std::vector<Shape> shapes_;
  MipMap mip_;            ///< image, or the baked shapes/collage texture
  float texel_m_ = 0.0f;  ///< baked texel size (shapes, collage)
};

// The lookup, inline for the renderer's inner loop.

inline float Texture::evaluate(const Eigen::Vector3f& p_W, const Eigen::Vector2f& uv_m, float footprint_m) const {
  switch (kind_) {
    case Kind::kConstant: return static_cast<float>(options_.value);
    case Kind::kChecker: {
      const float sq = static_cast<float>(options_.square_m);
      const long long i = static_cast<long long>(std::floor(uv_m.x() / sq)) +
                          static_cast<long long>(std::floor(uv_m.y() / sq));
      return static_cast<float>((i & 1LL) ? options_.value_b : options_.value);
    }
    case Kind::kNoise: return noise(p_W, footprint_m);
    case Kind::kImage: return image(uv_m, footprint_m);
    case Kind::kShapes:
    case Kind::kCollage: {
      const float s = uv_m.x() / texel_m_, t = uv_m.y() / texel_m_;
      if (s < 0.0f || t < 0.0f || s > static_cast<float>(mip_.level(0).cols) ||
          t > static_cast<float>(mip_.level(0).rows))
        return static_cast<float>(options_.background);
      return mip_.sample(s, t, footprint_m / texel_m_);
    }
  }
  return 0.0f;
}

}  // namespace evio::scenes
