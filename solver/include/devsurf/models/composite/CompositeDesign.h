#pragma once

#include <array>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "devsurf/io/CreaseStrokes.h"
#include "devsurf/spline/BSplineCurve.h"

namespace devsurf::models::composite {

/// Label of an edge of the composite's mesh (000_… §3.1): a ruling (straight segment) or a spline
/// curve.
enum class EdgeType { Ruling, Spline };
const char* edgeTypeName(EdgeType t);  ///< "R" or "S"

/// What joins the two faces along an interior edge (scene "crease").
enum class CreaseKind {
  None,      ///< no condition: the edge may fold or not (an R edge always folds freely)
  Fold,      ///< curved fold, 000_… eq. (7): the edge unfolds to one planar curve on both sides
  Geodesic,  ///< geodesic property, 000_… eq. (8): the two developed boundaries are mirror images
  Smooth,    ///< tangent-plane continuity: the normals of the two faces agree along the edge
  Straight,  ///< straight unfolding (000_… §3.3): an S edge that develops into a straight line (a
             ///< geodesic of its face(s)); allowed on boundary edges too
};
const char* creaseKindName(CreaseKind k);  ///< "none", "fold", "geodesic", "smooth", "straight"

/// One edge of the composite: its end vertices, label, and for S edges the spline. The spline's
/// control sequence runs from vertex v0 to vertex v1 and its first and last control points ARE
/// those vertices (000_… §3.1 vertex–edge consistency): the model keeps one variable block per
/// vertex and one per S edge for the interior control points only.
struct CompositeEdge {
  int v0 = -1, v1 = -1;
  EdgeType type = EdgeType::Ruling;
  /// S edges: clamped, polynomial (no weights), control points as rows from v0 to v1.
  /// Empty (no knots, no points) for R edges.
  spline::BSplineCurve curve;
  CreaseKind crease = CreaseKind::None;
};

/// A point the scene addresses: a vertex, or control point `index` of an S edge's curve (index 0
/// and n−1 are the edge's vertices v0 and v1).
struct PointRef {
  int vertex = -1;  ///< ≥ 0 for a vertex
  int edge = -1;    ///< ≥ 0 for an edge control point
  int index = 0;
  static PointRef ofVertex(int v) { return {v, -1, 0}; }
  static PointRef ofEdgePoint(int e, int k) { return {-1, e, k}; }
  bool isVertex() const { return vertex >= 0; }
  bool operator==(const PointRef& o) const {
    return vertex == o.vertex && edge == o.edge && (vertex >= 0 || index == o.index);
  }
};

/// A point pulled softly toward a target (the drag mechanism).
struct Handle {
  PointRef point;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  double weight = 1.0;
};

/// A curve of a development's prescribed domain (design units, in the development's plane).
struct DomainCurve {
  Eigen::MatrixX2d points;  ///< polyline, ≥ 2 points (≥ 3 if closed), consecutive points distinct
  bool closed = false;      ///< the last point joins the first (not repeated)
};

/// A vertex pinned to a point of the development (a corner of the domain).
struct DomainCorner {
  int vertex = -1;
  Eigen::Vector2d at = Eigen::Vector2d::Zero();
};

/// Isometric mapping onto a prescribed domain D̄ (000_… §5 "Isometric mapping"): corners are
/// pinned; every other sample of a boundary edge stays on the domain curve nearest to that edge
/// (linearized to the curve's tangent at the foot point, renewed every iteration), and so do the
/// samples of an interior S edge that starts on a domain curve (mean distance under 2 % of its
/// chord: a crease drawn in the development).
/// \note The domain is given in the development's orientation: faces run counterclockwise in the
///       development as they do seen from their normals' side.
struct DevelopmentDomain {
  std::vector<DomainCurve> boundary;
  std::vector<DomainCorner> corners;
  bool empty() const { return boundary.empty() && corners.empty(); }
};

/// A fold-angle target of a crease (scene "fold_angles": [{"edge", "end", "angle"}]; FOLD's
/// edges_foldAngle): an interior R edge folds about itself (one hinge, end 0); an interior S edge
/// is a hinge at each end (end 0 at v0, 1 at v1) where both faces have a ruling. Pulled softly
/// towards foldAmount × angleDeg (the fold slider).
struct FoldAngleTarget {
  int edge = -1;
  int end = 0;            ///< 0 or 1; 0 for R edges
  double angleDeg = 0.0;  ///< degrees in [−180, 180], + valley, − mountain
};

/// A composite developable (000_… §3.1): a labelled polygon mesh whose faces are spline
/// developables (S R S R), the same with one ruling degenerated to a point (S R S), cones (S R R)
/// and planar polygons (R … R).
struct CompositeDesign {
  Eigen::MatrixX3d vertices;            ///< one row per vertex
  std::vector<CompositeEdge> edges;
  /// Every face as its boundary edges (indices into edges) in order; the order fixes the face's
  /// orientation (counterclockwise seen from the side its normal points to). All faces must be
  /// oriented consistently (a shared edge is traversed in opposite directions).
  std::vector<std::vector<int>> faces;
  std::vector<PointRef> fixed;
  std::vector<Handle> handles;
  /// Pairs of S edges meeting at a vertex whose curves are to pass through it with one tangent
  /// (000_… §3.1, "when asked"; scene "tangent_continuity": [[e1, e2], …]).
  std::vector<std::array<int, 2>> tangentContinuity;
  /// Development management (scene "development": {"samples": n}; 003_… §5.2.5): samples per
  /// span along the S edges of the sampled mesh whose planar development is solved for together
  /// with the surface (eq. 12). 0 = no development (the default).
  int developmentSamples = 0;
  /// Optional prescribed domain of the development (needs developmentSamples > 0).
  DevelopmentDomain developmentDomain;
  /// Edges along which the development is cut open (000_… §6 Fig. 14): the faces on the two sides
  /// of a seam get separate development vertices, related by one translation T (a variable), so
  /// the development is periodic — the surface unfolds onto a cylinder of circumference |T|. Must
  /// be interior edges; empty = no cut.
  std::vector<int> developmentSeam;
  /// Optional starting values of the development (design units), one row per vertex of the
  /// sampled mesh as CompositeDevelopment::vertices2d numbers them. Used when the row count
  /// matches (a saved or rebuilt design keeps its development); otherwise, or when empty, the
  /// development starts from unfolding the surface. CompositeModel::design() returns the current
  /// development here.
  Eigen::MatrixX2d developmentVertices;
  /// Fold-angle targets (scene "fold_angles"); empty = none (every crease folds freely).
  std::vector<FoldAngleTarget> foldAngles;
  /// How far along its fold-angle targets the design is pulled (scene "fold_amount", [0, 1]): 0 =
  /// flat, 1 = the targets themselves (the fold slider's position).
  double foldAmount = 1.0;
  /// The flat drawing the design was made from (scene "drawing": {"strokes": […]}), in design
  /// units on the sheet (x right, y up; the development's frame): the sheet's outline (B strokes)
  /// and its creases and cuts, a curved stroke being the interpolating spline through its points.
  /// Empty for designs not made from a crease pattern. Layout edits change the strokes and rebuild
  /// the design from them (compositeFromDrawing); the solver does not read them.
  std::vector<io::CreaseStroke> drawing;
};

}  // namespace devsurf::models::composite
