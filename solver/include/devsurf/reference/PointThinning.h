#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>

namespace devsurf::reference {

/// Options of thinPointCloud. The radius sets the level of detail the approximation reproduces
/// (000_… §4.2): features smaller than it are averaged away by the normal fits.
struct ThinningOptions {
  double radius = 0.0;      ///< ball radius r > 0, in the cloud's units (required)
  std::uint32_t seed = 1;   ///< order in which points are visited (a fixed seed gives a fixed result)
  int minimumNeighbours = 3;  ///< a kept point whose ball holds fewer points gets the given normal, or none
};

/// A thinned cloud: the kept points q_j with a normal m_j each from a plane fitted to their ball.
struct ThinnedCloud {
  std::vector<int> kept;      ///< indices into the input, in the order they were chosen
  Eigen::MatrixX3d points;    ///< kept.size()×3
  Eigen::MatrixX3d normals;   ///< kept.size()×3 unit normals (zero rows where none could be fitted)
  /// Per kept point, λ_min/λ_max of its ball's covariance, in [0, 1]: 0 for a plane, growing
  /// towards 1 where the ball is not flat at this radius (noise, a feature, a thin part); 0 also
  /// where no normal was fitted (too few points, or all on a line).
  Eigen::VectorXd flatness;
  /// Per kept point, whether its normal was fitted to its ball (else it is the given one, or 0).
  std::vector<char> fitted;
};

/// Thinning "similar to Poisson sampling" (000_… §4.2): points are visited in a seeded random
/// order; a point not yet discarded is kept, the plane through its ball of radius r (PCA over the
/// ball) gives its normal, and the ball's points are discarded. So no two kept points are closer
/// than r and every input point lies within r of a kept one. The ball search is nanoflann's k-d
/// tree (Debian's libnanoflann-dev). A fitted normal is oriented to agree with the input normal
/// when there is one.
/// @param[in] points   n×3, finite
/// @param[in] normals  n×3 or 0 rows
/// @throws std::invalid_argument if the radius is not a positive finite number, sizes disagree or
///         a coordinate is not finite
ThinnedCloud thinPointCloud(const Eigen::MatrixX3d& points, const Eigen::MatrixX3d& normals,
                            const ThinningOptions& options);

/// A thinning radius for a region of a scan: 3 % of its bounding-box diagonal d; when the normals
/// are to be fitted (the file has none), at least 1.5·d/√N (N points over a region whose area is
/// about d²/2.5 are ~d/(1.6√N) apart, so a ball holds ~15 of them and a plane fits). A ball of
/// radius 0.1 on CGAL's bunny (220 vertices, no normals): at 3 % only 6 kept points had a normal.
/// @returns 0 for fewer than 2 points or coincident points
double suggestedThinningRadius(const Eigen::MatrixX3d& points, bool normalsGiven);

}  // namespace devsurf::reference
