#pragma once

#include <vector>

#include <Eigen/Core>

#include "devsurf/models/strip/StripModel.h"

namespace devsurf::models::strip {

/// How a flat strip is placed over a region of reference points (000_… §4.2, Fig. 10a: "PCA is
/// used to fit initial flat strips").
struct RegionStripOptions {
  int controlPoints = 8;  ///< per boundary curve (≥ degree + 1)
  int degree = 3;
  /// Direction of the rulings in the PCA plane. Auto: the direction of least normal curvature of
  /// a quadratic height field fitted over the plane (a developable's rulings have zero normal
  /// curvature); where the region is nearly flat, across the longer extent.
  enum class Rulings { Auto, AcrossLongest, AlongLongest };
  Rulings rulings = Rulings::Auto;
  /// The rectangle grows by this fraction of its size on each side (points near the region's
  /// edge then project inside the strip).
  double margin = 0.02;
  /// Lift the control points onto the fitted quadratic height field instead of leaving the strip
  /// flat. The paper starts flat (Fig. 10a); a flat rectangle spans the region's projection, which
  /// for a strongly curved region is shorter than the surface (a 100° arc is 14 % longer than its
  /// chord), and the low-weight eq. (9) stretches it only slowly. Lifted, the strip covers the
  /// region from the start.
  bool liftToHeightField = true;
};

/// The approximation target of thinned points: the rows whose normal could be fitted (non-zero;
/// reference::thinPointCloud leaves a zero normal where a ball held too few points), with the
/// paper's default weights.
ApproximationTarget approximationTargetFrom(const Eigen::MatrixX3d& points, const Eigen::MatrixX3d& normals);

/// Indices of the rows of `points` within `radius` of `centre` (a brush stroke's ball).
std::vector<int> pointsInBall(const Eigen::MatrixX3d& points, const Eigen::Vector3d& centre, double radius);

/// A quadratic height field h(x, y) = c0 + c1 x + c2 y + c3 x² + c4 xy + c5 y² fitted by least
/// squares to points in a PCA frame (x, y in the plane, h along its normal; fitted in coordinates
/// divided by `size`), and the in-plane direction of least normal curvature (where a developable's
/// rulings run).
struct QuadraticHeightField {
  Eigen::VectorXd coefficients;                      ///< c0 … c5 (zero when not fitted)
  bool curved = false;                               ///< the larger |curvature| exceeds 1e-3/size
  Eigen::Vector2d leastCurvature{0.0, 1.0};          ///< unit, in (x, y); (0, 1) when not curved
};
/// @param[in] local  N×3 points in the frame; fewer than 6 leave the field zero
QuadraticHeightField fitQuadraticHeightField(const Eigen::MatrixXd& local, double size);

/// A rectangular strip over the points: in the plane through their centroid spanned by the two
/// largest principal axes, covering their projection, curves a and b (clamped uniform B-splines of
/// `degree`) along one side and the opposite side, rulings between them; lifted onto the points'
/// quadratic height field over that plane unless options.liftToHeightField is false.
/// @param[in] points  the region's points, N×3 with N ≥ 3 not all on a line
/// @throws std::invalid_argument for fewer than 3 points, non-finite points, collinear points or
///         bad options
StripDesign flatStripOverRegion(const Eigen::MatrixX3d& points, const RegionStripOptions& options = {});

}  // namespace devsurf::models::strip

namespace devsurf::models::strip {

/// What mergeStrips did to line the strips up.
struct StripMerge {
  StripDesign merged;
  bool reversedFirst = false;   ///< the first strip's curves were reversed
  bool reversedSecond = false;  ///< the second strip's curves were reversed
  bool swappedSecond = false;   ///< the second strip's a and b were exchanged
  double gap = 0.0;             ///< distance between the joined end rulings (mean of both ends)
  bool overlap = false;         ///< the strips overlapped (each was cut at the overlap's middle)
  double keptFirst = 1.0;       ///< fraction of the first strip's samples kept (1: not cut)
  double keptSecond = 1.0;      ///< fraction of the second strip's samples kept
  double joinOffset = 0.0;      ///< step across between the middle lines where they are joined
                                ///< (their offset less its part along the way they run there)
};

/// Merges two strips into one (000_… Fig. 10c: "merged by putting together their respective
/// control point sequences (averaging the end control points)"). The strips are lined up first:
/// of the eight ways to reverse either and exchange the second's a and b, the one whose joined
/// end rulings are closest and whose outer end rulings are farthest apart (the sum of the gaps
/// less the sum of the spans). Then both are sampled densely and joined end to end; where they
/// overlap (a user's brush strokes do), each is cut at the middle of the overlap, since joining
/// the control sequences as they are folds the merged strip back there (tested). The merged a and
/// b are least-squares fits of the joined samples with n₁ + n₂ − 1 control points on clamped
/// uniform knots, at common chord-length parameters of the middle line, so rulings stay paired;
/// for strips that meet end to end this reproduces the joined sequences up to the fit.
/// Strips that do not continue one another are refused (std::invalid_argument): joined, the middle
/// line would turn back by more than 90°; the cut at the overlap's middle would drop more than 40 %
/// of one of them (side by side, as a fraction of its samples, uniform in its parameter); or it
/// would join middle lines stepping across by more than half the narrower strip's mean width (a
/// gap between ends in line is not a step across).
/// Approximation targets are concatenated (weights of the first); fixed points and handles are
/// dropped; normals become a normal spline with one control point per curve control point.
/// @throws std::invalid_argument for closed or rational curves, differing degrees, or strips that
///         do not continue one another (above)
StripMerge mergeStrips(const StripDesign& first, const StripDesign& second);

}  // namespace devsurf::models::strip
