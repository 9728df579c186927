#pragma once

#include <cstdint>
#include <string>

#include <Eigen/Core>

namespace devsurf::reference {

/// What a reference file may hold (issue 15: a user's scan or mesh). A file over a limit is
/// refused with a message naming the limit: by its size on disk and the counts its header
/// declares before it is parsed, by the counts found while or after it is parsed.
struct ReferenceLimits {
  std::uint64_t maxFileBytes = 512ull << 20;  ///< bytes on disk (default 512 MiB)
  std::int64_t maxPoints = 5'000'000;         ///< points of a cloud or vertices of a mesh
  std::int64_t maxTriangles = 10'000'000;     ///< after polygons are split into triangles
};

/// Largest coordinate magnitude of a reference shape: a scene's (proto::kMaxCoordinate), since the
/// surfaces fitted to a shape are scenes in its units. Quoted as "±1e9" in the error.
inline constexpr double kMaxShapeCoordinate = 1e9;

/// A shape a user brings: a point cloud (no triangles) or a triangle mesh, in the file's units.
struct ReferenceShape {
  Eigen::MatrixX3d points;     ///< n×3 points (a mesh's vertices)
  Eigen::MatrixX3d normals;    ///< n×3 unit normals as the file gives them, or 0 rows
  Eigen::MatrixX3i triangles;  ///< t×3 vertex indices, polygons split as fans; 0 rows for a cloud
  /// Faces the file declares (OFF, PLY headers; binary STL's count; OBJ "f" and ASCII STL
  /// "facet" lines) that are not in `triangles` (faces OpenMesh refuses, e.g. with a repeated
  /// vertex). A non-manifold face is kept: OpenMesh adds it with its own copies of its vertices,
  /// so `points` may have more rows than the file has vertices.
  std::int64_t facesSkipped = 0;
  std::string format;  ///< "xyz", "ply", "obj", "off" or "stl" (from the extension)

  bool isMesh() const { return triangles.rows() > 0; }
  /// Length of the bounding box's diagonal (0 for fewer than two distinct points).
  double diagonal() const;
};

/// Reads a reference shape by extension: .xyz / .pwn (one point per line, "x y z" or
/// "x y z nx ny nz", '#' comments), and .ply (a cloud or a mesh, ASCII or binary), .obj, .off, .stl
/// through OpenMesh. Normals are kept when the file has them (xyz/pwn, PLY vertex normals).
/// Precision: OpenMesh's readers parse coordinates as single-precision floats (about 7 digits:
/// scans in large coordinates, e.g. UTM metres, should be shifted near the origin first); .xyz
/// and .pwn keep doubles. Binary OFF is not read.
/// @throws std::invalid_argument naming the file (and the line, or the limit) on a missing or
///         unreadable file, an unknown extension, a malformed or non-finite line, a coordinate
///         outside ±kMaxShapeCoordinate (the line, or the vertex), a header that
///         declares more than a limit (or disagrees with a binary STL's size), a file over a
///         limit, or no points at all.
ReferenceShape readReferenceShape(const std::string& path, const ReferenceLimits& limits = {});

}  // namespace devsurf::reference
