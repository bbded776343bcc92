#pragma once
/// @file isosurface.h
/// Surface extraction from an implicit solid by naive surface nets
/// (S. Gibson, "Constrained elastic surface nets", MICCAI 1998; the
/// "naive" variant without relaxation): F > 0 is solid, F <= 0 is free.
///
/// F is sampled on the grid points x_ijk = origin + cell · (i, j, k). Every
/// grid cell whose 8 corners do not all have the same sign gets one vertex,
/// the mean of the zero crossings (linear interpolation) on its 12 edges.
/// Every grid edge with a sign change gives a quad joining the vertices of
/// the 4 cells around it, oriented so that its front faces the free side.
/// The mesh is closed except where the solid meets the grid boundary.

#include <functional>

#include "evio/core/eigen_types.h"
#include "evio/core/triangle_mesh.h"

namespace evio::scenes {

struct IsoGrid {
  Vec3 origin = Vec3::Zero();   ///< grid point (0, 0, 0) in W (m)
  double cell_m = 0.25;         ///< grid step (m)
  int nx = 2, ny = 2, nz = 2;   ///< grid points per axis (>= 2)
};

/// Triangle mesh of the boundary of {F > 0}; vertex normals from the mesh,
/// uv = world (x, y). F is evaluated once per grid point, in parallel (F
/// must be a pure function; the result does not depend on thread count).
TriangleMesh extractIsosurface(const IsoGrid& grid, const std::function<double(const Vec3&)>& F);

}  // namespace evio::scenes
