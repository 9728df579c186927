#pragma once

// Shared by the tests of strips side by side (000_… Fig. 10d–e): flat strips in a row and the
// points a cover's bands hold.

#include <vector>

#include <Eigen/Core>

#include "devsurf/models/strip/StripCover.h"
#include "devsurf/models/strip/StripModel.h"

namespace devsurf::testing {

/// A flat strip with a along y = y0 and b along y = y1 in the plane z = 0, from x = 0 to 1
/// (clamped uniform cubics with n control points).
inline models::strip::StripDesign flatStrip(double y0, double y1, int n = 6) {
  models::strip::StripDesign s;
  s.a.knots = s.b.knots = spline::KnotVector::clampedUniform(3, n);
  s.a.points.resize(n, 3);
  s.b.points.resize(n, 3);
  for (int i = 0; i < n; ++i) {
    s.a.points.row(i) << double(i) / (n - 1), y0, 0.0;
    s.b.points.row(i) << double(i) / (n - 1), y1, 0.0;
  }
  return s;
}

/// The rows of `points` that the layout's bands hold (the region as covered), band by band.
inline Eigen::MatrixX3d coveredPoints(const Eigen::MatrixX3d& points, const models::strip::RegionLayout& layout) {
  Eigen::Index count = 0;
  for (const auto& band : layout.bands) count += static_cast<Eigen::Index>(band.size());
  Eigen::MatrixX3d covered(count, 3);
  Eigen::Index row = 0;
  for (const auto& band : layout.bands)
    for (const int j : band) covered.row(row++) = points.row(j);
  return covered;
}

}  // namespace devsurf::testing
