#include "evio/scenes/primitives.h"

#include <algorithm>
#include <cmath>

#include "evio/scenes/mesh_ops.h"

namespace evio::scenes {

namespace {

int cells(double length, double cell) {
  return cell > 0.0 ? std::max(1, static_cast<int>(std::ceil(length / cell - 1e-9))) : 1;
}

/// A rectangle of size (w, h) centred at the origin of the frame (origin,
/// ex, ey), front along ex × ey, uv = (x + w/2, h/2 − y).
TriangleMesh rectangle(const Vec3& origin, const Vec3& ex, const Vec3& ey, double w, double h,
                       double cell) {
  const int nx = cells(w, cell), ny = cells(h, cell);
  const auto local = [=](int i, int j) {
    return Vec2(-0.5 * w + w * i / nx, -0.5 * h + h * j / ny);
  };
  TriangleMesh m = gridMesh(
      nx + 1, ny + 1,
      [&](int i, int j) {
        const Vec2 q = local(i, j);
        return Eigen::Vector3f((origin + q.x() * ex + q.y() * ey).cast<float>());
      },
      [&](int i, int j) {
        const Vec2 q = local(i, j);
        return Eigen::Vector2f(static_cast<float>(q.x() + 0.5 * w), static_cast<float>(0.5 * h - q.y()));
      });
  const Eigen::Vector3f n = ex.cross(ey).normalized().cast<float>();
  m.normals.assign(m.positions.size(), n);
  return m;
}

}  // namespace

TriangleMesh planeMesh(const PlaneParams& params) {
  TriangleMesh m = rectangle(Vec3::Zero(), Vec3::UnitX(), Vec3::UnitY(), params.size_m.x(),
                             params.size_m.y(), params.cell_m);
  transformMesh(m, rotationFromRpyDeg(params.rotation_deg), params.position_m);
  return m;
}

TriangleMesh boxMesh(const BoxParams& params) {
  const Vec3 h = 0.5 * params.size_m;
  const double c = params.cell_m;
  TriangleMesh box;
  // Each face: centre, in-face axes (ex, ey) with ex × ey outward, extents.
  const Vec3 X = Vec3::UnitX(), Y = Vec3::UnitY(), Z = Vec3::UnitZ();
  appendMesh(box, rectangle(Vec3(0, 0, h.z()), X, Y, params.size_m.x(), params.size_m.y(), c));   // top
  appendMesh(box, rectangle(Vec3(0, 0, -h.z()), -X, Y, params.size_m.x(), params.size_m.y(), c)); // bottom
  appendMesh(box, rectangle(Vec3(h.x(), 0, 0), Y, Z, params.size_m.y(), params.size_m.z(), c));   // +x
  appendMesh(box, rectangle(Vec3(-h.x(), 0, 0), -Y, Z, params.size_m.y(), params.size_m.z(), c)); // -x
  appendMesh(box, rectangle(Vec3(0, h.y(), 0), -X, Z, params.size_m.x(), params.size_m.z(), c));  // +y
  appendMesh(box, rectangle(Vec3(0, -h.y(), 0), X, Z, params.size_m.x(), params.size_m.z(), c));  // -y
  transformMesh(box, rotationFromRpyDeg(params.rotation_deg), params.position_m);
  return box;
}

}  // namespace evio::scenes
