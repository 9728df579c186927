#pragma once

#include <cstdint>
#include <string>

#include <Eigen/Core>

namespace devsurf::reference {

/// What a reference file may hold (issue 15: a user's scan or mesh). A file over a limit is
/// refused before it is parsed in full, with a message naming the limit.
struct ReferenceLimits {
  std::uint64_t maxFileBytes = 512ull << 20;  ///< bytes on disk (default 512 MiB)
  std::int64_t maxPoints = 5'000'000;         ///< points of a cloud or vertices of a mesh
  std::int64_t maxTriangles = 10'000'000;     ///< after polygons are split into triangles
};

/// A shape a user brings: a point cloud (no triangles) or a triangle mesh, in the file's units.
struct ReferenceShape {
  Eigen::MatrixX3d points;     ///< n×3 points (a mesh's vertices)
  Eigen::MatrixX3d normals;    ///< n×3 unit normals as the file gives them, or 0 rows
  Eigen::MatrixX3i triangles;  ///< t×3 vertex indices, polygons split as fans; 0 rows for a cloud
  /// Faces the file has that are not in `triangles`: OpenMesh leaves out faces it cannot add
  /// (non-manifold ones); counted from the file's own face count (OFF, PLY headers; OBJ "f" lines).
  int facesSkipped = 0;
  std::string format;  ///< "xyz", "ply", "obj", "off" or "stl" (from the extension)

  bool isMesh() const { return triangles.rows() > 0; }
  /// Length of the bounding box's diagonal (0 for fewer than two distinct points).
  double diagonal() const;
};

/// Reads a reference shape by extension: .xyz / .pwn (one point per line, "x y z" or
/// "x y z nx ny nz", '#' comments), and .ply (a cloud or a mesh, ASCII or binary), .obj, .off, .stl
/// through OpenMesh. Normals are kept when the file has them (xyz/pwn, PLY vertex normals).
/// @throws std::invalid_argument naming the file (and the line, or the limit) on a missing or
///         unreadable file, an unknown extension, a malformed or non-finite line, a file over a
///         limit, a face index out of range, or no points at all.
ReferenceShape readReferenceShape(const std::string& path, const ReferenceLimits& limits = {});

}  // namespace devsurf::reference
