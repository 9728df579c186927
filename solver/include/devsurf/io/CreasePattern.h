#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace devsurf::io {

/// How an edge of a crease pattern behaves when the sheet is folded.
enum class EdgeAssignment {
  Boundary,  ///< edge of the sheet (one incident face)
  Mountain,  ///< folded away from the viewer of the development (fold angle < 0)
  Valley,    ///< folded towards the viewer of the development (fold angle > 0)
  Flat,      ///< interior edge that stays flat (triangulation / unassigned interior edge)
  Cut,       ///< slit: the material is cut along the edge
};

/// One edge (i, j) of the crease pattern.
struct CreaseEdge {
  int v0 = -1;
  int v1 = -1;
  EdgeAssignment assignment = EdgeAssignment::Flat;
  /// Fold angle in degrees, FOLD convention: deviation from flatness, positive = valley,
  /// negative = mountain, 0 for flat, boundary and cut edges; range [−180, 180].
  /// Unset: writers measure it from the folded state when they can (see measuredFoldAngle).
  std::optional<double> foldAngle;
  /// Polyline crease this edge belongs to (an id of CreasePattern::curves, or any id ≥ 0 shared
  /// by the edges of one chain; a composite's S edges joined with one tangent share the first
  /// one's id, each keeping its own spline in `curves`); −1 for an edge on no curve.
  int curve = -1;
  /// Not a fold line: a straight edge the import added (a bridge that joins an island to the
  /// sheet around it, so that no face has a hole), or an edge a composite keeps smooth (its
  /// crease pattern marks its R edges labelled "smooth"). Flat; a composite built from the pattern
  /// keeps it smooth, like a proposed ruling, and never makes it a free hinge. FOLD:
  /// `edges_devsurf:smooth` (true/false per edge), written when any edge has it.
  bool proposed = false;
};

/// Spline description of one crease curve (3D, the folded state), exported under namespaced keys.
struct CreaseCurve {
  int id = -1;                  ///< matches CreaseEdge::curve
  int degree = 0;
  std::vector<double> knots;    ///< controlPoints.rows() + degree + 1 non-decreasing values
  Eigen::MatrixX3d controlPoints;  ///< model units, folded state
  std::vector<double> weights;  ///< empty (polynomial) or one positive weight per control point
};

/// A folded piece of sheet material, described for export.
///
/// Conventions: the development lies in the xy plane with y pointing up and its faces listed
/// counter-clockwise (so the front side of the sheet, the one valley folds close onto, faces +z);
/// the folded state uses the same vertex indexing. Lengths are model units; `unitToMm`
/// millimetres per model unit turn them into physical sizes.
struct CreasePattern {
  std::string title;
  Eigen::MatrixX2d vertices2d;  ///< n×2 development
  Eigen::MatrixX3d vertices3d;  ///< n×3 folded state, or 0 rows when not known
  double unitToMm = 1.0;        ///< millimetres per model unit (> 0)
  std::vector<CreaseEdge> edges;
  std::vector<std::vector<int>> faces;  ///< vertex loops, counter-clockwise in the development
  Eigen::MatrixX4d rulings;     ///< r×4 ruling segments (x0, y0, x1, y1) in the development
  std::vector<CreaseCurve> curves;  ///< optional spline data, at most one entry per curve id

  int numVertices() const { return static_cast<int>(vertices2d.rows()); }
  bool hasFoldedState() const { return vertices3d.rows() > 0; }

  /// Checks the parts fit together: vertices3d empty or n×3; finite coordinates; unitToMm > 0;
  /// edge indices in range and distinct; fold angles finite, in [−180, 180] and consistent with
  /// the assignment (mountain ≤ 0, valley ≥ 0, others 0); faces with ≥ 3 valid vertices and a
  /// positive signed area in the development; finite rulings; curves with unique ids, a valid
  /// degree, knots.size() == controlPoints.rows() + degree + 1, non-decreasing knots, finite
  /// control points and weights empty or positive, one per control point.
  /// @throws std::invalid_argument naming the rule broken.
  void validate() const;
};

/// FOLD letter of an assignment: B, M, V, F, C.
char foldAssignmentLetter(EdgeAssignment a);
/// Inverse of foldAssignmentLetter; "U" (unassigned) and "J" (join) read as Flat.
/// @throws std::invalid_argument for any other string.
EdgeAssignment parseFoldAssignment(const std::string& letter);
/// Lower-case name: boundary, mountain, valley, flat, cut.
const char* assignmentName(EdgeAssignment a);

/// Signed fold angle (degrees, FOLD convention) of every edge, measured in the folded state from
/// the normals of the two faces sharing it: the face left of v0→v1 in the development and the
/// face right of it. An entry is empty when there is no folded state, the edge does not have
/// exactly one face on each side, or a face normal is degenerate.
std::vector<std::optional<double>> measuredFoldAngles(const CreasePattern& pattern);

/// The fold angle writers export for every edge: the given one; otherwise 0 for boundary, cut and
/// flat edges; otherwise the measured magnitude with the sign of the assignment; otherwise empty.
std::vector<std::optional<double>> exportedFoldAngles(const CreasePattern& pattern);

/// A maximal chain of edges sharing assignment and curve id: vertices in order along the chain
/// (for a closed chain the first vertex is not repeated), edges[k] joins vertices[k] and
/// vertices[k+1] (and, when closed, the last edge joins back to vertices[0]).
struct EdgeChain {
  EdgeAssignment assignment = EdgeAssignment::Flat;
  int curve = -1;
  bool closed = false;
  std::vector<int> vertices;
  std::vector<int> edges;
};

/// Groups the edges by (assignment, curve) and links each group into chains, broken at vertices
/// where the group does not continue through exactly two of its edges. Deterministic: groups by
/// first appearance, chains start at the lowest-numbered free edge.
std::vector<EdgeChain> edgeChains(const CreasePattern& pattern);

}  // namespace devsurf::io
