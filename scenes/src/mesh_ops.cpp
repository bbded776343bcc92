#include "evio/scenes/mesh_ops.h"

#include <cmath>
#include <numbers>

namespace evio::scenes {

Mat3 rotationFromRpyDeg(const Vec3& rpy_deg) {
  const Vec3 r = rpy_deg * (std::numbers::pi / 180.0);
  return (Eigen::AngleAxisd(r.z(), Vec3::UnitZ()) * Eigen::AngleAxisd(r.y(), Vec3::UnitY()) *
          Eigen::AngleAxisd(r.x(), Vec3::UnitX()))
      .toRotationMatrix();
}

void computeVertexNormals(TriangleMesh& mesh) {
  std::vector<Eigen::Vector3d> acc(mesh.positions.size(), Eigen::Vector3d::Zero());
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d a = mesh.positions[static_cast<std::size_t>(t[0])].cast<double>();
    const Eigen::Vector3d b = mesh.positions[static_cast<std::size_t>(t[1])].cast<double>();
    const Eigen::Vector3d c = mesh.positions[static_cast<std::size_t>(t[2])].cast<double>();
    const Eigen::Vector3d n = (b - a).cross(c - a);  // length = 2 × area
    for (int k = 0; k < 3; ++k) acc[static_cast<std::size_t>(t[k])] += n;
  }
  mesh.normals.resize(mesh.positions.size());
  for (std::size_t i = 0; i < acc.size(); ++i) {
    const double len = acc[i].norm();
    mesh.normals[i] = len > 0.0 ? Eigen::Vector3f((acc[i] / len).cast<float>()) : Eigen::Vector3f::UnitZ();
  }
}

void transformMesh(TriangleMesh& mesh, const Mat3& R, const Vec3& t, double scale) {
  const Eigen::Matrix3f Rf = R.cast<float>();
  for (auto& p : mesh.positions) p = (R * (scale * p.cast<double>()) + t).cast<float>();
  for (auto& n : mesh.normals) n = (Rf * n).normalized();
}

void appendMesh(TriangleMesh& dst, const TriangleMesh& src) {
  const int offset = static_cast<int>(dst.positions.size());
  const bool dst_empty = dst.positions.empty();
  const bool normals = dst_empty ? !src.normals.empty() : !dst.normals.empty();
  const bool uvs = dst_empty ? !src.uvs.empty() : !dst.uvs.empty();
  dst.positions.insert(dst.positions.end(), src.positions.begin(), src.positions.end());
  if (normals) {
    if (src.normals.size() == src.positions.size())
      dst.normals.insert(dst.normals.end(), src.normals.begin(), src.normals.end());
    else
      dst.normals.resize(dst.positions.size(), Eigen::Vector3f::UnitZ());
  }
  if (uvs) {
    if (src.uvs.size() == src.positions.size())
      dst.uvs.insert(dst.uvs.end(), src.uvs.begin(), src.uvs.end());
    else
      dst.uvs.resize(dst.positions.size(), Eigen::Vector2f::Zero());
  }
  for (const auto& t : src.triangles) dst.triangles.push_back(t + Eigen::Vector3i::Constant(offset));
}

TriangleMesh gridMesh(int nx, int ny, const std::function<Eigen::Vector3f(int, int)>& position,
                      const std::function<Eigen::Vector2f(int, int)>& uv,
                      const std::function<bool(int, int)>& keep_cell) {
  TriangleMesh mesh;
  mesh.positions.reserve(static_cast<std::size_t>(nx) * static_cast<std::size_t>(ny));
  mesh.uvs.reserve(mesh.positions.capacity());
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      mesh.positions.push_back(position(i, j));
      mesh.uvs.push_back(uv(i, j));
    }
  const auto idx = [nx](int i, int j) { return j * nx + i; };
  mesh.triangles.reserve(2 * static_cast<std::size_t>(nx - 1) * static_cast<std::size_t>(ny - 1));
  for (int j = 0; j + 1 < ny; ++j)
    for (int i = 0; i + 1 < nx; ++i) {
      if (keep_cell && !keep_cell(i, j)) continue;
      mesh.triangles.emplace_back(idx(i, j), idx(i + 1, j), idx(i + 1, j + 1));
      mesh.triangles.emplace_back(idx(i, j), idx(i + 1, j + 1), idx(i, j + 1));
    }
  return mesh;
}

double surfaceArea(const TriangleMesh& mesh) {
  double area = 0.0;
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d a = mesh.positions[static_cast<std::size_t>(t[0])].cast<double>();
    const Eigen::Vector3d b = mesh.positions[static_cast<std::size_t>(t[1])].cast<double>();
    const Eigen::Vector3d c = mesh.positions[static_cast<std::size_t>(t[2])].cast<double>();
    area += 0.5 * (b - a).cross(c - a).norm();
  }
  return area;
}

}  // namespace evio::scenes
