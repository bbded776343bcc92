#pragma once
/// @file mesh_ops.h
/// Small operations on TriangleMesh used by the generators.

#include <functional>

#include "evio/core/eigen_types.h"
#include "evio/core/triangle_mesh.h"

namespace evio::scenes {

/// R = Rz(yaw) · Ry(pitch) · Rx(roll) from [roll, pitch, yaw] in degrees.
Mat3 rotationFromRpyDeg(const Vec3& rpy_deg);

/// Area-weighted vertex normals from the triangles (front side per
/// triangle_mesh.h). Vertices of no triangle get +z.
void computeVertexNormals(TriangleMesh& mesh);

/// p ← R (scale · p) + t; normals ← R n.
void transformMesh(TriangleMesh& mesh, const Mat3& R, const Vec3& t, double scale = 1.0);

/// Appends `src` to `dst` (both must agree on having normals and uvs, or the
/// missing attribute is filled with zeros / computed later).
void appendMesh(TriangleMesh& dst, const TriangleMesh& src);

/// A regular grid of nx × ny vertices at position(i, j) with uv(i, j),
/// i along the first axis. Each cell gives two triangles whose front is the
/// side of ∂p/∂i × ∂p/∂j. `keep_cell(i, j)` (optional) drops cells.
TriangleMesh gridMesh(int nx, int ny, const std::function<Eigen::Vector3f(int, int)>& position,
                      const std::function<Eigen::Vector2f(int, int)>& uv,
                      const std::function<bool(int, int)>& keep_cell = {});

/// Sum of triangle areas (m²).
double surfaceArea(const TriangleMesh& mesh);

}  // namespace evio::scenes
