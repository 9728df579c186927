#pragma once

#include <vector>

#include <Eigen/Core>

namespace devsurf::metrics {

/// Planarity of a polygon meant to be flat (a composite's planar face): the largest distance of
/// a corner from the corners' least-squares plane, divided by the mean of the polygon's two
/// shortest edges (the normalization of quadFlatness). Well conditioned for any loop, convex or
/// not, including loops that run in and out along a bridge, where the diagonals of four
/// consecutive corners can be parallel and their distance says nothing about planarity.
/// 0 for fewer than 4 corners and when the two shortest edges have (mean) length ≤ tiny.
/// @param[in] points  corner positions, indexed by loop
/// @param[in] loop    corner indices in order around the polygon
/// @param[in] tiny    lengths at or below this count as zero (e.g. 1e-12 × model size)
double polygonFlatness(const std::vector<Eigen::Vector3d>& points, const std::vector<int>& loop, double tiny);

}  // namespace devsurf::metrics
