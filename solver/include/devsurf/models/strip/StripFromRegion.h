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

/// Indices of the rows of `points` within `radius` of `centre` (a brush stroke's ball).
std::vector<int> pointsInBall(const Eigen::MatrixX3d& points, const Eigen::Vector3d& centre, double radius);

/// A rectangular strip over the points: in the plane through their centroid spanned by the two
/// largest principal axes, covering their projection, curves a and b (clamped uniform B-splines of
/// `degree`) along one side and the opposite side, rulings between them; lifted onto the points'
/// quadratic height field over that plane unless options.liftToHeightField is false.
/// @param[in] points  the region's points, N×3 with N ≥ 3 not all on a line
/// @throws std::invalid_argument for fewer than 3 points, non-finite points, collinear points or
///         bad options
StripDesign flatStripOverRegion(const Eigen::MatrixX3d& points, const RegionStripOptions& options = {});

}  // namespace devsurf::models::strip
