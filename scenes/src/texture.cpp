#include "evio/scenes/texture.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <numbers>

#include "evio/core/error.h"
#include "evio/core/io/image_file.h"
#include "evio/core/random_stream.h"
#include "evio/scenes/noise.h"
#include "avx2.h"

namespace evio::scenes {

namespace {
constexpr float kPi = std::numbers::pi_v<float>;

float clamp01(float x) { return x < 0.0f ? 0.0f : (x > 1.0f ? 1.0f : x); }
}  // namespace

std::string TextureOptions::knownTypes() { return "constant, noise, image, shapes, collage, checker"; }

void TextureOptions::validate() const {
  if (type == "constant") {
    requireInRange("value", value, 0.0, 1.0);
  } else if (type == "checker") {
    requireInRange("value", value, 0.0, 1.0);
    requireInRange("value_b", value_b, 0.0, 1.0);
    requirePositive("square_m", square_m);
  } else if (type == "noise") {
    requireInRange("dust_albedo", dust_albedo, 0.0, 1.0);
    requireInRange("rock_albedo", rock_albedo, 0.0, 1.0);
    requirePositive("patch_wavelength_m", patch_wavelength_m);
    requireInRange("rock_fraction", rock_fraction, 0.0, 1.0);
    requirePositive("detail_wavelength_m", detail_wavelength_m);
    requireInRange("detail_contrast", detail_contrast, 0.0, 1.0);
    requireInRange("octaves", octaves, 1, 16);
  } else if (type == "image") {
    requireField(!path.empty(), "path", "an image file is required");
    requirePositive("size_m[0]", size_m.x());
    requirePositive("size_m[1]", size_m.y());
    requireNonNegative("gain", gain);
  } else if (type == "shapes" || type == "collage") {
    requireInRange("background", background, 0.0, 1.0);
    requireInRange("foreground", foreground, 0.0, 1.0);
    requireInRange("count", count, 0, 10000);
    requirePositive("region_m[0]", region_m.x());
    requirePositive("region_m[1]", region_m.y());
    requirePositive("shape_size_m[0]", shape_size_m.x());
    requireField(shape_size_m.y() >= shape_size_m.x(), "shape_size_m", "max must be >= min");
    if (type == "collage") requireInRange("octaves", octaves, 1, 16);
  } else {
    requireField(false, "type", "unknown texture type '" + type + "' (known: " + knownTypes() + ")");
  }
}

Texture::Texture(const TextureOptions& options, std::uint64_t seed, const std::string& base_dir,
                 const std::string& field)
    : options_(options), seed_(static_cast<std::uint32_t>(seed ^ (seed >> 32))) {
  const std::string& t = options.type;
  if (t == "constant") kind_ = Kind::kConstant;
  else if (t == "checker") kind_ = Kind::kChecker;
  else if (t == "noise") kind_ = Kind::kNoise;
  else if (t == "image") kind_ = Kind::kImage;
  else if (t == "shapes") kind_ = Kind::kShapes;
  else if (t == "collage") kind_ = Kind::kCollage;
  else throw Error(field + ".type: unknown texture type '" + t + "' (known: " + TextureOptions::knownTypes() + ")");

  if (kind_ == Kind::kNoise || kind_ == Kind::kCollage)
    lattice_ = std::make_unique<noise::ValueLattice>(seed);
  if (kind_ == Kind::kNoise) {
    noise_.inv_patch_wl = static_cast<float>(1.0 / options.patch_wavelength_m);
    noise_.inv_detail_wl = static_cast<float>(1.0 / options.detail_wavelength_m);
    noise_.threshold = static_cast<float>(0.5 * (0.5 - options.rock_fraction));
    noise_.dust = static_cast<float>(options.dust_albedo);
    noise_.rock_minus_dust = static_cast<float>(options.rock_albedo - options.dust_albedo);
    noise_.contrast = static_cast<float>(1.6 * options.detail_contrast);
  }
  if (kind_ == Kind::kImage) {
    std::filesystem::path p(options.path);
    if (p.is_relative() && !base_dir.empty()) p = std::filesystem::path(base_dir) / p;
    try {
      image_ = io::readGrayImage(p.string());
    } catch (const Error& e) {
      throw Error(field + ".path: " + e.what());
    }
    if (image_.cols < 1 || image_.rows < 1) throw Error(field + ".path: empty image " + p.string());
    for (int r = 0; r < image_.rows; ++r)
      for (int c = 0; c < image_.cols; ++c)
        if (!std::isfinite(image_.at<float>(r, c)))
          throw Error(field + ".path: " + p.string() + ": non-finite pixel at (" + std::to_string(c) +
                      ", " + std::to_string(r) + ")");
  }
  if (kind_ == Kind::kImage) mip_ = MipMap(image_, options.repeat);
  if (kind_ == Kind::kShapes || kind_ == Kind::kCollage) {
    RandomStream rng(seed, "texture shapes");
    const double rmin = options.shape_size_m.x(), rmax = options.shape_size_m.y();
    for (int i = 0; i < options.count; ++i) {
      Shape s;
      const double radius = rng.uniform(rmin, rmax);
      s.radius = static_cast<float>(radius);
      // Keep shapes inside the region.
      s.centre = Eigen::Vector2f(
          static_cast<float>(rng.uniform(radius, std::max(radius, options.region_m.x() - radius))),
          static_cast<float>(rng.uniform(radius, std::max(radius, options.region_m.y() - radius))));
      s.angle = static_cast<float>(rng.uniform(0.0, 2.0 * std::numbers::pi));
      const int kind = static_cast<int>(rng.uniformInt(5));
      static constexpr int kSides[5] = {0, 3, 4, 5, 6};
      s.sides = kSides[kind];
      s.value = kind_ == Kind::kShapes
                    ? static_cast<float>(options.foreground)
                    : static_cast<float>(rng.uniform(options.foreground, options.background));
      shapes_.push_back(s);
    }
    // Bake onto texels of 1/8 of the smallest radius (at most 4096 per axis).
    const double texel = std::max({options.shape_size_m.x() / 8.0, options.region_m.x() / 4096.0,
                                   options.region_m.y() / 4096.0});
    texel_m_ = static_cast<float>(texel);
    const int cols = std::max(1, static_cast<int>(std::ceil(options.region_m.x() / texel)));
    const int rows = std::max(1, static_cast<int>(std::ceil(options.region_m.y() / texel)));
    cv::Mat baked(rows, cols, CV_32FC1);
    for (int r = 0; r < rows; ++r)
      for (int c = 0; c < cols; ++c) {
        const Eigen::Vector2f uv(static_cast<float>((c + 0.5) * texel), static_cast<float>((r + 0.5) * texel));
        baked.at<float>(r, c) = kind_ == Kind::kShapes
                                    ? shapes(uv, texel_m_, static_cast<float>(options.background))
                                    : collage(uv, texel_m_);
      }
    mip_ = MipMap(baked, false);
  }
}

float Texture::noise(const Eigen::Vector3f& p, float footprint) const {
  const NoiseConstants& c = noise_;
  // Dust/rock patches: a low-frequency field thresholded softly at the rock fraction.
  const float patch = lattice_->value(p * c.inv_patch_wl);
  const float rock = noise::smoothstep(c.threshold - 0.08f, c.threshold + 0.08f, patch);
  const float base = c.dust + rock * c.rock_minus_dust;
  const float detail = lattice_->fbm(p * c.inv_detail_wl + Eigen::Vector3f(11.3f, 29.1f, 5.7f),
                                     options_.octaves, 0.6f, footprint * c.inv_detail_wl);
  return clamp01(base * (1.0f + c.contrast * detail));
}

float Texture::collage(const Eigen::Vector2f& uv, float footprint) const {
  // Paper with a soft mottled print under the shapes.
  const Eigen::Vector3f q(uv.x() * 12.0f, uv.y() * 12.0f, 0.37f);
  const float n = lattice_->fbm(q, options_.octaves, 0.55f, footprint * 12.0f);
  const float bg = clamp01(static_cast<float>(options_.background) * (1.0f + 0.35f * n));
  return shapes(uv, footprint, bg);
}

float Texture::image(const Eigen::Vector2f& uv, float footprint) const {
  const auto& o = options_;
  const float sx = static_cast<float>(image_.cols) / static_cast<float>(o.size_m.x());
  const float sy = static_cast<float>(image_.rows) / static_cast<float>(o.size_m.y());
  return clamp01(static_cast<float>(o.gain) *
                 mip_.sample((uv.x() - static_cast<float>(o.offset_m.x())) * sx,
                             (uv.y() - static_cast<float>(o.offset_m.y())) * sy, footprint * sx));
}

float Texture::shapes(const Eigen::Vector2f& uv, float footprint, float background) const {
  const float fp = std::max(footprint, 1e-5f);
  float value = background;
  for (const Shape& s : shapes_) {
    const Eigen::Vector2f q = uv - s.centre;
    const float r2 = q.squaredNorm();
    const float reach = s.radius + fp;
    if (r2 > reach * reach) continue;
    const float r = std::sqrt(r2);
    float sd;  // signed distance, negative inside
    if (s.sides == 0) {
      sd = r - s.radius;
    } else {
      // Regular polygon with circumradius `radius`: distance to the nearest
      // edge line along its normal (exact inside, close outside).
      const float sector = 2.0f * kPi / static_cast<float>(s.sides);
      const float a = std::atan2(q.y(), q.x()) - s.angle;
      const float k = std::floor(a / sector + 0.5f);
      const float apothem = s.radius * std::cos(0.5f * sector);
      sd = std::cos(a - k * sector) * r - apothem;
    }
    const float alpha = clamp01(0.5f - sd / fp);
    value += alpha * (s.value - value);
  }
  return value;
}

#if defined(EVIO_SCENES_AVX2)
EVIO_AVX2 void Texture::evaluate8Avx2(const float* px, const float* py, const float* pz, const float* u,
                                      const float* v, const float* footprint, float* out) const {
  switch (kind_) {
    case Kind::kNoise: {  // noise() lane by lane
      const NoiseConstants& c = noise_;
      alignas(32) float q[3][8], patch[8], fp[8], detail[8];
      const __m256 x = _mm256_loadu_ps(px), y = _mm256_loadu_ps(py), z = _mm256_loadu_ps(pz);
      const __m256 inv_patch = _mm256_set1_ps(c.inv_patch_wl), inv_detail = _mm256_set1_ps(c.inv_detail_wl);
      _mm256_store_ps(q[0], _mm256_mul_ps(x, inv_patch));
      _mm256_store_ps(q[1], _mm256_mul_ps(y, inv_patch));
      _mm256_store_ps(q[2], _mm256_mul_ps(z, inv_patch));
      lattice_->value8Avx2(q[0], q[1], q[2], patch);
      // smoothstep(threshold − 0.08, threshold + 0.08, patch)
      const float e0 = c.threshold - 0.08f, e1 = c.threshold + 0.08f;
      const __m256 t = avx2::clamp01(
          _mm256_div_ps(_mm256_sub_ps(_mm256_load_ps(patch), _mm256_set1_ps(e0)), _mm256_set1_ps(e1 - e0)));
      const __m256 rock = _mm256_mul_ps(_mm256_mul_ps(t, t), _mm256_sub_ps(_mm256_set1_ps(3.0f), _mm256_mul_ps(_mm256_set1_ps(2.0f), t)));
      const __m256 base = _mm256_add_ps(_mm256_set1_ps(c.dust), _mm256_mul_ps(rock, _mm256_set1_ps(c.rock_minus_dust)));
      _mm256_store_ps(q[0], _mm256_add_ps(_mm256_mul_ps(x, inv_detail), _mm256_set1_ps(11.3f)));
      _mm256_store_ps(q[1], _mm256_add_ps(_mm256_mul_ps(y, inv_detail), _mm256_set1_ps(29.1f)));
      _mm256_store_ps(q[2], _mm256_add_ps(_mm256_mul_ps(z, inv_detail), _mm256_set1_ps(5.7f)));
      _mm256_store_ps(fp, _mm256_mul_ps(_mm256_loadu_ps(footprint), inv_detail));
      lattice_->fbm8Avx2(q[0], q[1], q[2], options_.octaves, 0.6f, fp, detail);
      const __m256 r = _mm256_mul_ps(
          base, _mm256_add_ps(_mm256_set1_ps(1.0f), _mm256_mul_ps(_mm256_set1_ps(c.contrast), _mm256_load_ps(detail))));
      _mm256_storeu_ps(out, avx2::clamp01(r));
      return;
    }
    case Kind::kShapes:
    case Kind::kCollage: {  // the baked texture inside [0, cols] × [0, rows] texels, else the background
      const __m256 texel = _mm256_set1_ps(texel_m_);
      const __m256 s = _mm256_div_ps(_mm256_loadu_ps(u), texel), t = _mm256_div_ps(_mm256_loadu_ps(v), texel);
      const __m256 zero = _mm256_setzero_ps();
      const __m256 outside = _mm256_or_ps(
          _mm256_or_ps(_mm256_cmp_ps(s, zero, _CMP_LT_OQ), _mm256_cmp_ps(t, zero, _CMP_LT_OQ)),
          _mm256_or_ps(_mm256_cmp_ps(s, _mm256_set1_ps(static_cast<float>(mip_.level(0).cols)), _CMP_GT_OQ),
                       _mm256_cmp_ps(t, _mm256_set1_ps(static_cast<float>(mip_.level(0).rows)), _CMP_GT_OQ)));
      alignas(32) float ss[8], tt[8], fp[8], r[8];
      _mm256_store_ps(ss, s);
      _mm256_store_ps(tt, t);
      _mm256_store_ps(fp, _mm256_div_ps(_mm256_loadu_ps(footprint), texel));
      mip_.sample8Avx2(ss, tt, fp, r);
      _mm256_storeu_ps(out, _mm256_blendv_ps(_mm256_load_ps(r), _mm256_set1_ps(static_cast<float>(options_.background)), outside));
      return;
    }
    case Kind::kImage: {  // image() lane by lane
      const auto& o = options_;
      const float sx = static_cast<float>(image_.cols) / static_cast<float>(o.size_m.x());
      const float sy = static_cast<float>(image_.rows) / static_cast<float>(o.size_m.y());
      alignas(32) float ss[8], tt[8], fp[8], r[8];
      _mm256_store_ps(ss, _mm256_mul_ps(_mm256_sub_ps(_mm256_loadu_ps(u), _mm256_set1_ps(static_cast<float>(o.offset_m.x()))),
                                        _mm256_set1_ps(sx)));
      _mm256_store_ps(tt, _mm256_mul_ps(_mm256_sub_ps(_mm256_loadu_ps(v), _mm256_set1_ps(static_cast<float>(o.offset_m.y()))),
                                        _mm256_set1_ps(sy)));
      _mm256_store_ps(fp, _mm256_mul_ps(_mm256_loadu_ps(footprint), _mm256_set1_ps(sx)));
      mip_.sample8Avx2(ss, tt, fp, r);
      _mm256_storeu_ps(out, avx2::clamp01(_mm256_mul_ps(_mm256_set1_ps(static_cast<float>(o.gain)), _mm256_load_ps(r))));
      return;
    }
    case Kind::kConstant:
    case Kind::kChecker:
      break;
  }
  for (int k = 0; k < 8; ++k)
    out[k] = evaluate(Eigen::Vector3f(px[k], py[k], pz[k]), Eigen::Vector2f(u[k], v[k]), footprint[k]);
}
#else
void Texture::evaluate8Avx2(const float* px, const float* py, const float* pz, const float* u, const float* v,
                            const float* footprint, float* out) const {
  for (int k = 0; k < 8; ++k)
    out[k] = evaluate(Eigen::Vector3f(px[k], py[k], pz[k]), Eigen::Vector2f(u[k], v[k]), footprint[k]);
}
#endif

}  // namespace evio::scenes
