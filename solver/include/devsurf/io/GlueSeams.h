#pragma once

#include <array>
#include <vector>

#include <Eigen/Core>

#include "devsurf/io/PolygonMesh.h"

namespace devsurf::io {

/// One edge of a polygon mesh with what the cutting-pattern exports need to know about it.
struct PolygonEdge {
  int v0 = -1, v1 = -1;  ///< in the order of the first face that has the edge (so a boundary
                         ///< edge of a counter-clockwise unfolding has its face on the left)
  int faceCount = 0;     ///< 1 = boundary edge (cut or glued), 2 = interior edge
  int face = -1;         ///< the first face that has the edge
  int gluedTo = -1;      ///< the boundary edge this one is glued to (index into edges), or -1
  int seam = -1;         ///< 0-based seam of a glued edge, or -1
  int side = -1;         ///< 0 or 1: which side of its seam the edge is on, or -1
};

/// The edges of a mesh with its glued boundary edges paired up and grouped into seams.
///
/// Glue pairs (i, j) say vertex i and vertex j of the unfolding are one point of the 3D mesh;
/// they are closed transitively (i ~ j, j ~ k ⇒ i ~ k: several pieces meeting in a cone point).
/// A boundary edge (a, b) is *glued* to another boundary edge (c, d) when their end points are
/// glued to each other ({a, b} ~ {c, d} in either order); an edge whose two end points are glued
/// to each other, or whose end points match more than one other edge, is matched with the
/// first such edge in edge order (the rest stay cut). Other boundary edges are *cut* edges.
/// (Gluing is known only at vertices: a boundary edge whose two end points are both glued counts
/// as glued even if the model means the edge itself to stay open — e.g. the side edges of a strip
/// one face wide whose top and bottom are glued.)
/// A *seam* is a maximal chain of glue pairs (e, e′), (f, f′), … where e and f share a vertex v,
/// e′ and f′ share a vertex v′, and v ~ v′ — consecutive glued edges along one seam line. With
/// the unfolding's coordinates given, a seam also ends at a vertex where the material meets at a
/// corner or a cone point: the angle sums of v and v′ (their faces' corner angles in M′) differ
/// from 2π by more than π/4 (a hole's corner, the apex of a cone with two seams). Side 0
/// holds the chain's edges on the side of the seam's lowest-numbered edge. Seams are numbered in
/// the order of their lowest-numbered edge. Edges are numbered in the order faces meet them
/// (face 0's edges first, each face's in its corner order).
struct GlueSeams {
  std::vector<PolygonEdge> edges;
  int seamCount = 0;
};

/// @param vertexCount number of vertices of the mesh (M and M′ share indices)
/// @param unfolding V×2 or V×3 vertices of M′ for the corner rule above, or no rows (seams then
///        run through every shared glued vertex)
/// @throws std::invalid_argument naming the face for bad faces (validatePolygonFaces) or an
///         edge of more than two faces, naming the glue pair for an index out of range or a pair
///         (i, i).
GlueSeams findGlueSeams(int vertexCount, const std::vector<PolygonFace>& faces,
                        const std::vector<std::array<int, 2>>& gluePairs,
                        const Eigen::MatrixXd& unfolding = Eigen::MatrixXd());

/// Where one side of a seam is numbered on a cutting pattern.
struct SeamLabel {
  int seam = -1;                               ///< 0-based seam
  int side = -1;                               ///< 0 or 1
  Eigen::Vector2d position = Eigen::Vector2d::Zero();  ///< in the unfolding's units
};

/// Label positions of every side of every seam, seam by seam, side 0 first: beside the side's
/// edge nearest the mean of that side's edge midpoints, moved `inset` (unfolding units) from the
/// edge's middle towards the centre of the edge's face.
/// @param unfolding V×2 or V×3 vertices of M′ (the ones findGlueSeams was given)
std::vector<SeamLabel> seamLabelPositions(const GlueSeams& seams, const std::vector<PolygonFace>& faces,
                                          const Eigen::MatrixXd& unfolding, double inset);

}  // namespace devsurf::io
