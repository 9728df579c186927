#pragma once

#include <Eigen/Core>

namespace devsurf::metrics {

/// Planarity of a quad as Tang et al. 2016 Fig. 17 measure it: δ = distance between the lines of
/// the two diagonals divided by the mean of the two shortest edges. 0 for a planar quad (also
/// when its diagonals are parallel: parallel lines share a plane) and for a quad with a degenerate
/// side (a triangle: shortest edge ≤ tiny).
/// @param[in] p0, p1, p2, p3  corners in order
/// @param[in] tiny            lengths at or below this count as zero (e.g. 1e-12 × model size)
double quadFlatness(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1, const Eigen::Vector3d& p2,
                    const Eigen::Vector3d& p3, double tiny);

}  // namespace devsurf::metrics
