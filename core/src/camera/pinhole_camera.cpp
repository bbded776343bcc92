#include "evio/core/camera/pinhole_camera.h"

#include "validate_intrinsics.h"

namespace evio {

PinholeCamera::PinholeCamera(int width, int height, const Params& params)
    : width_(width), height_(height), params_(params) {
  detail::validateCameraParams(width, height, params, {});
}

bool PinholeCamera::project(const Vec3& p_C, Vec2* uv, Mat23* d_uv_d_p,
                            ParamsJacobian* d_uv_d_params) const {
  if (!isInFrontOfCamera(p_C)) return false;
  const double a = p_C.x() / p_C.z();
  const double b = p_C.y() / p_C.z();
  *uv = Vec2(fx() * a + cx(), fy() * b + cy());
  if (d_uv_d_p) {
    const Mat23 d_n_d_p = dNormalizedDPoint(p_C);
    d_uv_d_p->row(0) = fx() * d_n_d_p.row(0);
    d_uv_d_p->row(1) = fy() * d_n_d_p.row(1);
  }
  if (d_uv_d_params) {
    *d_uv_d_params << a, 0.0, 1.0, 0.0,  //
        0.0, b, 0.0, 1.0;
  }
  return true;
}

bool PinholeCamera::unproject(const Vec2& uv, Vec3* bearing_C) const {
  if (!uv.allFinite()) return false;
  *bearing_C = Vec3((uv.x() - cx()) / fx(), (uv.y() - cy()) / fy(), 1.0).normalized();
  return true;
}

}  // namespace evio
