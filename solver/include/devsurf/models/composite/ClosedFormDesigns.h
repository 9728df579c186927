#pragma once

#include <Eigen/Core>

#include "devsurf/creases/CylinderCatenaryCrease.h"
#include "devsurf/models/composite/CompositeDesign.h"
#include "devsurf/spline/BSplineCurve.h"

namespace devsurf::models::composite {

/// Closed-form curved folds (Mundilova 003_… Part I) as composite designs, the exact (or
/// approximation-level) solutions the composite model's tests and presets start from.
///
/// Every builder returns the same combinatorics (that of a single curved fold between two strips):
///
///   vertices: 0 = c(begin), 1 = c(end), 2 = b₁(end), 3 = b₁(begin), 4 = b₂(begin), 5 = b₂(end)
///   edges:    0  S 0→1  the crease c, labelled CreaseKind::Fold
///             1  R 1→2,  2  S 2→3 (b₁ reversed),  3  R 3→0          (first sheet)
///             4  R 0→4,  5  S 4→5 (b₂),           6  R 5→1          (second sheet)
///   faces:    [0, 1, 2, 3] (first sheet: a = c, b = b₁), [4, 5, 6, 0] (second sheet: a = b₂, b = c)
///
/// c, b₁ and b₂ share degree and knots; the ruling of sheet i at parameter t joins c(t) and
/// b_i(t). Nothing is fixed and there are no handles; callers add them (the vertex numbers above
/// are stable).

/// Index of the crease edge and of the far boundaries in every closed-form design.
inline constexpr int kClosedFormCreaseEdge = 0;
inline constexpr int kClosedFormFirstBoundaryEdge = 2;   ///< b₁, stored reversed (2→3)
inline constexpr int kClosedFormSecondBoundaryEdge = 5;  ///< b₂

/// The two-strip fold design from the control points of c, b₁, b₂ (each n×3, rows from t = begin
/// to t = end, same knots).
/// @param[in] knots  clamped knot vector shared by the three curves (n control points)
/// @param[in] crease, firstBoundary, secondBoundary  control points, n×3 each
/// @throws std::invalid_argument on mismatched sizes or a non-clamped/rational knot vector
CompositeDesign twoSheetFoldDesign(const spline::KnotVector& knots, const Eigen::MatrixX3d& crease,
                                   const Eigen::MatrixX3d& firstBoundary,
                                   const Eigen::MatrixX3d& secondBoundary);

/// A planar curved fold by reflection (003_… §2.3), EXACT in B-splines.
///
/// The first sheet is the general cylinder over the planar profile g(u) (a 2D B-spline in the
/// plane z = 0) extruded along e₃; the crease plane P = {x : n·x = offset} (n_z ≠ 0) cuts it in
///   c(u) = (g(u), z_P(g(u))),  z_P(x, y) = (offset − n_x x − n_y y)/n_z,
/// which is a B-spline with control points (G_i, z_P(G_i)) because z_P is affine. The first sheet
/// runs from c up to the cut with the plane z = top, b₁(u) = (g(u), top). The cylinder continues
/// below P down to z = bottom; folding reflects that part in P (the second sheet's tangent planes
/// are the cylinder's reflected in the crease's osculating plane P), so
///   b₂(u) = R_P (g(u), bottom),
/// again affine in g. Hence both strips are exactly developable (their rulings are parallel to e₃
/// and R_P e₃), the crease satisfies the curved-fold condition exactly, and every residual of the
/// composite model is at round-off level.
///
/// \note Reflecting the first sheet itself (b₂ = R_P b₁) would put both developments on the same
///       side of the developed crease — not a fold of one sheet of paper. The paper continues
///       across the crease into the cylinder's other half, whose mirror image is used here (as in
///       creases::planarFoldByReflection, d₂ = −R d₁).
struct PlanarFoldSpec {
  /// Profile g(u): clamped polynomial B-spline, control points n×2 (x, y) in the plane z = 0.
  spline::BSplineCurve profile;
  Eigen::Vector3d planeNormal = Eigen::Vector3d(0.25, 0.1, 1.0);  ///< n (normalized here), n_z ≠ 0
  double planeOffset = 0.0;  ///< P: n·x = planeOffset (n as given, before normalization)
  double top = 1.0;          ///< z of the first sheet's far boundary; above P over the whole profile
  double bottom = -1.0;      ///< z of the reflected half's far boundary; below P over the profile
};

/// A default specification: a cubic S-shaped profile of 7 control points, about 3 × 1.2, the
/// tilted plane of PlanarFoldSpec's defaults, top = 1, bottom = −1.
PlanarFoldSpec defaultPlanarFoldSpec();

/// @throws std::invalid_argument on a rational or non-2D profile, n_z ≈ 0, or a top/bottom that
///         does not lie above/below P at every control point of the profile (the convex hull
///         property then keeps the whole sheet on its side)
CompositeDesign planarFoldDesign(const PlanarFoldSpec& spec = defaultPlanarFoldSpec());

/// How a closed-form crease that is not polynomial is put into B-spline form.
struct ClosedFormFit {
  int degree = 5;  ///< of the crease and both boundaries
  int spans = 16;  ///< uniform spans over the crease's parameter interval
  int samplesPerSpan = 8;  ///< least-squares samples per span (plus the end points)
};

/// The curved crease of constant angle on the cylinder of revolution (003_… §3.1.3; see
/// creases::CylinderCatenaryCrease) as a composite design: c, the cylinder sheet's far boundary
/// b₁ = c + L·side·e₃ (its rulings are the cylinder's generators), and the second sheet's far
/// boundary b₂ = c + L r₂ (rulings reflected in the crease's osculating planes).
///
/// The closed form is not polynomial: c(u) and c(u) + L r₂(u) are fitted by least squares over
/// [u0, u1] ↦ t ∈ [0, 1] (uniform clamped knots, end points interpolated), and b₁'s control points
/// are c's shifted by L·side·e₃ — so the first sheet is an exact cylinder over the fitted crease
/// and only the second sheet and the fold condition carry the fitting error (O(h^{p−1}) in the
/// second derivatives). cylinderCatenaryFitError() measures it.
/// @throws std::invalid_argument on degree < 2, spans < 1 or samplesPerSpan < 1
CompositeDesign cylinderCatenaryCreaseDesign(const creases::CylinderCatenaryCrease& crease,
                                             const ClosedFormFit& fit = {});

/// Largest distance, over `samples` equally spaced parameters t, between the design's crease and
/// second far boundary (edges 0 and 5) and the closed forms c(u(t)), c(u(t)) + L r₂(u(t))
/// (design units).
/// @throws std::invalid_argument if the design does not have the closed-form combinatorics
double cylinderCatenaryFitError(const creases::CylinderCatenaryCrease& crease,
                                const CompositeDesign& design, int samples = 1001);

/// The crease of the default preset (examples/composite-cylinder-crease.json): φ = 1 rad on the
/// unit cylinder, u ∈ [−1, 1], rulings of length 0.8, side +1.
creases::CylinderCatenaryCrease defaultCylinderCatenaryCrease();

}  // namespace devsurf::models::composite
