#pragma once
/// @file primitives.h
/// Planes and boxes (source_options.h for placement and uv conventions).

#include "evio/core/triangle_mesh.h"
#include "evio/scenes/source_options.h"

namespace evio::scenes {

/// A rectangle in the local x-y plane, front +z_local, placed in W.
TriangleMesh planeMesh(const PlaneParams& params);

/// A box with outward faces (flat normals), placed in W. Face uv: metres on
/// each face, v downwards for the side faces (image top at the top edge).
TriangleMesh boxMesh(const BoxParams& params);

}  // namespace evio::scenes
