#pragma once

// Shared by the tests of strips side by side (000_… Fig. 10d–e): flat strips in a row and the
// points a cover's bands hold, and distances to strips.

#include <vector>

#include <Eigen/Core>

#include "devsurf/models/strip/StripCover.h"
#include "devsurf/models/strip/StripModel.h"
#include "devsurf/reference/SurfaceDistance.h"

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

/// Distances from `points` to the strips, sampled 200 × 20 each, as one triangle surface.
inline reference::SurfaceDistance distanceToStrips(const Eigen::MatrixX3d& points,
                                                   const std::vector<models::strip::StripDesign>& strips, double tolerance) {
  std::vector<Eigen::RowVector3d> V;
  std::vector<Eigen::RowVector3i> T;
  for (const models::strip::StripDesign& s : strips) {
    const int U = 200, W = 20, base = static_cast<int>(V.size());
    for (int i = 0; i <= U; ++i) {
      const double u = s.a.knots.domainBegin() + (s.a.knots.domainEnd() - s.a.knots.domainBegin()) * i / U;
      const Eigen::Vector3d a = s.a.evaluate(u), b = s.b.evaluate(u);
      for (int k = 0; k <= W; ++k) V.push_back(((1.0 - double(k) / W) * a + double(k) / W * b).transpose());
    }
    for (int i = 0; i < U; ++i)
      for (int k = 0; k < W; ++k) {
        const int p = base + i * (W + 1) + k;
        T.emplace_back(p, p + W + 1, p + W + 2);
        T.emplace_back(p, p + W + 2, p + 1);
      }
  }
  Eigen::MatrixX3d Vm(static_cast<Eigen::Index>(V.size()), 3);
  Eigen::MatrixX3i Tm(static_cast<Eigen::Index>(T.size()), 3);
  for (std::size_t k = 0; k < V.size(); ++k) Vm.row(static_cast<Eigen::Index>(k)) = V[k];
  for (std::size_t k = 0; k < T.size(); ++k) Tm.row(static_cast<Eigen::Index>(k)) = T[k];
  return reference::surfaceDistance(points, Vm, Tm, tolerance);
}

}  // namespace devsurf::testing
