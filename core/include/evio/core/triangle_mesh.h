#pragma once
/// @file triangle_mesh.h
/// An indexed triangle mesh: the one geometry type shared by mesh import
/// (core/io/mesh_file.h), the procedural generators and the Embree scene
/// (scenes/). Single precision, as the ray tracer uses.
///
/// Orientation: triangle (a, b, c) faces the side of
///   n = (p_b - p_a) × (p_c - p_a)
/// (counter-clockwise seen from the front). For solid objects the front is
/// the outside (the side a camera may be on).

#include <Eigen/Core>
#include <vector>

namespace evio {

struct TriangleMesh {
  std::vector<Eigen::Vector3f> positions;  ///< vertex positions (m)
  std::vector<Eigen::Vector3f> normals;    ///< unit vertex normals, empty or one per vertex
  std::vector<Eigen::Vector2f> uvs;        ///< texture coordinates, empty or one per vertex
  std::vector<Eigen::Vector3i> triangles;  ///< vertex indices, counter-clockwise from the front

  bool empty() const { return triangles.empty(); }
};

}  // namespace evio
