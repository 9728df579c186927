#pragma once

#include <array>
#include <functional>
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
  std::vector<int> sourceOfSegment;           ///< the input segment each piece comes from; −1 for a bridge
  std::vector<int> mergedInto;                ///< per input point: the id it was merged into (itself if kept)
  std::vector<std::vector<int>> faces;        ///< bounded faces, counter-clockwise point loops
  /// Input segments with no piece on the boundary of a kept face: dangling (a free end), of zero
  /// length, or in a component other than the largest (an island or a separate sheet).
  std::vector<int> unusedSegments;
  /// Input segments crossed or touched in their interior by another (split there).
  std::vector<std::array<int, 2>> crossings;
  /// Faces left out because they touch themselves at a point (a loop through one point twice).
  int pinchedFaces = 0;
  /// Components inside the sheet that were left out (another component inside a face, not
  /// bridged): their segments are unused.
  int islands = 0;
  /// Components inside the sheet joined to it by bridges (options.bridgeIslands).
  int bridgedIslands = 0;
  /// Indices into `segments` of the bridges: straight segments added from an island to what
  /// surrounds it, two per island, so that no face has a hole (their sourceOfSegment is −1).
  std::vector<int> bridges;
  /// The sheet's outer loop (the kept component's outer boundary, clockwise), empty without faces.
  std::vector<int> outline;
};

/// How planarArrangement treats its input.
struct PlanarArrangementOptions {
  /// Absolute distance below which points are one point and a point lies on a segment; ≤ 0 picks
  /// 1e-9 × the points' bounding-box diagonal.
  double tolerance = 0.0;
  /// Join every component that lies inside the sheet (a closed crease, a hole's outline, a
  /// pattern drawn apart inside a face) to the segments around it by two straight bridges, each
  /// the shortest segment from a point of the island to a segment around it that crosses nothing
  /// and meets both ends at 10° or more (the second from the island's far side — 120° away seen
  /// from its centroid, else a third of its outline away — ending elsewhere; ends of earlier
  /// bridges preferred). Without it islands are left out;
  /// with it too, past a work bound (3 × outline points × pieces summed over the tries, 4e7: a
  /// sheet perforated by thousands of tiny loops).
  bool bridgeIslands = false;
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
/// @param[in] options    tolerance, bridging of islands
/// @throws std::invalid_argument for non-finite points or ids out of range, naming the segment
PlanarArrangement planarArrangement(const Eigen::MatrixX2d& points, const std::vector<std::array<int, 2>>& segments,
                                    const PlanarArrangementOptions& options);

/// planarArrangement with a tolerance (≤ 0: 1e-9 × the diagonal), islands left out.
PlanarArrangement planarArrangement(const Eigen::MatrixX2d& points, const std::vector<std::array<int, 2>>& segments,
                                    double tolerance = 0.0);

/// Which faces are holes: cut off from the sheet's outline by walls. A face belongs to the sheet
/// when it has an edge on the outline, or a chain of neighbours across shared edges that are not
/// walls leads to one. Faces enclosed by an outline drawn inside the sheet (a hole's outline,
/// walls) are holes, with whatever lies inside them.
/// @param[in] faces    point loops (as PlanarArrangement::faces)
/// @param[in] outline  the sheet's outer loop (PlanarArrangement::outline); an edge that has one
///                     face only because a face beside it was left out (pinched) is not outline
/// @param[in] isWall   whether the edge between two points is a wall
/// @return per face: a hole
std::vector<bool> holeFaces(const std::vector<std::vector<int>>& faces, const std::vector<int>& outline,
                            const std::function<bool(int, int)>& isWall);

/// Removes the hole faces of an arrangement (holeFaces), the walls being its segments whose input
/// segment the caller names (bridges are never walls). A walled-off region with a drawn edge inside
/// it that is not a wall is kept (a hole holds no creases: an outline drawn twice, a frame drawn
/// inside). Nothing is removed when every face would be.
/// @param[in,out] arrangement  its faces lose the holes (points and segments stay)
/// @param[in] isWallSource     per input segment id: whether it is a wall (an outline drawn inside)
/// @return the number of faces removed
int cutOutHoles(PlanarArrangement& arrangement, const std::function<bool(int)>& isWallSource);

/// Whether p lies inside a point loop (even–odd rule; points on the loop either way).
bool pointInLoop(const Eigen::MatrixX2d& points, const std::vector<int>& loop, const Eigen::Vector2d& p);

/// Twice the signed area of a point loop (positive = counter-clockwise).
double loopSignedArea2(const Eigen::MatrixX2d& points, const std::vector<int>& loop);

}  // namespace devsurf::spatial
