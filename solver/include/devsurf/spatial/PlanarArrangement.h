#pragma once

#include <array>
#include <vector>

#include <Eigen/Core>

namespace devsurf::spatial {

/// The faces a set of straight segments cuts the plane into (a crease pattern without faces).
///
/// Conventions: points are rows (x, y); every segment of the result joins two distinct points and
/// no two segments of the result cross or overlap; faces are bounded faces only, each a loop of
/// point ids, counter-clockwise (positive signed area), no point twice.
struct PlanarArrangement {
  Eigen::MatrixX2d points;                    ///< the input points (merged ones keep their first id), then the crossings
  std::vector<std::array<int, 2>> segments;   ///< pieces of the input segments after splitting
  std::vector<int> sourceOfSegment;           ///< the input segment each piece comes from
  std::vector<int> mergedInto;                ///< per input point: the id it was merged into (itself if kept)
  std::vector<std::vector<int>> faces;        ///< bounded faces, counter-clockwise point loops
  /// Input segments with no piece on the boundary of a kept face: dangling (a free end), of zero
  /// length, or in a component other than the largest (an island or a separate sheet).
  std::vector<int> unusedSegments;
  /// Input segments crossed or touched in their interior by another (split there).
  std::vector<std::array<int, 2>> crossings;
  /// Faces left out because they touch themselves at a point (a loop through one point twice).
  int pinchedFaces = 0;
  /// Faces with a hole (another component inside them): the island's segments are unused.
  int islands = 0;
};

/// Splits the segments where they cross, overlap or touch one another's interior, merges points
/// closer than `tolerance`, drops dangling segments (repeatedly, so trees hanging off the sheet go
/// too), keeps the connected component with the largest outer boundary and walks its faces (each
/// half-edge followed by the next one clockwise around its end point, so every face lies to the
/// left of its edges).
///
/// O(s²) in the number of segments (with bounding-box rejection): meant for crease patterns of up
/// to a few thousand segments.
///
/// @param[in] points     n×2 points
/// @param[in] segments   pairs of point ids
/// @param[in] tolerance  absolute distance below which points are one point and a point lies on a
///                       segment; ≤ 0 picks 1e-9 × the points' bounding-box diagonal
/// @throws std::invalid_argument for non-finite points or ids out of range, naming the segment
PlanarArrangement planarArrangement(const Eigen::MatrixX2d& points, const std::vector<std::array<int, 2>>& segments,
                                    double tolerance = 0.0);

/// Whether p lies inside a point loop (even–odd rule; points on the loop either way).
bool pointInLoop(const Eigen::MatrixX2d& points, const std::vector<int>& loop, const Eigen::Vector2d& p);

/// Twice the signed area of a point loop (positive = counter-clockwise).
double loopSignedArea2(const Eigen::MatrixX2d& points, const std::vector<int>& loop);

}  // namespace devsurf::spatial
