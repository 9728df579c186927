#pragma once

#include <vector>

#include <Eigen/Core>

namespace devsurf::spatial {

/// Flat pieces of a polygon mesh laid out on the plane (see unfoldPieces).
struct FlatLayout {
  Eigen::MatrixX2d vertices;               ///< every piece's own copy of each of its points
  std::vector<std::vector<int>> polygons;  ///< per input polygon: ids into vertices (empty when skipped)
  std::vector<int> pieceOfVertex;          ///< piece of each vertex
  std::vector<int> pointOfVertex;          ///< the input point each vertex is a copy of
  int pieces = 0;                          ///< pieces that hold at least one polygon
  /// Largest |ℓ′ − ℓ| / ℓ over the polygon edges of the layout against the same edges in 3D (0 for
  /// a developable mesh, up to round-off).
  double lengthErrorMax = 0.0;
};

/// Unfolds each piece of a polygon mesh onto the plane from its own 3D edge lengths: the polygons
/// are split into fans of triangles, the first triangle of a piece is laid down counter-clockwise
/// and every other one is unfolded across an edge it shares with one already placed (breadth-first;
/// a point reached twice keeps its first position). Orientation is kept, so polygons that are
/// consistently oriented in 3D stay counter-clockwise seen from the normal's side. Each piece is
/// then turned so its longest direction (principal axis) lies along x, and the pieces are stacked
/// one above the other (piece 0 at the bottom, gaps of 15 % of the piece's height), starting at the
/// origin. Points a piece shares with another piece are copied, one copy per piece.
///
/// A piece whose triangles are not connected through shared edges is unfolded from its first
/// triangle's component only: its other polygons are left out (their entries in `polygons` empty).
///
/// @param points           3D points
/// @param polygons         ids into points, ≥ 3 per polygon to be used (shorter ones are skipped)
/// @param pieceOfPolygon   piece id ≥ 0 of every polygon; ids need not be consecutive
/// @throws std::invalid_argument for ids out of range, sizes that differ, non-finite points or a
///         triangle with an edge of zero length.
FlatLayout unfoldPieces(const std::vector<Eigen::Vector3d>& points, const std::vector<std::vector<int>>& polygons,
                        const std::vector<int>& pieceOfPolygon);

/// Pieces of a polygon mesh: polygons joined across every edge they share (polygons meeting at a
/// single point only stay apart). Numbered 0, 1, … by first polygon.
std::vector<int> edgeConnectedPieces(const std::vector<std::vector<int>>& polygons);

/// Welds points closer than `tolerance`: the id of the point each one is merged into (the lowest
/// id of its cluster, found through nanoflann's k-d tree; points chain into one cluster).
/// @param points   n×3
/// @param tolerance ≥ 0
std::vector<int> weldedPointIds(const Eigen::MatrixX3d& points, double tolerance);

}  // namespace devsurf::spatial
