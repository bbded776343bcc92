#include "evio/scenes/texture.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <numbers>

#include "evio/core/error.h"
#include "evio/core/io/image_file.h"
#include "evio/core/random_stream.h"
#include "evio/scenes/noise.h"

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
  }
}

float Texture::noise(const Eigen::Vector3f& p, float footprint) const {
  const auto& o = options_;
  // Dust/rock patches: a low-frequency field thresholded softly at the rock fraction.
  const float patch = noise::fbm3(p / static_cast<float>(o.patch_wavelength_m), 3, 0.5f, seed_);
  const float threshold = 0.6f * (0.5f - static_cast<float>(o.rock_fraction));
  const float rock = noise::smoothstep(threshold - 0.08f, threshold + 0.08f, patch);
  const float base = static_cast<float>(o.dust_albedo) +
                     rock * static_cast<float>(o.rock_albedo - o.dust_albedo);
  const float wl = static_cast<float>(o.detail_wavelength_m);
  const float detail = noise::fbm3(p / wl, o.octaves, 0.6f, seed_ + 101U, footprint / wl);
  return clamp01(base * (1.0f + static_cast<float>(o.detail_contrast) * 1.6f * detail));
}

float Texture::image(const Eigen::Vector2f& uv) const {
  const auto& o = options_;
  float s = (uv.x() - static_cast<float>(o.offset_m.x())) / static_cast<float>(o.size_m.x()) *
                static_cast<float>(image_.cols) - 0.5f;
  float t = (uv.y() - static_cast<float>(o.offset_m.y())) / static_cast<float>(o.size_m.y()) *
                static_cast<float>(image_.rows) - 0.5f;
  const int x0 = static_cast<int>(std::floor(s)), y0 = static_cast<int>(std::floor(t));
  const float fx = s - static_cast<float>(x0), fy = t - static_cast<float>(y0);
  const auto fetch = [&](int x, int y) {
    if (o.repeat) {
      x %= image_.cols;
      y %= image_.rows;
      if (x < 0) x += image_.cols;
      if (y < 0) y += image_.rows;
    } else {
      x = std::clamp(x, 0, image_.cols - 1);
      y = std::clamp(y, 0, image_.rows - 1);
    }
    return image_.at<float>(y, x);
  };
  const float a = fetch(x0, y0) + fx * (fetch(x0 + 1, y0) - fetch(x0, y0));
  const float b = fetch(x0, y0 + 1) + fx * (fetch(x0 + 1, y0 + 1) - fetch(x0, y0 + 1));
  return clamp01(static_cast<float>(o.gain) * (a + fy * (b - a)));
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

float Texture::evaluate(const Eigen::Vector3f& p_W, const Eigen::Vector2f& uv_m, float footprint_m) const {
  switch (kind_) {
    case Kind::kConstant: return static_cast<float>(options_.value);
    case Kind::kChecker: {
      const float sq = static_cast<float>(options_.square_m);
      const long long i = static_cast<long long>(std::floor(uv_m.x() / sq)) +
                          static_cast<long long>(std::floor(uv_m.y() / sq));
      return static_cast<float>((i & 1LL) ? options_.value_b : options_.value);
    }
    case Kind::kNoise: return noise(p_W, footprint_m);
    case Kind::kImage: return image(uv_m);
    case Kind::kShapes: return shapes(uv_m, footprint_m, static_cast<float>(options_.background));
    case Kind::kCollage: {
      // Paper with a soft mottled print under the shapes.
      const Eigen::Vector3f q(uv_m.x() * 12.0f, uv_m.y() * 12.0f, 0.37f);
      const float n = noise::fbm3(q, options_.octaves, 0.55f, seed_ + 7U, footprint_m * 12.0f);
      const float bg = clamp01(static_cast<float>(options_.background) * (1.0f + 0.35f * n));
      return shapes(uv_m, footprint_m, bg);
    }
  }
  return 0.0f;
}

}  // namespace evio::scenes
