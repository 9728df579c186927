#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>

namespace devsurf::reference {

/// How segmentByNormals clusters a mesh's triangles.
struct NormalSegmentationOptions {
  int patches = 6;              ///< k, clusters wanted (≥ 1)
  /// Weight of position against normal in the clustering features [n, w·p/diagonal]: 0 clusters
  /// by normal alone (patches may be scattered over the shape), larger values give compact ones.
  double positionWeight = 1.0;
  int iterations = 50;          ///< Lloyd iterations at most
  std::uint32_t seed = 1;       ///< k-means++ seeding (std::mt19937)
};

/// A segmentation of a triangle mesh into patches of similar normals (the Gauss image clustered,
/// as developable panelling segments a shape, 004_… §5 citing Gavril et al. 2018): area-weighted
/// k-means++ over features [unit normal, w·centroid/diagonal] of the triangles. 004_… leaves
/// segmentation to the user; this gives one to start from when the input has none.
/// @param[in] V  n×3 vertices
/// @param[in] T  t×3 triangles
/// @return t patch ids in 0 … k′−1 (k′ ≤ k: empty clusters are dropped), numbered by first triangle
/// @throws std::invalid_argument if there are no triangles, an index is out of range, a coordinate
///         is not finite, or patches < 1 or positionWeight < 0
std::vector<int> segmentByNormals(const Eigen::MatrixX3d& V, const Eigen::MatrixX3i& T,
                                  const NormalSegmentationOptions& options = {});

/// The same clustering for points (a cloud, or a mesh's vertices), each of weight one: k-means++
/// over [unit normal, w·point/diagonal]. The normals must be oriented consistently (the two sides
/// of a thin part fall into different clusters only then): orientedPointNormals gives such.
/// @param[in] points   n×3
/// @param[in] normals  n×3, oriented (zero rows cluster by position alone)
/// @return n patch ids in 0 … k′−1 (k′ ≤ k: empty clusters are dropped), numbered by first point
/// @throws std::invalid_argument if there are no points, sizes disagree, a value is not finite, or
///         patches < 1 or positionWeight < 0
std::vector<int> segmentPointsByNormals(const Eigen::MatrixX3d& points, const Eigen::MatrixX3d& normals,
                                        const NormalSegmentationOptions& options = {});

}  // namespace devsurf::reference
