#pragma once
/// @file camera.h
/// A camera of any supported model behind one value type (std::variant over
/// PinholeCamera, RadTanCamera, EquidistantCamera), for code that reads the
/// model from a file. Conventions (frames, pixel centres): camera_common.h.

#include <string>
#include <string_view>
#include <variant>

#include "evio/core/camera/camera_common.h"
#include "evio/core/camera/equidistant_camera.h"
#include "evio/core/camera/pinhole_camera.h"
#include "evio/core/camera/radtan_camera.h"
#include "evio/core/eigen_types.h"

namespace evio {

class Camera {
 public:
  using Model = std::variant<PinholeCamera, RadTanCamera, EquidistantCamera>;

  /// Implicit from any concrete model.
  Camera(PinholeCamera c) : model_(std::move(c)) {}      // NOLINT(google-explicit-constructor)
  Camera(RadTanCamera c) : model_(std::move(c)) {}       // NOLINT(google-explicit-constructor)
  Camera(EquidistantCamera c) : model_(std::move(c)) {}  // NOLINT(google-explicit-constructor)

  /// Builds and validates a camera from its description:
  ///   model        "pinhole", "radtan" or "equidistant";
  ///   width/height resolution in pixels (> 0);
  ///   intrinsics   [fx, fy, cx, cy] in pixels (fx, fy > 0);
  ///   distortion   pinhole: empty; radtan: [k1, k2, p1, p2, k3];
  ///                equidistant: [k1, k2, k3, k4].
  /// Throws evio::Error naming the offending field ("model", "resolution.width",
  /// "intrinsics.fx", "distortion", "distortion[2] (p1)", ...).
  static Camera create(std::string_view model, int width, int height, const Vec4& intrinsics,
                       const VecX& distortion);

  /// The model names create() accepts, for messages: "pinhole, radtan, equidistant".
  static std::string knownModels();

  /// "pinhole", "radtan" or "equidistant".
  std::string_view model() const;
  int width() const;
  int height() const;
  /// All parameters in the model's order ([fx, fy, cx, cy, distortion...]).
  VecX params() const;
  /// [fx, fy, cx, cy].
  Vec4 intrinsics() const { return params().head<4>(); }
  /// The distortion coefficients (empty for pinhole), as create() takes them.
  VecX distortion() const;

  /// Pixel of p_C with optional ∂uv/∂p_C; see the concrete models.
  bool project(const Vec3& p_C, Vec2* uv, Mat23* d_uv_d_p = nullptr) const;
  /// Unit-norm bearing of pixel uv; see the concrete models.
  bool unproject(const Vec2& uv, Vec3* bearing_C) const;

  /// True when uv lies in the image shrunk by border_px on every side:
  ///   border_px - 0.5 <= u < width - 0.5 - border_px (and alike for v),
  /// so that for border_px = 0 exactly the uv that round to a valid pixel index
  /// are inside. False for non-finite uv.
  bool isInside(const Vec2& uv, double border_px = 0.0) const;

  /// The concrete model, for std::visit or std::get_if.
  const Model& variant() const { return model_; }
  /// The concrete model if it is a T, else nullptr.
  template <class T>
  const T* as() const {
    return std::get_if<T>(&model_);
  }

  friend bool operator==(const Camera& l, const Camera& r) { return l.model_ == r.model_; }

 private:
  Model model_;
};

}  // namespace evio
