#include "evio/core/camera/camera.h"

#include <cmath>
#include <type_traits>

#include "evio/core/error.h"

namespace evio {

namespace {

template <class Model>
Model makeModel(int width, int height, const Vec4& intrinsics, const VecX& distortion) {
  constexpr int kNumDistortion = Model::kNumParams - 4;
  if (distortion.size() != kNumDistortion) {
    throw Error("distortion: model " + std::string(Model::kModelName) + " expects " +
                std::to_string(kNumDistortion) + " coefficients, got " +
                std::to_string(distortion.size()));
  }
  typename Model::Params params;
  params.template head<4>() = intrinsics;
  if constexpr (kNumDistortion > 0) params.template tail<kNumDistortion>() = distortion;
  return Model(width, height, params);
}

}  // namespace

Camera Camera::create(std::string_view model, int width, int height, const Vec4& intrinsics,
                      const VecX& distortion) {
  if (model == PinholeCamera::kModelName)
    return makeModel<PinholeCamera>(width, height, intrinsics, distortion);
  if (model == RadTanCamera::kModelName)
    return makeModel<RadTanCamera>(width, height, intrinsics, distortion);
  if (model == EquidistantCamera::kModelName)
    return makeModel<EquidistantCamera>(width, height, intrinsics, distortion);
  throw Error("model: unknown camera model '" + std::string(model) + "' (known: " + knownModels() +
              ")");
}

std::string Camera::knownModels() {
  return std::string(PinholeCamera::kModelName) + ", " + RadTanCamera::kModelName + ", " +
         EquidistantCamera::kModelName;
}

std::string_view Camera::model() const {
  return std::visit([](const auto& c) -> std::string_view { return std::decay_t<decltype(c)>::kModelName; },
                    model_);
}

int Camera::width() const {
  return std::visit([](const auto& c) { return c.width(); }, model_);
}

int Camera::height() const {
  return std::visit([](const auto& c) { return c.height(); }, model_);
}

VecX Camera::params() const {
  return std::visit([](const auto& c) -> VecX { return c.params(); }, model_);
}

VecX Camera::distortion() const {
  const VecX p = params();
  return p.tail(p.size() - 4);
}

bool Camera::project(const Vec3& p_C, Vec2* uv, Mat23* d_uv_d_p) const {
  return std::visit([&](const auto& c) { return c.project(p_C, uv, d_uv_d_p); }, model_);
}

bool Camera::unproject(const Vec2& uv, Vec3* bearing_C) const {
  return std::visit([&](const auto& c) { return c.unproject(uv, bearing_C); }, model_);
}

bool Camera::isInside(const Vec2& uv, double border_px) const {
  const double lo = border_px - 0.5;
  return uv.x() >= lo && uv.y() >= lo && uv.x() < width() - 0.5 - border_px &&
         uv.y() < height() - 0.5 - border_px;
}

}  // namespace evio
