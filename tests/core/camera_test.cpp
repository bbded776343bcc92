#include "evio/core/camera/camera.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "evio/core/error.h"
#include "evio/core/random_stream.h"
#include "numeric_jacobian.h"

namespace evio {
namespace {

// ---------------------------------------------------------------------------
// Realistic parameter sets per model. Every set is valid over the whole image
// (each pixel unprojects), which the round-trip test asserts.

template <class T>
std::vector<T> testCameras();

template <>
std::vector<PinholeCamera> testCameras<PinholeCamera>() {
  using P = PinholeCamera::Params;
  return {
      // DAVIS240C of the Event-Camera Dataset (shapes_*), distortion dropped.
      PinholeCamera(240, 180, P(199.092366542, 198.82882047, 132.192071378, 110.712660011)),
      PinholeCamera(346, 260, P(320.0, 320.0, 172.5, 129.5)),
      PinholeCamera(1280, 720, P(912.4, 910.8, 651.3, 355.9)),
  };
}

template <>
std::vector<RadTanCamera> testCameras<RadTanCamera>() {
  using P = RadTanCamera::Params;
  P davis240c, davis346, hd, ideal;
  // calib.txt of the Event-Camera Dataset's DAVIS240C sequences (strong barrel).
  davis240c << 199.092366542, 198.82882047, 132.192071378, 110.712660011, -0.368436311798,
      0.150947243557, -0.000296130534385, -0.000759431726241, 0.0;
  davis346 << 322.1, 321.7, 170.4, 128.9, -0.08, 0.05, 2e-4, -3e-4, -0.01;
  hd << 900.0, 900.0, 640.0, 360.0, 0.1, -0.25, 1e-3, 2e-3, 0.1;
  ideal << 400.0, 400.0, 319.5, 239.5, 0.0, 0.0, 0.0, 0.0, 0.0;
  return {RadTanCamera(240, 180, davis240c), RadTanCamera(346, 260, davis346),
          RadTanCamera(1280, 720, hd), RadTanCamera(640, 480, ideal)};
}

template <>
std::vector<EquidistantCamera> testCameras<EquidistantCamera>() {
  using P = EquidistantCamera::Params;
  P davis346, wide, ideal;
  davis346 << 260.0, 260.5, 173.0, 130.0, -0.03, 0.01, -0.005, 0.001;
  // TUM-VI fisheye distortion with a longer focal length, so that the image
  // corners stay inside the 180° field of view (θ ≈ 1.2 rad at the corners).
  wide << 300.0, 299.8, 254.9, 256.9, 0.0034823894022493434, 0.0007150348452162257,
      -0.0020532361418706202, 0.00020293673591811182;
  ideal << 400.0, 400.0, 320.0, 240.0, 0.0, 0.0, 0.0, 0.0;
  return {EquidistantCamera(346, 260, davis346), EquidistantCamera(512, 512, wide),
          EquidistantCamera(640, 480, ideal)};
}

/// Random points in front of camera `cam` that project into its image
/// (unprojected random pixels times random distances), plus the point on the
/// optical axis through the principal point (r = 0).
template <class T>
std::vector<Vec3> pointsInView(const T& cam, int n, const char* stream) {
  RandomStream rng(11, stream);
  std::vector<Vec3> points;
  Vec3 axis;
  if (cam.unproject(Vec2(cam.params()[2], cam.params()[3]), &axis)) points.push_back(2.0 * axis);
  while (static_cast<int>(points.size()) < n) {
    const Vec2 uv(rng.uniform(0.0, cam.width() - 1.0), rng.uniform(0.0, cam.height() - 1.0));
    Vec3 bearing;
    if (!cam.unproject(uv, &bearing)) continue;  // counted by the round-trip test
    points.push_back(bearing * rng.uniform(0.5, 20.0));
  }
  return points;
}

/// max |a - b| <= tol · max(1, max |b|).
template <class A, class B>
::testing::AssertionResult closeRelative(const A& a, const B& b, double tol) {
  const double scale = std::max(1.0, b.cwiseAbs().maxCoeff());
  const double err = (a - b).cwiseAbs().maxCoeff();
  if (err <= tol * scale) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "max error " << err << " > " << tol << " · " << scale
                                       << "\nanalytic:\n" << a << "\nnumeric:\n" << b;
}

template <class T>
class CameraModelTest : public ::testing::Test {};

using CameraModels = ::testing::Types<PinholeCamera, RadTanCamera, EquidistantCamera>;
TYPED_TEST_SUITE(CameraModelTest, CameraModels);

// Every pixel centre on a 4-px grid, plus the last row and column and the
// outer edges of the image (-0.5 and size - 0.5), unprojects to a unit bearing
// that projects back to the same pixel within 1e-9 px.
TYPED_TEST(CameraModelTest, UnprojectProjectRoundTripOverWholeImage) {
  for (const auto& cam : testCameras<TypeParam>()) {
    std::vector<double> us{-0.5, cam.width() - 1.0, cam.width() - 0.5};
    std::vector<double> vs{-0.5, cam.height() - 1.0, cam.height() - 0.5};
    for (int u = 0; u < cam.width(); u += 4) us.push_back(u);
    for (int v = 0; v < cam.height(); v += 4) vs.push_back(v);
    double max_err = 0.0;
    for (double u : us) {
      for (double v : vs) {
        const Vec2 uv(u, v);
        Vec3 bearing;
        ASSERT_TRUE(cam.unproject(uv, &bearing)) << "pixel " << uv.transpose();
        EXPECT_NEAR(bearing.norm(), 1.0, 1e-15);
        Vec2 back;
        ASSERT_TRUE(cam.project(bearing, &back)) << "pixel " << uv.transpose();
        max_err = std::max(max_err, (back - uv).norm());
      }
    }
    EXPECT_LT(max_err, 1e-9) << "params " << cam.params().transpose();
  }
}

// project then unproject returns the direction of the point (1e-11 rad).
TYPED_TEST(CameraModelTest, ProjectUnprojectRecoversBearing) {
  for (const auto& cam : testCameras<TypeParam>()) {
    for (const Vec3& p : pointsInView(cam, 200, "bearing")) {
      Vec2 uv;
      ASSERT_TRUE(cam.project(p, &uv));
      Vec3 bearing;
      ASSERT_TRUE(cam.unproject(uv, &bearing));
      EXPECT_LT((bearing - p.normalized()).norm(), 1e-11) << p.transpose();
    }
  }
}

// ∂uv/∂p_C against central differences with step 1e-6 · |p|; the truncation
// and round-off errors are far below the tolerance 1e-6 · max(1, max|J|).
TYPED_TEST(CameraModelTest, JacobianWrtPointMatchesNumeric) {
  for (const auto& cam : testCameras<TypeParam>()) {
    for (const Vec3& p : pointsInView(cam, 100, "jacobian_point")) {
      Vec2 uv;
      Mat23 J;
      ASSERT_TRUE(cam.project(p, &uv, &J));
      auto f = [&](const Vec3& q) -> Vec2 {
        Vec2 out;
        EXPECT_TRUE(cam.project(q, &out));
        return out;
      };
      const Mat23 numeric = test::numericJacobian<2, 3>(f, p, 1e-6 * p.norm());
      EXPECT_TRUE(closeRelative(J, numeric, 1e-6)) << "p " << p.transpose();
    }
  }
}

// ∂uv/∂params against central differences with step 1e-4 on every parameter
// (focal lengths, principal point and distortion). uv is linear in each single
// parameter for all three models, so central differences have no truncation
// error and the round-off is ~1e-9; tolerance 1e-7 · max(1, max|J|).
TYPED_TEST(CameraModelTest, JacobianWrtParamsMatchesNumeric) {
  using Params = typename TypeParam::Params;
  constexpr int N = TypeParam::kNumParams;
  for (const auto& cam : testCameras<TypeParam>()) {
    for (const Vec3& p : pointsInView(cam, 50, "jacobian_params")) {
      Vec2 uv;
      typename TypeParam::ParamsJacobian J;
      ASSERT_TRUE(cam.project(p, &uv, nullptr, &J));
      auto f = [&](const Params& params) -> Vec2 {
        Vec2 out;
        EXPECT_TRUE(TypeParam(cam.width(), cam.height(), params).project(p, &out));
        return out;
      };
      const Eigen::Matrix<double, 2, N> numeric = test::numericJacobian<2, N>(f, cam.params(), 1e-4);
      EXPECT_TRUE(closeRelative(J, numeric, 1e-7)) << "p " << p.transpose();
    }
  }
}

TYPED_TEST(CameraModelTest, PointsBehindOrOnImagePlaneAreRejected) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  for (const auto& cam : testCameras<TypeParam>()) {
    for (const Vec3& p : {Vec3(0, 0, -1), Vec3(0.1, -0.2, -3), Vec3(1, 1, 0), Vec3(0, 0, 0),
                          Vec3(1, 0, 1e-7), Vec3(nan, 0, 1), Vec3(0, 0, inf), Vec3(0, 0, nan)}) {
      Vec2 uv;
      Mat23 J;
      typename TypeParam::ParamsJacobian Jp;
      EXPECT_FALSE(cam.project(p, &uv, &J, &Jp)) << p.transpose();
    }
    Vec3 bearing;
    EXPECT_FALSE(cam.unproject(Vec2(nan, 3.0), &bearing));
    EXPECT_FALSE(cam.unproject(Vec2(0.0, inf), &bearing));
    // The optical axis is fine.
    Vec2 uv;
    EXPECT_TRUE(cam.project(Vec3(0, 0, 1), &uv));
  }
}

TYPED_TEST(CameraModelTest, VariantWrapperAgreesWithConcreteModel) {
  for (const auto& cam : testCameras<TypeParam>()) {
    const Camera wrapped(cam);
    EXPECT_EQ(wrapped.model(), TypeParam::kModelName);
    EXPECT_EQ(wrapped.width(), cam.width());
    EXPECT_EQ(wrapped.height(), cam.height());
    EXPECT_EQ(wrapped.params(), VecX(cam.params()));
    EXPECT_EQ(wrapped.intrinsics(), Vec4(cam.params().template head<4>()));
    ASSERT_NE(wrapped.template as<TypeParam>(), nullptr);
    EXPECT_EQ(std::get<TypeParam>(wrapped.variant()), cam);

    // The factory rebuilds the same camera from its description.
    const Camera rebuilt = Camera::create(wrapped.model(), wrapped.width(), wrapped.height(),
                                          wrapped.intrinsics(), wrapped.distortion());
    EXPECT_EQ(rebuilt, wrapped);

    for (const Vec3& p : pointsInView(cam, 30, "variant")) {
      Vec2 uv_a, uv_b;
      Mat23 J_a, J_b;
      ASSERT_TRUE(cam.project(p, &uv_a, &J_a));
      ASSERT_TRUE(wrapped.project(p, &uv_b, &J_b));
      EXPECT_EQ(uv_a, uv_b);
      EXPECT_EQ(J_a, J_b);
      Vec3 b_a, b_b;
      ASSERT_TRUE(cam.unproject(uv_a, &b_a));
      ASSERT_TRUE(wrapped.unproject(uv_a, &b_b));
      EXPECT_EQ(b_a, b_b);
    }
    Vec2 uv;
    EXPECT_FALSE(wrapped.project(Vec3(0, 0, -1), &uv));
  }
}

// --- model-specific checks ---------------------------------------------------

// RadTan against a hand-computed example (OpenCV's formula, worked out in
// exact rational arithmetic): fx=200 fy=190 cx=120 cy=90, k1=-0.3 k2=0.1
// p1=0.001 p2=-0.002 k3=0.01, point (0.2, -0.1, 1):
//   r² = 0.05, R = 1 - 0.015 + 0.00025 + 0.00000125 = 0.98525125
//   a_d = 0.2 R + 2 p1 (0.2)(-0.1) + p2 (0.05 + 0.08)   = 0.19675025
//   b_d = -0.1 R + p1 (0.05 + 0.02) + 2 p2 (0.2)(-0.1)  = -0.098375125
//   u = 200 a_d + 120 = 159.35005,  v = 190 b_d + 90 = 71.30872625.
TEST(RadTanCamera, MatchesHandComputedExample) {
  RadTanCamera::Params p;
  p << 200, 190, 120, 90, -0.3, 0.1, 0.001, -0.002, 0.01;
  const RadTanCamera cam(240, 180, p);
  Vec2 uv;
  ASSERT_TRUE(cam.project(Vec3(0.2, -0.1, 1.0), &uv));
  EXPECT_NEAR(uv.x(), 159.35005, 1e-12);
  EXPECT_NEAR(uv.y(), 71.30872625, 1e-12);
  // Scaling the point does not move its pixel.
  Vec2 uv2;
  ASSERT_TRUE(cam.project(Vec3(0.2, -0.1, 1.0) * 7.5, &uv2));
  EXPECT_NEAR((uv2 - uv).norm(), 0.0, 1e-12);
}

// Equidistant: point (1, 0, 1) has r = 1 and θ = π/4, so
// u = fx θ (1 + k1 θ² + k2 θ⁴) + cx; with fx = 300, cx = 320, k1 = 0.1,
// k2 = 0.01 that is 571.0501832583944 (evaluated in double precision).
TEST(EquidistantCamera, MatchesHandComputedExample) {
  EquidistantCamera::Params p;
  p << 300, 310, 320, 240, 0.1, 0.01, 0.0, 0.0;
  const EquidistantCamera cam(640, 480, p);
  Vec2 uv;
  ASSERT_TRUE(cam.project(Vec3(1.0, 0.0, 1.0), &uv));
  EXPECT_NEAR(uv.x(), 571.0501832583944, 1e-9);
  EXPECT_NEAR(uv.y(), 240.0, 1e-12);
}

// k1 = -0.37 alone: d(r R)/dr = 1 - 1.11 r² vanishes at r² = 1/1.11. Beyond it
// the model folds over, so projection and unprojection must refuse.
TEST(RadTanCamera, RejectsPointsWhereDistortionFoldsOver) {
  RadTanCamera::Params p;
  p << 200, 200, 120, 90, -0.37, 0.0, 0.0, 0.0, 0.0;
  const RadTanCamera cam(240, 180, p);
  EXPECT_NEAR(cam.maxRadiusSquared(), 1.0 / 1.11, 1e-15);
  Vec2 uv;
  EXPECT_TRUE(cam.project(Vec3(0.89, 0.0, 1.0), &uv));   // r² = 0.79
  EXPECT_FALSE(cam.project(Vec3(0.0, 0.96, 1.0), &uv));  // r² = 0.92
  // Largest distorted radius: r (1 - 0.37 r²) at r² = 1/1.11, ≈ 0.6325.
  Vec3 bearing;
  EXPECT_TRUE(cam.unproject(Vec2(120 + 200 * 0.6, 90), &bearing));
  EXPECT_FALSE(cam.unproject(Vec2(120 + 200 * 0.65, 90), &bearing));
}

// A quadratic bound: 1 - 1.2 s + 0.1 s² = 0 at s = (1.2 - √1.04) / 0.2.
TEST(RadTanCamera, ValidRadiusMatchesClosedForm) {
  RadTanCamera::Params p;
  p << 200, 200, 120, 90, -0.4, 0.02, 0.0, 0.0, 0.0;
  EXPECT_NEAR(RadTanCamera(240, 180, p).maxRadiusSquared(), (1.2 - std::sqrt(1.04)) / 0.2, 1e-14);
  p << 200, 200, 120, 90, 0.1, 0.01, 0.0, 0.0, 0.0;  // increasing everywhere
  EXPECT_EQ(RadTanCamera(240, 180, p).maxRadiusSquared(), RadTanCamera::kMaxRadiusSquared);
}

// k1 = -0.5: dθ_d/dθ = 1 - 1.5 θ² vanishes at θ = √(2/3) ≈ 0.8165 rad.
TEST(EquidistantCamera, RejectsAnglesWhereDistortionFoldsOver) {
  EquidistantCamera::Params p;
  p << 300, 300, 320, 240, -0.5, 0.0, 0.0, 0.0;
  const EquidistantCamera cam(640, 480, p);
  EXPECT_NEAR(cam.maxTheta(), std::sqrt(2.0 / 3.0), 1e-15);
  Vec2 uv;
  EXPECT_TRUE(cam.project(Vec3(std::tan(0.8), 0.0, 1.0), &uv));
  EXPECT_FALSE(cam.project(Vec3(0.0, std::tan(0.83), 1.0), &uv));
}

// TUM-VI's own fisheye (f ≈ 191 px on 512 × 512): the image corners lie beyond
// θ = 90° and cannot be unprojected to a point in front of the camera.
TEST(EquidistantCamera, CornersBeyondNinetyDegreesAreRejected) {
  EquidistantCamera::Params p;
  p << 190.97847715128717, 190.9733070521226, 254.93170605935475, 256.8974428996504,
      0.0034823894022493434, 0.0007150348452162257, -0.0020532361418706202,
      0.00020293673591811182;
  const EquidistantCamera cam(512, 512, p);
  EXPECT_DOUBLE_EQ(cam.maxTheta(), std::numbers::pi / 2);
  Vec3 bearing;
  EXPECT_FALSE(cam.unproject(Vec2(0, 0), &bearing));
  EXPECT_FALSE(cam.unproject(Vec2(511, 511), &bearing));
  ASSERT_TRUE(cam.unproject(Vec2(256, 30), &bearing));  // θ ≈ 1.19 rad, still in front
  EXPECT_GT(bearing.z(), 0.0);
}

TEST(Camera, IsInsideUsesPixelCentreConvention) {
  const Camera cam = PinholeCamera(240, 180, PinholeCamera::Params(200, 200, 120, 90));
  EXPECT_TRUE(cam.isInside(Vec2(0, 0)));
  EXPECT_TRUE(cam.isInside(Vec2(-0.5, -0.5)));
  EXPECT_TRUE(cam.isInside(Vec2(239.49, 179.49)));
  EXPECT_FALSE(cam.isInside(Vec2(239.5, 100)));
  EXPECT_FALSE(cam.isInside(Vec2(100, 179.5)));
  EXPECT_FALSE(cam.isInside(Vec2(-0.51, 100)));
  EXPECT_TRUE(cam.isInside(Vec2(4.5, 4.5), 5.0));
  EXPECT_FALSE(cam.isInside(Vec2(4.49, 100), 5.0));
  EXPECT_FALSE(cam.isInside(Vec2(234.5, 100), 5.0));
  EXPECT_FALSE(cam.isInside(Vec2(std::numeric_limits<double>::quiet_NaN(), 1.0)));
}

/// Runs `f`, expects an evio::Error whose message contains `field`.
template <class F>
void expectErrorNaming(F&& f, const std::string& field) {
  try {
    f();
    ADD_FAILURE() << "expected an evio::Error naming " << field;
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
  }
}

TEST(Camera, FactoryValidatesAndNamesTheField) {
  const Vec4 k(200, 200, 120, 90);
  VecX radtan(5);
  radtan << -0.3, 0.1, 0.0, 0.0, 0.0;
  EXPECT_EQ(Camera::create("radtan", 240, 180, k, radtan).model(), "radtan");
  EXPECT_EQ(Camera::create("pinhole", 240, 180, k, VecX()).model(), "pinhole");
  EXPECT_EQ(Camera::create("equidistant", 240, 180, k, VecX::Zero(4)).model(), "equidistant");

  expectErrorNaming([&] { Camera::create("fisheye", 240, 180, k, VecX()); }, "model");
  expectErrorNaming([&] { Camera::create("radtan", 240, 180, k, VecX::Zero(4)); }, "distortion");
  expectErrorNaming([&] { Camera::create("pinhole", 240, 180, k, VecX::Zero(5)); }, "distortion");
  expectErrorNaming([&] { Camera::create("equidistant", 240, 180, k, radtan); }, "distortion");
  expectErrorNaming([&] { Camera::create("pinhole", 0, 180, k, VecX()); }, "resolution.width");
  expectErrorNaming([&] { Camera::create("pinhole", 240, -1, k, VecX()); }, "resolution.height");
  expectErrorNaming([&] { Camera::create("pinhole", 240, 180, Vec4(0, 200, 120, 90), VecX()); },
                    "intrinsics.fx");
  expectErrorNaming([&] { Camera::create("pinhole", 240, 180, Vec4(200, -5, 120, 90), VecX()); },
                    "intrinsics.fy");
  const double nan = std::numeric_limits<double>::quiet_NaN();
  expectErrorNaming([&] { Camera::create("pinhole", 240, 180, Vec4(200, 200, nan, 90), VecX()); },
                    "intrinsics.cx");
  VecX bad = radtan;
  bad[2] = nan;
  expectErrorNaming([&] { Camera::create("radtan", 240, 180, k, bad); }, "distortion[2] (p1)");
}

}  // namespace
}  // namespace evio
