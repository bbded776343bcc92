#include "evio/estimator/backend/visual_models.h"

#include "evio/core/camera/camera_common.h"
#include "evio/core/so3.h"

namespace evio::estimator {
namespace {

bool inFront(const Vec3& h) { return h.allFinite() && h.z() > kMinDepthRatio * h.norm(); }

}  // namespace

Pose cameraPose(const ImuState& imu, const Pose& T_B_C, Eigen::Matrix<double, 6, 15>* d_cam_d_imu) {
  if (d_cam_d_imu != nullptr) {
    d_cam_d_imu->setZero();
    d_cam_d_imu->block<3, 3>(kCloneP, kIdxP).setIdentity();
    d_cam_d_imu->block<3, 3>(kCloneP, kIdxTheta) = -imu.q_W_B.toRotationMatrix() * so3::hat(T_B_C.translation());
    d_cam_d_imu->block<3, 3>(kCloneTheta, kIdxTheta) = T_B_C.rotation().transpose();
  }
  return imu.T_W_B() * T_B_C;
}

bool projectWorldPoint(const CameraClone& clone, const Vec3& p_W, Vec2* z, Mat26* d_z_d_clone,
                       Mat23* d_z_d_p_W) {
  const Mat3 Rt = clone.R_W_C().transpose();
  const Vec3 h = Rt * (p_W - clone.p_W_C);
  if (!inFront(h)) return false;
  *z = h.head<2>() / h.z();
  if (d_z_d_clone != nullptr || d_z_d_p_W != nullptr) {
    const Mat23 d_z_d_h = dNormalizedDPoint(h);
    // ∂h/∂δp = −R_iᵀ;  ∂h/∂δθ = [h]x  (R_iᵀ = Exp(−δθ) R̂ᵀ);  ∂h/∂p_W = R_iᵀ.
    if (d_z_d_clone != nullptr) {
      d_z_d_clone->leftCols<3>() = -d_z_d_h * Rt;
      d_z_d_clone->rightCols<3>() = d_z_d_h * so3::hat(h);
    }
    if (d_z_d_p_W != nullptr) *d_z_d_p_W = d_z_d_h * Rt;
  }
  return true;
}

bool projectAnchoredFeature(const CameraClone& anchor, const CameraClone& clone, const Vec3& abr, Vec2* z,
                            Mat26* d_z_d_anchor, Mat26* d_z_d_clone, Mat23* d_z_d_abr) {
  const Mat3 Ra = anchor.R_W_C();
  const Mat3 Rit = clone.R_W_C().transpose();
  const Vec3 b(abr.x(), abr.y(), 1.0);
  const double rho = abr.z();
  const Vec3 dp = anchor.p_W_C - clone.p_W_C;
  const Vec3 h = Rit * (Ra * b + rho * dp);
  if (!inFront(h)) return false;
  *z = h.head<2>() / h.z();
  if (d_z_d_anchor == nullptr && d_z_d_clone == nullptr && d_z_d_abr == nullptr) return true;
  const Mat23 d_z_d_h = dNormalizedDPoint(h);
  if (d_z_d_clone != nullptr) {
    // ∂h/∂δp_i = −ρ R_iᵀ;  ∂h/∂δθ_i = [h]x.
    d_z_d_clone->leftCols<3>() = -rho * d_z_d_h * Rit;
    d_z_d_clone->rightCols<3>() = d_z_d_h * so3::hat(h);
  }
  if (d_z_d_anchor != nullptr) {
    // ∂h/∂δp_a = ρ R_iᵀ;  ∂h/∂δθ_a = −R_iᵀ R_a [b]x  (R_a b ≈ R̂_a (b + δθ × b)).
    d_z_d_anchor->leftCols<3>() = rho * d_z_d_h * Rit;
    d_z_d_anchor->rightCols<3>() = -d_z_d_h * Rit * Ra * so3::hat(b);
  }
  if (d_z_d_abr != nullptr) {
    // ∂h/∂α = R_iᵀ R_a e1, ∂h/∂β = R_iᵀ R_a e2, ∂h/∂ρ = R_iᵀ (p_a − p_i).
    Mat3 d_h_d_abr;
    d_h_d_abr.leftCols<2>() = Rit * Ra.leftCols<2>();
    d_h_d_abr.col(2) = Rit * dp;
    *d_z_d_abr = d_z_d_h * d_h_d_abr;
  }
  return true;
}

Vec3 anchoredToWorld(const CameraClone& anchor, const Vec3& abr, Mat36* d_p_d_anchor, Mat3* d_p_d_abr) {
  const Mat3 Ra = anchor.R_W_C();
  const Vec3 b(abr.x(), abr.y(), 1.0);
  const double inv_rho = 1.0 / abr.z();
  const Vec3 p_W = Ra * b * inv_rho + anchor.p_W_C;
  if (d_p_d_anchor != nullptr) {
    d_p_d_anchor->leftCols<3>().setIdentity();
    d_p_d_anchor->rightCols<3>() = -Ra * so3::hat(b) * inv_rho;
  }
  if (d_p_d_abr != nullptr) {
    d_p_d_abr->leftCols<2>() = Ra.leftCols<2>() * inv_rho;
    d_p_d_abr->col(2) = -Ra * b * inv_rho * inv_rho;
  }
  return p_W;
}

bool worldToAnchored(const CameraClone& anchor, const Vec3& p_W, Vec3* abr) {
  const Vec3 p_C = anchor.R_W_C().transpose() * (p_W - anchor.p_W_C);
  if (!inFront(p_C)) return false;
  *abr = Vec3(p_C.x() / p_C.z(), p_C.y() / p_C.z(), 1.0 / p_C.z());
  return true;
}

bool reanchorFeature(const CameraClone& from, const CameraClone& to, const Vec3& abr, Vec3* abr_new,
                     Mat36* d_new_d_from, Mat36* d_new_d_to, Mat3* d_new_d_abr) {
  const Mat3 Ra = from.R_W_C();
  const Mat3 Rnt = to.R_W_C().transpose();
  const Vec3 b(abr.x(), abr.y(), 1.0);
  const double rho = abr.z();
  const Vec3 dp = from.p_W_C - to.p_W_C;
  const Vec3 h = Rnt * (Ra * b + rho * dp);
  if (!inFront(h)) return false;
  const double iz = 1.0 / h.z();
  *abr_new = Vec3(h.x() * iz, h.y() * iz, rho * iz);
  if (d_new_d_from == nullptr && d_new_d_to == nullptr && d_new_d_abr == nullptr) return true;
  // abr' = g(h, ρ):  ∂g/∂h = [iz 0 −h_x iz²; 0 iz −h_y iz²; 0 0 −ρ iz²],  ∂g/∂ρ|direct = (0, 0, iz).
  Mat3 d_g_d_h;
  d_g_d_h << iz, 0.0, -h.x() * iz * iz,  //
      0.0, iz, -h.y() * iz * iz,         //
      0.0, 0.0, -rho * iz * iz;
  if (d_new_d_from != nullptr) {
    d_new_d_from->leftCols<3>() = rho * d_g_d_h * Rnt;
    d_new_d_from->rightCols<3>() = -d_g_d_h * Rnt * Ra * so3::hat(b);
  }
  if (d_new_d_to != nullptr) {
    d_new_d_to->leftCols<3>() = -rho * d_g_d_h * Rnt;
    d_new_d_to->rightCols<3>() = d_g_d_h * so3::hat(h);
  }
  if (d_new_d_abr != nullptr) {
    Mat3 d_h_d_abr;
    d_h_d_abr.leftCols<2>() = Rnt * Ra.leftCols<2>();
    d_h_d_abr.col(2) = Rnt * dp;
    *d_new_d_abr = d_g_d_h * d_h_d_abr;
    d_new_d_abr->col(2) += Vec3(0.0, 0.0, iz);
  }
  return true;
}

}  // namespace evio::estimator
