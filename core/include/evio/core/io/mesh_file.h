#pragma once
/// @file mesh_file.h
/// Triangle meshes from Wavefront OBJ and Stanford PLY files (own small
/// parsers; no third-party mesh library).
///
/// OBJ: `v x y z`, `vt u v`, `vn x y z` and `f` with any of the corner forms
/// `i`, `i/t`, `i//n`, `i/t/n` (1-based; negative indices count back from the
/// last element read). Polygons are fan-triangulated. Corners that combine
/// different texture or normal indices become separate vertices. Other
/// statements (o, g, s, usemtl, mtllib, l, ...) are ignored.
///
/// PLY: `ascii`, `binary_little_endian` and `binary_big_endian`, version 1.0.
/// The `vertex` element supplies x y z and optionally nx ny nz and u v (also
/// named s t or texture_u texture_v); the `face` element a list property
/// `vertex_indices` (or `vertex_index`). Other elements and properties are
/// skipped.
///
/// Errors (evio::Error) name the file and line (OBJ, PLY header) or the
/// element index (PLY body): unreadable file, malformed number, index out of
/// range, truncated body, no triangles.

#include <string>

#include "evio/core/triangle_mesh.h"

namespace evio::io {

/// Reads an OBJ or PLY file, chosen by extension (case-insensitive).
TriangleMesh readMesh(const std::string& path);

TriangleMesh readObj(const std::string& path);
TriangleMesh readPly(const std::string& path);

/// Writes `v`/`vt`/`vn`/`f` lines (17 significant digits are not needed:
/// floats are printed with 9, which round-trips single precision). Atomic.
void writeObj(const std::string& path, const TriangleMesh& mesh);

/// Writes a binary little-endian PLY (float x y z [nx ny nz] [u v]; face list
/// uchar/int). Atomic.
void writePly(const std::string& path, const TriangleMesh& mesh);

}  // namespace evio::io
